"""A six-joint map's compiled pruning keeps the answer: :func:`solver.path.bounded.choice_holds`.

A dropped slot is known only by a bound on its mu_path (V_max's least value over the waypoints
followed, with a margin for rounding). Where ``choice_holds`` says a placement's pick stands,
the branch :func:`solver.path.tracking.choose_branch` (the reference rule) picks must be the
same whatever each dropped slot's mu_path: at its bound (rounded up within the margin), below
it, or infeasible. The whole pass is held to following every slot cell by cell in
``tests/solver/families/test_numeric_pruned_map.py``; here the cases sit on the tie.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from solver.core.codes import TIE_RTOL
from solver.path.bounded import MARGIN, choice_holds
from solver.path.tracking import choose_branch

N = 6  # slots: 3**dropped outcomes per case


def _case(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """mu (followed: value or -inf), bounds and dropped slots, on and around a tie at 0.3."""
    steps = np.array([-1e-3, -3e-12, -1e-12, -4e-13, 0.0, 4e-13, 1e-12, 3e-12, 1e-3])
    values = 0.3 * (1.0 + rng.choice(steps, size=N))
    kind = rng.choice(3, size=N)  # 0 followed and feasible, 1 followed and failed, 2 dropped
    mu = np.where(kind == 0, values, -np.inf)
    return mu[:, None], values[:, None], (kind == 2)[:, None]


@pytest.mark.parametrize("seed", range(40))
def test_a_held_choice_is_the_choice_whatever_the_dropped_slots(seed: int) -> None:
    rng = np.random.default_rng(seed)
    held = refused = 0
    for _ in range(50):
        mu, bound, dropped = _case(rng)
        if not choice_holds(mu, bound, dropped)[0]:
            refused += 1
            continue
        held += 1
        feasible = mu > -np.inf
        pick = int(choose_branch(mu, feasible, np.where(feasible, -1, 0))[0])
        slots = np.flatnonzero(dropped[:, 0])
        outcomes = ("bound", "rounded", "below", "failed")
        for outcome in itertools.product(outcomes, repeat=len(slots)):
            value = mu.copy()
            for i, how in zip(slots, outcome, strict=True):
                scale = {"bound": 1.0, "rounded": 1.0 + MARGIN, "below": 1.0 - 1e-12}.get(how)
                value[i] = -np.inf if scale is None else bound[i] * scale
            alive = value > -np.inf
            chosen = choose_branch(value, alive, np.where(alive, -1, 0))
            assert int(chosen[0]) == pick, (mu, bound, dropped, outcome)
    assert held > 0 and refused > 0  # the cases reach both answers


def test_a_dropped_slot_that_may_win_is_refused() -> None:
    mu = np.array([[-np.inf], [0.30], [0.29]])
    dropped = np.array([[True], [False], [False]])
    # Slot 0 (before the pick, slot 1) dropped at a bound that may tie: refused.
    assert not choice_holds(mu, np.array([[0.30], [0.30], [0.29]]), dropped)[0]
    # Below the tie of slot 1 it cannot take its place.
    below = 0.30 * (1 - 3 * TIE_RTOL)
    assert choice_holds(mu, np.array([[below], [0.30], [0.29]]), dropped)[0]
    # After the pick, a bound within the tie cannot take its place; beyond it, it may.
    mu = np.array([[-np.inf], [0.30], [-np.inf]])
    dropped = np.array([[False], [False], [True]])
    assert choice_holds(mu, np.array([[0.0], [0.30], [0.30 * (1 + 0.5 * TIE_RTOL)]]), dropped)[0]
    assert not choice_holds(mu, np.array([[0.0], [0.30], [0.30 * (1 + 2 * TIE_RTOL)]]), dropped)[0]


def test_a_placement_without_a_feasible_slot_holds_only_without_drops() -> None:
    mu = np.full((3, 1), -np.inf)
    bound = np.full((3, 1), 0.3)
    assert choice_holds(mu, bound, np.zeros((3, 1), dtype=bool))[0]
    assert not choice_holds(mu, bound, np.array([[False], [True], [False]]))[0]
