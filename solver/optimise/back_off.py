"""A local solve's answer that collides, backed off towards its start (cell.md, the optimisers).

IPOPT and SLSQP follow one IK branch's speeds and know nothing of the cell: from a
collision-free start they may climb straight into a fixture, where the best placement is on the
way, at the last point clear of it. :func:`back_off` finds that point by bisection on the
segment from the start to the answer, each point judged by the evaluator with the cell (the
``auto`` branch). Without a cell nothing is backed off, so no answer changes.
"""

from __future__ import annotations

import numpy as np

from solver.optimise.candidate import Candidate
from solver.optimise.search_space import PlacementBounds, placement_rows
from solver.path.placement_evaluator import PlacementEvaluator
from solver.path.problem import PathProblem

BACK_OFF_STEPS = 12  # bisections: the point found is within 1/4096 of the segment of the edge
BACK_OFF_PLACEMENTS = 2 + BACK_OFF_STEPS  # evaluated, one at a time: the answer, start, steps
BACK_OFF_STATUS = "{}: it is not clear of the cell; the last clear point towards it from its start"


def backs_off(problem: PathProblem) -> bool:
    """Whether a local solve's answer is backed off (:func:`back_off`): with a cell only."""
    return problem.options.cell is not None


def back_off(
    problem: PathProblem,
    bounds: PlacementBounds,
    start: np.ndarray,
    answer: Candidate,
) -> Candidate | None:
    """The last feasible point from ``start`` towards ``answer``, where the answer is not feasible.

    Args:
        problem: the problem with its cell (the options' branch is ignored: ``auto``).
        bounds: the box (both ends are clamped into it).
        start: the decision vector the local solve started from.
        answer: the local solve's candidate.

    Returns:
        the candidate at the last feasible point found by BACK_OFF_STEPS bisections (at most
        BACK_OFF_PLACEMENTS placements, one at a time); None without a cell, where the answer
        is feasible, or where the start is not.
    """
    if not backs_off(problem):
        return None
    evaluate = PlacementEvaluator(problem)

    def feasible(vector: np.ndarray) -> bool:
        return bool(np.isfinite(evaluate(placement_rows(vector[None])).feed_index[0]))

    begin, end = bounds.clamp(np.asarray(start, float)), bounds.clamp(answer.vector)
    if feasible(end) or not feasible(begin):
        return None
    clear, blocked = 0.0, 1.0
    for _ in range(BACK_OFF_STEPS):
        middle = (clear + blocked) / 2
        if feasible(begin + middle * (end - begin)):
            clear = middle
        else:
            blocked = middle
    return Candidate(begin + clear * (end - begin), BACK_OFF_STATUS.format(answer.status))
