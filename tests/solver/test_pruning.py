"""The map kernels' pruning keeps the answer: :func:`solver.kernels.cell.choice_holds`.

A pruned branch is known only by a bound on its mu_path (or as failing); with joint
acceleration limits (:mod:`solver.kernels.acc_cells`) by a bound on its mu_acc, the branches
chosen by mu_acc with ``ACC_TIE_RTOL``. Where ``choice_holds`` says the answer stands, the
branch :func:`solver.path.tracking.choose_branch` (the numpy rule, the reference) picks must be
the same whatever each pruned branch's index: at its bound, below it, or infeasible. The
kernel-vs-pipeline tests (test_map_kernel.py, test_free_spin_kernel.py) hold the whole
kernels; here the cases are built to sit on the tie.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from solver.core.codes import ACC_TIE_RTOL, FEASIBLE, REASON_UNREACHABLE, TIE_RTOL
from solver.kernels.cell import PRUNED, choice_holds
from solver.path.tracking import choose_branch

N = 6  # rows: 3**6 outcomes of the pruned rows per case


def _case(rng: np.random.Generator, tie: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows followed (alive or failed) and pruned, values on and around a tie of 0.3 m/s."""
    steps = np.array([-1e-3, -3.0, -1.0, -0.4, 0.0, 0.4, 1.0, 3.0, 1e-3 / tie]) * tie
    values = 0.3 * (1.0 + rng.choice(steps, size=N))
    kind = rng.choice(3, size=N)  # 0 followed and feasible, 1 followed and failed, 2 pruned
    kind[rng.integers(N)] = 0  # pruning needs a feasible row
    alive = kind == 0
    why = np.where(kind == 2, PRUNED, np.where(kind == 1, REASON_UNREACHABLE, FEASIBLE))
    return alive, why.astype(np.int64), values


@pytest.mark.parametrize("tie", [TIE_RTOL, ACC_TIE_RTOL])  # mu_path; mu_acc (acceleration limits)
@pytest.mark.parametrize("seed", range(40))
def test_a_held_choice_is_the_choice_whatever_the_pruned_rows(seed: int, tie: float) -> None:
    rng = np.random.default_rng(seed)
    held = 0
    for _ in range(50):
        alive, why, slowest = _case(rng, tie)
        failed = np.where(alive, -1, 0)
        pick = int(choose_branch(slowest, alive, failed, tie))  # what write_cell takes
        if not choice_holds(alive, why, slowest, slowest, tie, pick):
            continue
        held += 1
        pruned = np.flatnonzero(why == PRUNED)
        for outcome in itertools.product(("bound", "below", "failed"), repeat=len(pruned)):
            value, feasible = slowest.copy(), alive.copy()
            for i, how in zip(pruned, outcome, strict=True):
                feasible[i] = how != "failed"
                value[i] = slowest[i] if how == "bound" else slowest[i] * (1 - tie)
            chosen = choose_branch(value, feasible, np.where(feasible, -1, 0), tie)
            assert int(chosen) == pick, (slowest, why, outcome)
    assert held > 0  # the cases reach the check's both answers (next test)


def test_a_pruned_row_that_may_win_is_not_held() -> None:
    # Row 0 pruned at a bound above the pick's (row 1): it may be the highest, and first.
    alive = np.array([False, True, True])
    why = np.array([PRUNED, FEASIBLE, FEASIBLE], dtype=np.int64)
    slowest = np.array([0.31, 0.30, 0.29])
    assert not choice_holds(alive, why, slowest, slowest, TIE_RTOL, 1)
    # Below the tie of row 1 it cannot.
    slowest[0] = 0.30 * (1 - 3 * TIE_RTOL)
    assert choice_holds(alive, why, slowest, slowest, TIE_RTOL, 1)
    # After the pick, a bound within the tie cannot take its place; beyond it, it may.
    why = np.array([FEASIBLE, FEASIBLE, PRUNED], dtype=np.int64)
    alive = np.array([False, True, False])
    slowest = np.array([0.0, 0.30, 0.30 * (1 + 0.4 * TIE_RTOL)])
    assert choice_holds(alive, why, slowest, slowest, TIE_RTOL, 1)
    slowest[2] = 0.30 * (1 + 2 * TIE_RTOL)
    assert not choice_holds(alive, why, slowest, slowest, TIE_RTOL, 1)
