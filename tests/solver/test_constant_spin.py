"""Constant tool spin (cam.md section 3): a placement variable that changes only the IK."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import Placement, spun_waypoints
from solver.families import get_robot
from solver.optimise.search_space import PlacementBounds
from tests.cases import MAP_EVALUATE_RTOL, OPTIMUM_EVALUATE_RTOL, OPTIMUM_METHODS_RTOL
from tests.problems import capability_map, evaluate_path, optimize_placement
from tests.solver.test_evaluate import load_path


def _turn_z(angle: float) -> np.ndarray:
    transform = np.eye(4)
    c, s = math.cos(angle), math.sin(angle)
    transform[:2, :2] = [[c, -s], [s, c]]
    return transform


def angled_spindle() -> np.ndarray:
    """T_F_TCP of a spindle at 90 degrees to the flange, its tip 0.12 m out along flange x."""
    tcp = np.eye(4)
    tcp[:3, :3] = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]  # tool z = flange x
    tcp[:3, 3] = [0.12, 0.0, 0.05]
    return tcp


@pytest.mark.parametrize("spin", [0.4, -2.0])
def test_spin_is_the_tcp_turned_about_its_z(spin: float) -> None:
    """Spinning every waypoint by theta = the TCP turned by -theta about its own z (1e-12)."""
    robot = get_robot("ur5e").with_options(transform_tool_to_tcp=angled_spindle())
    turned = robot.with_options(transform_tool_to_tcp=angled_spindle() @ _turn_z(-spin))
    path = load_path("curved_line")
    placement = Placement(0.1, 0.45, 0.0, 0.3)
    spun = evaluate_path(robot, path, Placement(0.1, 0.45, 0.0, 0.3, spin=spin))
    reference = evaluate_path(turned, path, placement)
    assert spun.feasible and reference.feasible
    assert spun.mu_path == pytest.approx(reference.mu_path, rel=1e-12)
    np.testing.assert_allclose(spun.u_T, reference.u_T, atol=1e-12)
    np.testing.assert_allclose(spun.u_R, reference.u_R, atol=1e-12)
    np.testing.assert_allclose(spun.h, reference.h, rtol=1e-12)
    # and the requirements are those of the unspun path
    unspun = evaluate_path(robot, path, placement)
    np.testing.assert_allclose(spun.u_R, unspun.u_R, atol=1e-12)


def test_spin_changes_mu_path_for_an_angled_spindle_only() -> None:
    path = load_path("curved_line")
    angled = get_robot("ur5e").with_options(transform_tool_to_tcp=angled_spindle())
    straight = get_robot("ur5e")
    values = {
        name: [
            evaluate_path(robot, path, Placement(0.0, 0.45, 0.0, 0.0, spin=spin)).mu_path
            for spin in (0.0, 0.5, 1.0)
        ]
        for name, robot in (("angled", angled), ("straight", straight))
    }
    assert len({round(v, 9) for v in values["angled"] if v is not None}) == 3
    # A straight spindle: only the last joint's angle moves, so the speeds stay.
    assert values["straight"][1] == pytest.approx(values["straight"][0], rel=1e-9)


def test_spin_grid_cells_equal_evaluate() -> None:
    robot = get_robot("ur5e").with_options(transform_tool_to_tcp=angled_spindle())
    path = load_path("curved_line")
    cmap = capability_map(
        robot,
        path,
        xs=np.array([-0.1, 0.1]),
        ys=np.array([0.4, 0.55]),
        z=0.0,
        yaws=np.array([0.0, 1.0]),
        spins=np.array([0.0, 0.8, -1.5]),
    )
    assert cmap.mu_path.shape == (3, 2, 2, 2)
    for index in np.ndindex(cmap.mu_path.shape):
        expected = evaluate_path(robot, path, cmap.placement(index))
        assert cmap.placement(index).spin == cmap.spins[index[0]]
        if expected.mu_path is None:
            assert np.isnan(cmap.mu_path[index])
        else:
            assert cmap.mu_path[index] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
    assert np.isfinite(cmap.mu_path).sum() >= 6


@pytest.fixture(scope="module")
def spin_optima() -> dict:
    robot = get_robot("ur5e").with_options(transform_tool_to_tcp=angled_spindle())
    path = load_path("curved_line")
    fixed = PlacementBounds(x=(-0.1, 0.1), y=(0.35, 0.55), yaw=(-math.pi, math.pi), z=0.0)
    free = dataclasses.replace(fixed, spin=(-math.pi, math.pi))
    return {
        "robot": robot,
        "path": path,
        **{
            (method, name): optimize_placement(robot, path, bounds=bounds, method=method)
            for method in ("casadi", "scipy")
            for name, bounds in (("no spin", fixed), ("spin", free))
        },
    }


@pytest.mark.parametrize("method", ["casadi", "scipy"])
def test_spin_bounds_never_lose_and_win_for_an_angled_spindle(
    spin_optima: dict, method: str
) -> None:
    """cam.md section 3: with spin bounds containing 0 the optimum is never below the no-spin
    one; for this angled spindle it is above it, and the evaluator agrees at its spin."""
    no_spin, spin = spin_optima[(method, "no spin")], spin_optima[(method, "spin")]
    assert no_spin is not None and spin is not None
    assert no_spin.placement.spin == 0.0
    assert spin.mu_path >= no_spin.mu_path
    assert spin.mu_path > no_spin.mu_path * 1.01
    evaluation = evaluate_path(spin_optima["robot"], spin_optima["path"], spin.placement)
    assert spin.mu_path == pytest.approx(evaluation.mu_path, rel=OPTIMUM_EVALUATE_RTOL)
    # Both methods find the same no-spin optimum (with spin free, differential evolution over
    # four variables settles 2.5 % below IPOPT's basin here: a known gap of the scipy method).
    other = spin_optima[("scipy" if method == "casadi" else "casadi", "no spin")]
    assert no_spin.mu_path == pytest.approx(other.mu_path, rel=OPTIMUM_METHODS_RTOL)


def test_spin_path_beats_the_constant_spin_within_its_steps(spin_optima: dict) -> None:
    """cam.md section 4: at least the constant-spin optimum, steps within max_spin_step, and
    the evaluator with the returned spins gives the same mu_path."""
    robot, path = spin_optima["robot"], spin_optima["path"]
    constant = spin_optima[("casadi", "spin")]
    bounds = PlacementBounds(
        x=(-0.1, 0.1), y=(0.35, 0.55), yaw=(-math.pi, math.pi), z=0.0, spin=(-math.pi, math.pi)
    )
    optimum = optimize_placement(robot, path, bounds=bounds, max_spin_step=0.02)
    assert optimum is not None and optimum.spins is not None
    assert optimum.mu_path >= constant.mu_path
    assert optimum.mu_path > 1.5 * constant.mu_path  # the angled spindle gains most here
    assert np.max(np.abs(np.diff(optimum.spins))) <= 0.02
    assert optimum.spins[0] == 0.0
    spun = evaluate_path(robot, spun_waypoints(path, optimum.spins), optimum.placement)
    assert optimum.mu_path == pytest.approx(spun.mu_path, rel=OPTIMUM_EVALUATE_RTOL)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"method": "scipy", "max_spin_step": 0.1}, "spin_path"),
        ({"spin_mode": "free", "max_spin_step": 0.1}, "spin_path"),
        ({"max_spin_step": 0.0}, "spin_path.max_spin_step"),
    ],
)
def test_bad_spin_path(kwargs: dict, field: str) -> None:
    bounds = PlacementBounds(x=(0.0, 0.1), y=(0.4, 0.5), yaw=(0.0, 0.1), z=0.1)
    with pytest.raises(InvalidInputError) as error:
        optimize_placement(get_robot("ur5"), load_path("curved_line"), bounds=bounds, **kwargs)
    assert error.value.field == field


def test_spin_bounds_wider_than_a_turn_are_refused() -> None:
    bounds = PlacementBounds(x=(0.0, 0.1), y=(0.4, 0.5), yaw=(0.0, 0.1), z=0.1, spin=(-3.2, 3.2))
    with pytest.raises(InvalidInputError) as error:
        optimize_placement(get_robot("ur5"), load_path("curved_line"), bounds=bounds)
    assert error.value.field == "bounds.spin"
