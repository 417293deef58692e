"""The six-joint pass takes det J's sign from V_max's LU (J at the tool point): the same statuses.

:func:`solver.families.numeric.scout_kernel.status_and_speed` reads the sign of det J from
the LU of J at the tool point (J_tool = S J_flange, det S = 1) instead of a second LU of J at
the flange; a tool point farther than ``NEAR_TOOL`` from the flange takes the flange's LU. Held
here: the LU's sign against numpy's determinant and its solution against :func:`lu_solve` bit
for bit, and the statuses along a path whose det J changes sign (the UR5's wrist through
q5 = 0) against ``follow_paths``' (the flange's LU), with a near and a far tool point.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.core.codes import OK, OK_MIRRORED, SINGULAR, TIE_RTOL
from solver.families.numeric import chain_kernel, lu_kernel, scout_kernel
from solver.families.numeric.family import NumericFamily
from solver.path import bounded
from tests.solver.families.numeric_maps import ur5_from_urdf

_Both = tuple[bool, bool, np.ndarray, bool, np.ndarray]


@njit(cache=False)
def _both(a: np.ndarray, b: np.ndarray) -> _Both:  # pragma: no cover - compiled
    a_plain, b_plain = a.copy(), b.copy()
    solved, negative = lu_kernel.lu_solve_signed(a, b)
    plain = lu_kernel.lu_solve(a_plain, b_plain)
    return solved, negative, b, plain, b_plain


def test_the_lu_gives_det_sign_and_lu_solve_bits() -> None:
    rng = np.random.default_rng(11)
    signs = set()
    for _ in range(2000):
        a = rng.normal(size=(6, 6)) * rng.uniform(0.01, 10.0, size=6)  # columns scaled apart
        b = rng.normal(size=6)
        solved, negative, x, plain, x_plain = _both(a.copy(), b.copy())
        assert solved and plain
        assert negative == (np.linalg.det(a) < 0.0)
        np.testing.assert_array_equal(x.view(np.int64), x_plain.view(np.int64))
        signs.add(negative)
    assert signs == {True, False}
    singular = np.ones((6, 6))
    assert not _both(singular, np.ones(6))[0]


def test_statuses_across_a_sign_change_as_follow_paths_with_near_and_far_tools() -> None:
    robot = ur5_from_urdf()
    family = robot.family
    assert isinstance(family, NumericFamily)
    n = 12
    path_q = np.column_stack(
        [
            np.linspace(0.3, 0.4, n),
            np.full(n, -1.2),
            np.full(n, 1.4),
            np.linspace(-0.6, -0.5, n),
            np.linspace(0.31, -0.24, n),  # q5 through 0 between two waypoints
            np.full(n, 0.7),
        ]
    )
    rotations, positions = chain_kernel.forward(family.chain.packed(), path_q)
    expected_q, expected = family.follow_piece(
        path_q[None, :1].copy(), rotations[None], positions[None], False
    )
    assert {OK, OK_MIRRORED} <= set(expected[0, 0].tolist())
    assert SINGULAR not in expected[0, 0]
    twists = np.random.default_rng(12).normal(size=(1, n, 6))
    rules = (TIE_RTOL, bounded.MARGIN, bounded.ROUGH, bounded.SLACK, bounded.STRIDE)
    for offset in (0.05, 2 * scout_kernel.NEAR_TOOL):  # V_max's LU; the flange's
        q, status, _, dropped = family.follow_bounded(
            path_q[None, :1].copy(),
            (rotations[None], positions[None]),
            (twists, positions[None] + offset, robot.qdot_max, np.zeros(n, dtype=bool), 9.0),
            (*rules, bounded.RESIDUAL, bounded.MOTION),
        )
        assert not dropped.any()
        np.testing.assert_array_equal(status[0, 0], expected[0, 0])
        np.testing.assert_array_equal(q[:, 0, 0], expected_q[:, 0, 0])
