"""A numeric family's path solve reports its progress and stops when the report raises.

An evaluation along a long path with numeric IK takes tens of seconds (20,000 waypoints), so
the family reports after the seeding, after every FOLLOW_WAYPOINTS waypoints it follows (every
waypoint without the compiled chain) and after every CHUNK_ROWS configurations it checks,
and a caller stops it by raising Cancelled from the report (the service does when the client
leaves). The reports must not change the answer: chunks of rows are computed as
the rows alone are.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from solver.core.progress import Cancelled
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.families.numeric import family as family_module
from solver.families.numeric.family import FOLLOW_WAYPOINTS, NumericFamily
from solver.families.numeric.velocity import CHUNK_ROWS
from solver.path import in_pieces
from solver.path.evaluate import evaluate_path
from solver.path.pipeline import REDUNDANT_FREE_SHARES
from tests.cases import ROOT
from tests.problems import problem

EXAMPLE = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
PLACEMENT = Placement(**EXAMPLE["placement"])
MODELS = ["kinova_jaco2", "panda"]  # six joints (J^-1 t), seven (the DTF LP)
PIECES = 3
"""A path of this many pieces of FOLLOW_WAYPOINTS: the compiled chain reports after each."""


def line(n: int, spacing: float = 1e-4) -> np.ndarray:
    """``n`` waypoints along x, ``spacing`` apart (m), the tool pointing down."""
    poses = np.tile(np.diag([1.0, -1.0, -1.0, 1.0]), (n, 1, 1))
    poses[:, 0, 3] = spacing * np.arange(n)
    return poses


@pytest.mark.parametrize("model", MODELS)
def test_the_reports_rise_to_one_and_do_not_change_the_answer(model: str) -> None:
    robot = get_robot(model)
    path = line(PIECES * FOLLOW_WAYPOINTS, spacing=2e-5)
    reports: list[float] = []
    reported = evaluate_path(problem(robot, path), PLACEMENT, progress=reports.append)
    quiet = evaluate_path(problem(robot, path), PLACEMENT)
    assert reported.feasible and reported.mu_path == quiet.mu_path
    np.testing.assert_array_equal(reported.q, quiet.q)
    np.testing.assert_array_equal(reported.v_max, quiet.v_max)
    assert len(reports) >= PIECES + 1  # the seeding, then one a piece followed at least
    assert all(0.0 < f <= 1.0 for f in reports)
    assert reports == sorted(reports) and reports[-1] == pytest.approx(1.0)


@pytest.mark.parametrize("model", MODELS)
def test_a_report_that_raises_stops_the_solve_at_once(model: str) -> None:
    calls: list[float] = []

    def leave(fraction: float) -> None:
        calls.append(fraction)
        if len(calls) == 5:
            raise Cancelled

    path = line(8 * FOLLOW_WAYPOINTS, spacing=1e-5)
    with pytest.raises(Cancelled):
        evaluate_path(problem(get_robot(model), path), PLACEMENT, progress=leave)
    assert len(calls) == 5  # no work, hence no report, after the one that raised
    assert calls[-1] < 0.5  # the seeding and four of eight pieces followed, not the whole path


@pytest.mark.parametrize("model", MODELS)
def test_joint_speeds_in_chunks_equal_each_row_alone(model: str) -> None:
    robot = get_robot(model)
    family = robot.family
    assert isinstance(family, NumericFamily)
    rng = np.random.default_rng(23)
    count = 2 * CHUNK_ROWS + 17
    q = rng.uniform(
        np.maximum(robot.q_lower, -np.pi), np.minimum(robot.q_upper, np.pi), (count, robot.dof)
    ).T
    q[:, 5] = np.nan  # an unsolved configuration: NaN speeds, wherever its chunk
    twist = rng.normal(size=(6, count))
    point = rng.normal(scale=0.1, size=(3, count)) + 0.4
    reports: list[float] = []
    speeds = family.joint_speeds_per_unit_twist(
        q, twist, point, qdot_max=robot.qdot_max, progress=reports.append
    )
    assert reports == [CHUNK_ROWS / (count - 1), 2 * CHUNK_ROWS / (count - 1), 1.0]
    assert np.isnan(speeds[:, 5]).all()
    for i in [0, 4, 6, CHUNK_ROWS - 1, CHUNK_ROWS, count - 1]:
        alone = family.joint_speeds_per_unit_twist(
            q[:, i : i + 1], twist[:, i : i + 1], point[:, i : i + 1], qdot_max=robot.qdot_max
        )
        np.testing.assert_array_equal(speeds[:, i], alone[:, 0])


@pytest.mark.parametrize("model", MODELS)
def test_a_path_followed_in_pieces_gives_the_bits_of_one_piece(
    model: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = get_robot(model)
    placed = problem(robot, line(PIECES * FOLLOW_WAYPOINTS + 7, spacing=2e-5))
    in_pieces = evaluate_path(placed, PLACEMENT)
    monkeypatch.setattr(family_module, "FOLLOW_WAYPOINTS", 10**9)
    whole = evaluate_path(
        problem(robot, line(PIECES * FOLLOW_WAYPOINTS + 7, spacing=2e-5)), PLACEMENT
    )
    assert in_pieces.feasible and whole.feasible
    np.testing.assert_array_equal(in_pieces.q, whole.q)
    np.testing.assert_array_equal(in_pieces.v_max, whole.v_max)


def test_a_seven_joint_free_spin_reports_through_its_lps_and_stops_there(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 27: the Panda's free spin solves an LP at every configuration (the spin LP, then
    the spin rates at the feed): both report after every piece of LIMIT_ROWS configurations
    (pieces give the bits of the whole) and a report that raises there stops the work."""
    monkeypatch.setattr(in_pieces, "LIMIT_ROWS", 64)
    robot = get_robot("panda")
    path = line(PIECES * FOLLOW_WAYPOINTS, spacing=2e-5)
    placed = problem(robot, path, spin_mode="free")
    reports: list[float] = []
    reported = evaluate_path(placed, PLACEMENT, progress=reports.append)
    quiet = evaluate_path(placed, PLACEMENT)
    assert reported.feasible and reported.mu_path == quiet.mu_path
    for field in ("q", "v_max", "qdot", "spins"):
        np.testing.assert_array_equal(getattr(reported, field), getattr(quiet, field))
    assert reports == sorted(reports) and reports[-1] == pytest.approx(1.0)
    shares = REDUNDANT_FREE_SHARES
    for low, high in [(shares[3], shares[4]), (shares[4], shares[5]), (shares[5], shares[6])]:
        assert sum(low < f <= high for f in reports) >= (2 if low == shares[3] else 10)


@pytest.mark.parametrize("part", [1, 4, 5, 6])  # tracking, null space, spin LP, spin schedule
def test_a_seven_joint_free_spin_stops_in_each_part(part: int) -> None:
    shares = REDUNDANT_FREE_SHARES
    calls: list[float] = []

    def leave(fraction: float) -> None:
        calls.append(fraction)
        if fraction > shares[part - 1]:
            raise Cancelled

    placed = problem(get_robot("panda"), line(2 * FOLLOW_WAYPOINTS, 2e-5), spin_mode="free")
    with pytest.raises(Cancelled):
        evaluate_path(placed, PLACEMENT, progress=leave)
    assert shares[part - 1] < calls[-1] <= shares[part]  # and nothing after
