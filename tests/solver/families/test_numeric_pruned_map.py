"""A numeric map that stops following hopeless branches answers every cell as one that does not.

:mod:`solver.path.pruning`: a cell's reported fields (mu_path, reason, failing waypoint, branch,
binding waypoint and joint, V_max along the chosen branch) are those of following every branch
(``prune=False``), bit for bit, and those of the numpy chain (the reference, never pruned) to
its tolerance. Six- and seven-joint arms are pruned in one compiled pass
(:mod:`solver.path.bounded`; seven joints: :mod:`solver.families.numeric.bounded_redundant_kernel`),
checked on the Panda, the xArm7, a UR and an OPW arm (whose family, made to follow in steps
here, still takes the compiled pass); arms of more joints in steps (:mod:`solver.path.pruning`),
checked on the Panda made to (``panda_in_steps``).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from solver.core.codes import REASON_UNREACHABLE
from solver.core.family import Branch
from solver.core.robots import Robot
from solver.families.numeric.family import NumericFamily
from solver.path import bounded
from solver.path.pipeline import ChunkResult, run_chunk
from solver.path.placed import check_placements
from solver.path.placements import PlacementResults, evaluate_placements
from solver.path.problem import PathOptions, PathProblem
from solver.path.pruning import can_prune
from tests.solver.families.numeric_maps import erk_placements, opw_from_urdf
from tests.solver.families.test_numeric_kernel import MU_RTOL, arm
from tests.solver.test_evaluate import load_path

FIELDS = (
    "mu_path",
    "reason",
    "failed_waypoint",
    "branch",
    "bottleneck_waypoint",
    "bottleneck_joint",
    "v_max",
)
CASES = {  # the arm, and its grid's x and y ranges
    "panda": ("panda", (-0.25, 0.25), (0.25, 0.65)),
    "xarm7": ("xarm7", (-0.25, 0.25), (0.25, 0.65)),
    "panda_in_steps": ("panda", (-0.25, 0.25), (0.25, 0.65)),
    "ur5_urdf": ("ur5_urdf", (-0.25, 0.25), (0.25, 0.65)),
    "irb2400_urdf": ("irb2400_urdf", (0.6, 1.0), (-0.25, 0.25)),
}


class _InSteps(NumericFamily):
    """The numeric family following in steps whatever its joints (the pruned map's path)."""

    @property
    def follows_in_steps(self) -> bool:
        """Always."""
        return True


class _OnlyInSteps(_InSteps):
    """The numeric family pruned in steps, never in one pass (as arms of eight joints are)."""

    @property
    def follows_bounded(self) -> bool:
        """Never."""
        return False


def stepped(robot: Robot, *, only: bool = False) -> Robot:
    """``robot`` whose numeric family follows in steps (``only``: and not in one pass)."""
    family = robot.family
    assert isinstance(family, NumericFamily)
    stepping = (_OnlyInSteps if only else _InSteps).__new__(_OnlyInSteps if only else _InSteps)
    stepping.__dict__.update(family.__dict__)
    return dataclasses.replace(robot, family=stepping)


def numeric(name: str, *, compiled: bool = True) -> Robot:
    """The case's arm with the numeric family (the IRB 2400 as a URDF from its OPW parameters)."""
    if name == "irb2400_urdf":
        return opw_from_urdf("abb_irb2400", compiled=compiled)
    return arm(name, compiled=compiled)


def placements_of(name: str) -> np.ndarray:
    """A 5 x 4 grid of the case, and two placements out of reach (no feasible branch)."""
    _, (x0, x1), (y0, y1) = CASES[name]
    grid = erk_placements(np.linspace(x0, x1, 5), np.linspace(y0, y1, 4), 0.1)
    far = np.array([[3.0, 0.0, 0.1, 0.0, 0.0], [0.0, 0.9, 0.1, 0.0, 0.0]])
    return np.concatenate([grid, far])


@pytest.mark.parametrize("name", CASES)
def test_pruned_map_equals_following_every_branch(name: str) -> None:
    robot = stepped(numeric(CASES[name][0]), only=name.endswith("_in_steps"))
    problem = PathProblem.of(robot, load_path("curved_line"))
    assert can_prune(problem)
    placements = placements_of(name)
    pruned = evaluate_placements(problem, placements, with_speeds=True)
    every = evaluate_placements(problem, placements, with_speeds=True, prune=False)
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(pruned, field), getattr(every, field), err_msg=field)
    feasible = np.isfinite(every.mu_path)
    assert 10 <= feasible.sum() < len(placements)  # both kinds of cell are compared
    if robot.dof == 7:  # and cells whose branches all fail, some after the first waypoint
        assert np.any(~feasible & (every.failed_waypoint > 0))
    # Pruning happened: branches were dropped (unreachable from their first waypoint).
    cells = check_placements(placements)
    kept, followed = (followed_branches(run_chunk(problem, cells, prune=p)) for p in (True, False))
    assert kept < followed


def followed_branches(run: ChunkResult) -> int:
    """The branches of a chunk's run that have a solution at their first waypoint."""
    tracked = run.tracked
    return int(np.sum((tracked.reason != REASON_UNREACHABLE) | (tracked.failed_waypoint > 0)))


@pytest.mark.parametrize("name", CASES)
def test_pruned_map_equals_numpy_reference(name: str) -> None:
    """The numpy chain follows every branch (it does not follow in steps): the reference."""
    path = load_path("curved_line")[:60]
    placements = placements_of(name)
    robot = stepped(numeric(CASES[name][0]), only=name.endswith("_in_steps"))
    ours = evaluate_placements(PathProblem.of(robot, path), placements)
    reference_problem = PathProblem.of(numeric(CASES[name][0], compiled=False), path)
    assert not can_prune(reference_problem)
    theirs: PlacementResults = evaluate_placements(reference_problem, placements)
    for field in ("reason", "failed_waypoint", "branch", "bottleneck_waypoint"):
        np.testing.assert_array_equal(getattr(ours, field), getattr(theirs, field), err_msg=field)
    np.testing.assert_allclose(ours.mu_path, theirs.mu_path, rtol=MU_RTOL, atol=0)


@pytest.mark.parametrize(
    "options",
    [
        PathOptions(spin_mode="free"),  # the spin schedule may refuse the best branch later
        PathOptions(branch=Branch.named(solution="0")),  # one branch: nothing to choose
    ],
    ids=["free_spin", "named_branch"],
)
def test_maps_that_need_every_branch_are_not_pruned(options: PathOptions) -> None:
    problem = PathProblem.of(numeric("panda"), load_path("curved_line")[:10], options)
    assert not can_prune(problem)


def test_six_joint_maps_prune_in_one_compiled_pass() -> None:
    ur5 = PathProblem.of(numeric("ur5_urdf"), load_path("curved_line")[:10])
    family = ur5.family
    assert can_prune(ur5) and isinstance(family, NumericFamily) and family.follows_bounded
    assert not can_prune(PathProblem.of(numeric("ur5_urdf", compiled=False), ur5.waypoints))
    panda = PathProblem.of(numeric("panda"), load_path("curved_line")[:10])
    family = panda.family
    assert can_prune(panda) and isinstance(family, NumericFamily) and family.follows_bounded


@pytest.mark.parametrize("name", ["ur5_urdf", "irb2400_urdf"])
def test_drops_the_check_refuses_are_followed_after_all(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The check made stricter (bounds raised 0.1 %) refuses drops: the same answer."""
    problem = PathProblem.of(numeric(name), load_path("curved_line")[:60])
    placements = placements_of(name)
    every = evaluate_placements(problem, placements, with_speeds=True, prune=False)
    refused = []
    checked = bounded.choice_holds

    def counted(mu: np.ndarray, bound: np.ndarray, dropped: np.ndarray) -> np.ndarray:
        holds = checked(mu, bound * 1.001, dropped)
        refused.append(int(np.count_nonzero(~holds)))
        return holds

    monkeypatch.setattr(bounded, "choice_holds", counted)
    pruned = evaluate_placements(problem, placements, with_speeds=True)
    assert sum(refused) > 0
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(pruned, field), getattr(every, field), err_msg=field)


@pytest.mark.parametrize(
    "setting",
    [("ROUGH", 0), ("RESIDUAL", 0.0), ("MOTION", 0.0), ("STRIDE", 1)],
    ids=["every_slot_exact", "no_stride_trusted", "no_motion_trusted", "stride_1"],
)
def test_scouting_settings_change_no_field(
    setting: tuple[str, float], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without scouting, with every stride untrusted (followed exactly), or waypoint by waypoint."""
    problem = PathProblem.of(numeric("ur5_urdf"), load_path("curved_line")[:60])
    placements = placements_of("ur5_urdf")
    ours = evaluate_placements(problem, placements, with_speeds=True)
    monkeypatch.setattr(bounded, *setting)
    theirs = evaluate_placements(problem, placements, with_speeds=True)
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(ours, field), getattr(theirs, field), err_msg=field)
