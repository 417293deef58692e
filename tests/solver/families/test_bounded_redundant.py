"""A seven-joint map's one-pass pruning keeps the answer, and a weaker drop rule would not.

:mod:`solver.families.numeric.bounded_redundant_kernel` drops a slot on its bound alone
(:func:`hopeless`); the pipeline checks the pick afterwards
(:func:`solver.path.bounded.pick_stands`).
Here: the rule never drops a slot that could be the pick (:func:`choose_branch`, the reference
rule, whatever the dropped slot's mu_path below its bound), and on the Panda and the xArm7 every
dropped slot's bound is at least the mu_path the pipeline finds following it to the end (bounds
halved are not). The whole pass is held to following every branch cell by cell in
``test_numeric_pruned_map.py``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from solver.core.codes import TIE_RTOL
from solver.families.numeric.bounded_redundant_kernel import hopeless
from solver.families.numeric.family import NumericFamily
from solver.families.numeric.following import REDUNDANT_MARGIN
from solver.path.pipeline import run_chunk
from solver.path.placed import check_placements
from solver.path.problem import PathProblem
from solver.path.tracking import choose_branch
from tests.solver.families.test_numeric_pruned_map import numeric, placements_of
from tests.solver.test_evaluate import load_path

STEPS = (-1e-3, -1e-10, -3e-12, -1e-12, -4e-13, 0.0, 4e-13, 1e-12, 3e-12, 1e-10, 1e-3)
"""Relative offsets of a slot's bound from the candidate's mu_path: on and around the tie."""


@pytest.mark.parametrize("margin", [0.0, REDUNDANT_MARGIN])
def test_a_dropped_slot_is_never_the_pick(margin: float) -> None:
    best = 0.3
    dropped = kept = 0
    for slot, candidate in ((0, 1), (2, 1)):
        for step in STEPS:
            bound = best * (1.0 + step)
            if not hopeless(slot, bound, candidate, best, TIE_RTOL, margin):
                kept += 1
                continue
            dropped += 1
            # Its mu_path: at its bound (rounded up within the margin), below it, or infeasible.
            for value in (bound * (1.0 + margin), bound, bound * (1.0 - 1e-12), -np.inf):
                mu = np.full((3, 1), -np.inf)
                mu[candidate, 0], mu[slot, 0] = best, value
                feasible = mu > -np.inf
                pick = choose_branch(mu, feasible, np.where(feasible, -1, 0))
                assert int(pick[0]) == candidate, (slot, step, value)
    assert dropped > 0 and kept > 0  # the cases reach both answers


def test_no_candidate_drops_nothing() -> None:
    assert not hopeless(2, 0.0, -1, -np.inf, TIE_RTOL, REDUNDANT_MARGIN)
    assert not hopeless(2, 0.0, 1, np.inf, TIE_RTOL, REDUNDANT_MARGIN)


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_a_dropped_slot_s_bound_is_above_its_mu_path(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each dropped slot, followed to the end by the pipeline, has mu_path at most its bound.

    The bound rule the pass rests on; bounds halved (half the least V_max followed) fail it.
    """
    problem = PathProblem.of(numeric(name), load_path("curved_line"))
    cells = check_placements(placements_of(name))
    passes: list[tuple[np.ndarray, ...]] = []
    follow_bounded = NumericFamily.follow_bounded

    def kept(self: NumericFamily, *args: Any) -> tuple[np.ndarray, ...]:
        result = follow_bounded(self, *args)
        passes.append(result)
        return result

    monkeypatch.setattr(NumericFamily, "follow_bounded", kept)
    run_chunk(problem, cells, prune=True)
    [(_, _, bound, dropped)] = passes
    every = run_chunk(problem, cells, prune=False)  # each slot followed to the end
    rows = len(every.mu_path)
    assert not dropped[rows:].any()  # slots after those are empty at every placement
    bound, dropped = bound[:rows], dropped[:rows]
    feasible = dropped & (every.mu_path > -np.inf)
    assert feasible.sum() >= 10  # dropped slots that the pipeline finds feasible
    assert np.all(every.mu_path[feasible] <= bound[feasible])
    assert np.any(every.mu_path[feasible] > 0.5 * bound[feasible])
