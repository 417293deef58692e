"""Pruning by mu_acc in the map kernels (solver.kernels.acc_cells): probes keep every answer.

A branch left by its V_acc at a stencil row has the branches still to follow probed there
(branches of one shoulder share joints, so they are often left at the same row), and each
branch's stencil row of the placement before is probed once for all. Neither may change an
answer: the compiled cells against the numpy pipeline, which forms mu_acc on every branch
(``same_cells``), on ERK-map columns in map order where the limits bind on every cell, and where
they bind on some cells only (the branch choice then turns on mu_acc on some cells and on
mu_path on others).
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.two_variable_lp import spin_rate_nearest_zero
from solver.families import get_robot
from solver.kernels.accelerations import probed_before
from solver.kernels.spin_schedule import spin_moves
from tests.solver.test_evaluate import load_path
from tests.solver.test_map_kernel import grid, same_cells


@pytest.mark.parametrize(
    ("spin_mode", "acceleration", "binding"),
    [
        ("fixed", 10.0, {1}),
        ("fixed", 16.0, {0, 1}),
        ("fixed", 17.0, {0, 1}),
        ("free", 10.0, {1}),
        ("free", 200.0, {0, 1}),
    ],
)
def test_erk_columns_equal_the_pipeline(
    spin_mode: str, acceleration: float, binding: set[int]
) -> None:
    """The ERK map's first four columns (84 cells, the map's order): every column identical to
    the numpy pipeline's, mu_acc and V_acc to the rounding of the joint angles."""
    columns = -0.25 + 0.02 * np.arange(4)
    placements = grid(columns, np.arange(0.25, 0.65 + 1e-9, 0.02), 0.1, np.zeros(1))
    result, _ = same_cells(
        get_robot("ur5"),
        load_path("curved_line"),
        placements,
        accelerations=acceleration,
        spin_mode=spin_mode,
    )
    assert len(placements) == 84 and np.isfinite(result.mu_path).all()
    assert result.limited_by is not None and set(result.limited_by) == binding


def test_probed_before_once_per_stencil_row() -> None:
    """A row's stencil row needs a probe unless it is none, the best row's, or a row before it
    was probed there."""
    acc_hint = np.array([5, -1, 5, 7, 9, 7])
    probed = np.array([True, False, False, False, False, False])
    assert [probed_before(i, acc_hint, probed, 9) for i in range(6)] == [
        False,  # row 0: nothing before it
        True,  # none
        True,  # row 0 was probed at 5
        False,  # 7: not yet
        True,  # the best row's
        False,  # row 3 has 7 but was not probed
    ]
    probed[3] = True
    assert probed_before(5, acc_hint, probed, 9)
    assert not probed_before(0, acc_hint, probed, 9)


@pytest.mark.parametrize("seed", range(3))
def test_spin_moves_are_the_numpy_schedules(seed: int) -> None:
    """The spin's moves the free-spin check and scan share (made once per branch) against the
    numpy schedule's sigma dt: the spin rate nearest zero at the feed times the segment's length
    over the feed; none without a feed."""
    rng = np.random.default_rng(seed)
    n, b, feed = 40, 3, 0.2
    qd = rng.normal(0.0, 10.0, (8, 6, n))  # the feed alone would break the speed limits
    qs = rng.uniform(0.5, 1.0, (8, 6, n)) * rng.choice([-1.0, 1.0], (8, 6, n))
    length = rng.uniform(0.001, 0.003, n - 1)
    qdot_max = np.full(6, 3.0)
    moves = np.full(n, np.nan)
    spin_moves(qd, qs, b, feed, length, qdot_max, moves)
    sigma = spin_rate_nearest_zero(qd[b, :, :-1], qs[b, :, :-1], qdot_max, np.full(n - 1, feed))
    assert moves[0] == 0.0 and np.count_nonzero(sigma) > n // 4
    np.testing.assert_allclose(moves[1:], sigma * length / feed, rtol=1e-12, atol=0.0)
    spin_moves(qd, qs, b, 0.0, length, qdot_max, moves)
    assert not moves.any()
