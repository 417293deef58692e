"""The narrower searches a request implies, whose answers its own must not fall below.

A method's answer is the best of local searches from its starts, and widening the box moves the
starts: the answer over a wider box can land below the answer over a narrower one inside it.
cam.md promises two such orders: with spin bounds containing 0 the optimum is never below the
optimum without spin (section 3), and a spin path's optimum is never below the constant-spin
optimum (section 4). Measured before this module (the optimiser audit, stop 53): a UR5e with
acceleration limits, spin bounds [-0.5, 0.5] added to a box, casadi 0.99 % below the answer
without spin; 0.17 % and 0.61 % on two more boxes.

So the front door (:func:`solver.optimise.optimize.optimize_placement`) also runs, with the
same method, each narrower search the request implies, and judges its candidates with the
others: the answer is then at least each narrower search's own. The work estimate counts them
(:func:`solver.optimise.work.work_of`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from solver.optimise.search_space import PlacementBounds

WITHOUT_SPIN = "without spin"
CONSTANT_SPIN = "with a constant spin"


@dataclass(frozen=True)
class Narrower:
    """A search inside the request's, run beside it.

    Attributes:
        name: what it is, as the work estimate and the answer's status say it.
        bounds: its box (inside the request's).
        max_spin_step: its spin path's largest step (rad), or None for one spin.
    """

    name: str
    bounds: PlacementBounds
    max_spin_step: float | None


def narrower_searches(bounds: PlacementBounds, max_spin_step: float | None) -> tuple[Narrower, ...]:
    """The searches the request's answer must not fall below, widest first.

    A spin path's constant-spin search over the same box (cam.md section 4), and where the spin
    bounds are a range containing 0, the search with the spin fixed at 0 (section 3).
    """
    searches = []
    if max_spin_step is not None:
        searches.append(Narrower(CONSTANT_SPIN, bounds, None))
    low, high = bounds.spin
    if low < high and low <= 0.0 <= high:
        searches.append(Narrower(WITHOUT_SPIN, dataclasses.replace(bounds, spin=(0.0, 0.0)), None))
    return tuple(searches)
