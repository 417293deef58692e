"""DTF: closed form = LP optimum, the invariants at the maximum, eq. (30), redundant arms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solver.core.dtf import (
    chiu,
    closed_form_batch,
    decomposed_speed,
    dtf,
    lp_speed,
    twist_per_unit_speed,
    yoshikawa,
)
from solver.core.exceptions import InvalidInputError
from solver.core.kinematics import jacobian_in_base
from solver.core.robots import example_robot_data_dir
from solver.families import get_robot, robot_from_urdf
from tests.cases import DTF_LP_RTOL, SENSORS_TABLE_3, unit

N_CASES = 1000


def _random_direction(rng: np.random.Generator) -> np.ndarray:
    vector = rng.normal(size=3)
    return vector / np.linalg.norm(vector)


def _random_cases(name: str, seed: int):
    """Non-singular configurations, random directions, h in [1e-2, 1e2], equal/unequal limits."""
    robot = get_robot(name)
    rng = np.random.default_rng(seed)
    cases = []
    while len(cases) < N_CASES:
        q = rng.uniform(-math.pi, math.pi, 6)
        jacobian = jacobian_in_base(robot, q)
        if np.linalg.cond(jacobian) > 1e6:
            continue
        limits = np.full(6, math.pi) if len(cases) % 2 else rng.uniform(0.5, 6.0, 6)
        h = 10 ** rng.uniform(-2, 2)
        cases.append((jacobian, _random_direction(rng), _random_direction(rng), h, limits))
    return cases


@pytest.mark.parametrize(("name", "seed"), [("ur5", 1), ("ur5e", 2)])
def test_closed_form_equals_lp_and_invariants_hold(name: str, seed: int) -> None:
    """Issue 2: DTF = LP optimum (rel 1e-9); at the maximum one joint is on its limit,
    J qdot* = [V u_T; Omega u_R], V / Omega = h, and eq. (30) equals the J^-1 form."""
    for jacobian, u_t, u_r, h, limits in _random_cases(name, seed):
        result = dtf(jacobian, u_T=u_t, u_R=u_r, h=h, qdot_max=limits)
        assert result.method == "closed_form"
        optimum, _ = lp_speed(jacobian, twist_per_unit_speed(u_t, u_r, h), qdot_max=limits)
        assert abs(result.v_max - optimum) <= DTF_LP_RTOL * optimum
        j = result.limiting_joint
        assert abs(abs(result.qdot[j]) - limits[j]) <= 1e-12 * limits[j]
        assert np.all(np.abs(result.qdot) <= limits * (1 + 1e-12))
        twist = np.concatenate([result.v_max * u_t, result.omega_max * u_r])
        np.testing.assert_allclose(
            jacobian @ result.qdot, twist, rtol=0, atol=1e-12 * max(1.0, float(np.abs(twist).max()))
        )
        assert abs(result.v_max / result.omega_max - h) <= 1e-12 * h
        decomposed = decomposed_speed(jacobian, u_t, u_r, h, limits)
        assert abs(decomposed - result.v_max) <= 1e-9 * result.v_max


@settings(max_examples=200, deadline=None)
@given(
    q=st.lists(st.floats(-math.pi, math.pi), min_size=6, max_size=6),
    log_h=st.floats(-2, 2),
    seed=st.integers(0, 2**32 - 1),
)
def test_lp_is_never_beaten_by_a_feasible_scaling(q: list[float], log_h: float, seed: int) -> None:
    """Property: no joint speed vector of the form s * J^-1 t_hat with s > DTF stays in limits."""
    jacobian = jacobian_in_base(get_robot("ur5e"), np.array(q))
    if np.linalg.cond(jacobian) > 1e8:
        return
    rng = np.random.default_rng(seed)
    u_t, u_r, h = _random_direction(rng), _random_direction(rng), 10**log_h
    limits = rng.uniform(0.5, 6.0, 6)
    result = dtf(jacobian, u_T=u_t, u_R=u_r, h=h, qdot_max=limits)
    scaled = np.linalg.solve(jacobian, twist_per_unit_speed(u_t, u_r, h)) * result.v_max * 1.001
    assert np.any(np.abs(scaled) > limits)


@pytest.mark.parametrize("segment", sorted(SENSORS_TABLE_3))
def test_paper_segments_invariants(segment: str) -> None:
    """Sensors 2022 Table 3 directions on UR5e (qdot_max = pi): the Table 4 invariants hold."""
    u_t, u_r, h = SENSORS_TABLE_3[segment]
    robot = get_robot("ur5e")
    q = np.array([0.2, -1.3, 1.6, -1.9, -1.5, 0.4])
    result = dtf(
        jacobian_in_base(robot, q), u_T=unit(u_t), u_R=unit(u_r), h=h, qdot_max=[math.pi] * 6
    )
    assert max(abs(result.qdot)) == pytest.approx(math.pi, rel=1e-12)
    assert result.v_max / result.omega_max == pytest.approx(h, rel=1e-12)


def test_pure_translation_and_pure_rotation() -> None:
    jacobian = jacobian_in_base(get_robot("ur5e"), np.array([0.2, -1.3, 1.6, -1.9, -1.5, 0.4]))
    limits = np.full(6, math.pi)
    u = np.array([1.0, 0.0, 0.0])
    translation = dtf(jacobian, u_T=u, u_R=None, h=math.inf, qdot_max=limits)
    assert translation.omega_max == 0.0
    np.testing.assert_allclose(
        jacobian @ translation.qdot, [translation.v_max, 0, 0, 0, 0, 0], atol=1e-12
    )
    rotation = dtf(jacobian, u_T=None, u_R=u, h=0.0, qdot_max=limits)
    assert rotation.v_max == 0.0
    np.testing.assert_allclose(
        jacobian @ rotation.qdot, [0, 0, 0, rotation.omega_max, 0, 0], atol=1e-12
    )
    # h -> inf and h -> 0 approach these limits.
    near_inf = dtf(jacobian, u_T=u, u_R=u, h=1e9, qdot_max=limits)
    assert near_inf.v_max == pytest.approx(translation.v_max, rel=1e-6)
    near_zero = dtf(jacobian, u_T=u, u_R=u, h=1e-9, qdot_max=limits)
    assert near_zero.omega_max == pytest.approx(rotation.omega_max, rel=1e-6)


def _panda():
    path = example_robot_data_dir() / "panda_description" / "urdf" / "panda.urdf"
    return robot_from_urdf(path.read_text(), base_frame="panda_link0", tool_frame="panda_link8")


def test_redundant_arm_uses_lp_at_least_pseudo_inverse() -> None:
    """Issue 2: for the 7-DOF Panda the LP answers, at least the pseudo-inverse DTF."""
    robot = _panda()
    rng = np.random.default_rng(5)
    strictly_better = 0
    for _ in range(50):
        q = rng.uniform(robot.q_lower, robot.q_upper)
        jacobian = jacobian_in_base(robot, q)
        u_t, u_r, h = _random_direction(rng), _random_direction(rng), 10 ** rng.uniform(-1, 1)
        result = dtf(jacobian, u_T=u_t, u_R=u_r, h=h, qdot_max=robot.qdot_max)
        assert result.method == "lp"
        pinv_speeds = np.linalg.pinv(jacobian) @ twist_per_unit_speed(u_t, u_r, h)
        pinv_value = 1.0 / np.max(np.abs(pinv_speeds) / robot.qdot_max)
        assert result.v_max >= pinv_value * (1 - 1e-9)
        strictly_better += result.v_max > pinv_value * 1.01
        assert np.all(np.abs(result.qdot) <= robot.qdot_max * (1 + 1e-9))
        np.testing.assert_allclose(
            jacobian @ result.qdot,
            np.concatenate([result.v_max * u_t, result.omega_max * u_r]),
            atol=1e-8,
        )
    assert strictly_better > 25  # redundancy is worth something in most configurations


def test_singular_configuration_falls_back_to_lp() -> None:
    robot = get_robot("ur5e")
    q = np.array([0.3, -1.1, 1.2, -0.4, 0.0, 0.7])  # wrist singular
    jacobian = jacobian_in_base(robot, q)
    u = np.array([0.0, 0.0, 1.0])
    result = dtf(jacobian, u_T=u, u_R=u, h=0.5, qdot_max=robot.qdot_max)
    assert result.method == "lp"
    with pytest.raises(InvalidInputError, match="closed_form"):
        dtf(jacobian, u_T=u, u_R=u, h=0.5, qdot_max=robot.qdot_max, method="closed_form")


def test_closed_form_batch_matches_scalar() -> None:
    robot = get_robot("ur5")
    rng = np.random.default_rng(9)
    qs = rng.uniform(-3, 3, (20, 6))
    jacobians = np.array([jacobian_in_base(robot, q) for q in qs])
    twists = np.array(
        [twist_per_unit_speed(_random_direction(rng), _random_direction(rng), 0.3) for _ in qs]
    )
    speed, qdot, limiting = closed_form_batch(jacobians, twists, robot.qdot_max)
    for i in range(len(qs)):
        value, _ = lp_speed(jacobians[i], twists[i], qdot_max=robot.qdot_max)
        assert speed[i] == pytest.approx(value, rel=1e-9)
        assert abs(qdot[i, limiting[i]]) == pytest.approx(robot.qdot_max[limiting[i]], rel=1e-12)


def test_reference_indices() -> None:
    """Yoshikawa = product of singular values; Chiu = 1/|J^-1 t| for a square J."""
    jacobian = jacobian_in_base(get_robot("ur5e"), np.array([0.2, -1.3, 1.6, -1.9, -1.5, 0.4]))
    assert yoshikawa(jacobian) == pytest.approx(np.prod(np.linalg.svd(jacobian)[1]), rel=1e-12)
    t = np.array([0.6, 0.0, 0.8, 0.0, 0.0, 0.0])
    assert chiu(jacobian, t) == pytest.approx(1.0 / np.linalg.norm(np.linalg.solve(jacobian, t)))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"u_T": [1.0, 1.0, 0.0], "u_R": [0, 0, 1.0], "h": 1.0}, "u_T"),
        ({"u_T": [1.0, 0.0, 0.0], "u_R": [0, 0, 0.5], "h": 1.0}, "u_R"),
        ({"u_T": [1.0, 0.0, 0.0], "u_R": [0, 0, 1.0], "h": -1.0}, "h"),
        ({"u_T": [1.0, 0.0, 0.0], "u_R": [0, 0, 1.0], "h": math.nan}, "h"),
        ({"u_T": [1.0, 0.0], "u_R": [0, 0, 1.0], "h": 1.0}, "u_T"),
    ],
)
def test_bad_task_input_names_the_field(kwargs: dict, field: str) -> None:
    jacobian = jacobian_in_base(get_robot("ur5e"), np.array([0.2, -1.3, 1.6, -1.9, -1.5, 0.4]))
    with pytest.raises(InvalidInputError) as info:
        dtf(jacobian, qdot_max=[math.pi] * 6, **kwargs)
    assert info.value.field == field


@pytest.mark.parametrize("turned", [None, 1, 2, 3, 4, "1e-15"])
def test_a_singular_configuration_gives_one_answer_however_written(turned: object) -> None:
    """The UR5e at q = 0 (elbow stretched, wrist singular) and the same pose with a joint turned
    by 2 pi, or off by rounding: the LP answered 0.391 at q = 0 and 0.0 with q2 = 2 pi, its row
    scaling making a row of J's rounding a constraint (audit 23). Against HiGHS on J with the
    rounding of sin(2 pi) left out, written here (no scaling): J at q = 0 exactly."""
    robot = get_robot("ur5e")
    q = np.zeros(6)
    if isinstance(turned, int):
        q[turned] = 2 * math.pi
    elif isinstance(turned, str):
        q[1] = float(turned)
    u_t, u_r, h = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), 0.5
    answer = dtf(jacobian_in_base(robot, q), u_T=u_t, u_R=u_r, h=h, qdot_max=robot.qdot_max)
    import scipy.optimize

    exact = jacobian_in_base(robot, np.zeros(6))
    twist = np.concatenate([u_t, u_r / h])
    n = exact.shape[1]
    reference = scipy.optimize.linprog(
        np.r_[np.zeros(n), -1.0],
        A_eq=np.hstack([exact, -twist[:, None]]),
        b_eq=np.zeros(6),
        bounds=[(-v, v) for v in robot.qdot_max] + [(0.0, None)],
        method="highs",
    )
    assert reference.status == 0 and -reference.fun > 0.3  # the tool can move along t_hat
    assert answer.method == "lp"
    assert answer.v_max == pytest.approx(-reference.fun, rel=1e-9)
