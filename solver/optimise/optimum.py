"""What the optimiser answers: the optimum as the evaluator sees it, and what the solver did.

:func:`solver.optimise.optimize.optimize_placement` returns one :class:`PlacementOptimum`
(qpsolvers' ``Solution``): ``found`` says whether any placement tried is feasible, and the
placement, mu_path and evaluation are the evaluator's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.spatial import Placement
from solver.optimise.failures import SearchFailure
from solver.path.evaluate import PathEvaluation


@dataclass(frozen=True)
class SolverReport:
    """What the optimiser did: its name, the status of the winning solve, iterations, seconds."""

    name: str
    status: str
    iterations: int
    seconds: float


@dataclass(frozen=True)
class PlacementOptimum:
    """The best placement found, as the evaluator sees it (qpsolvers' ``Solution``).

    Attributes:
        found: whether any placement the search tried (the start included) is feasible; when
            not, placement, mu_path and evaluation are None.
        placement: the optimum (inside the bounds).
        mu_path: m/s, the evaluator's mu_path there.
        evaluation: the evaluator's whole answer there.
        start: the start placement; start_mu_path its mu_path (None when infeasible).
        improvement_percent: 100 (index / start index - 1), the index mu_acc with
            acceleration limits, else mu_path; None without a feasible start.
        solver: what the optimiser did.
        symmetric: whether the search used the (r, psi) symmetry.
        spins: shape (N,), rad, each waypoint's spin on top of the placement's, when the
            answer came from the spin-path NLP (cam.md section 4); else None.
        joint_path: shape (N, n), rad, for a redundant arm (dof > 6) the joint path mu_path is
            at (the NLP's own, or the tracked one where that is faster); None for dof <= 6.
        mu_acc: m/s, with acceleration limits the evaluator's mu_acc there (what the search
            maximised, motion.md section 3); None without them.
        start_mu_acc: m/s, with acceleration limits the start's mu_acc (what
            ``improvement_percent`` compares with); None without them or a feasible start.
        active_waypoints: the waypoints in the final active set of the local solve that gave
            the answer (:mod:`solver.optimise.active_set`); None where the answer came from the
            whole path or from no local solve.
        start_evaluation: the evaluator's answer at the start (its reason and failed
            waypoint when it does not run).
        failure: when nothing was found, the most common failure of the placements judged
            (:mod:`solver.optimise.failures`); None when found.
    """

    found: bool
    placement: Placement | None
    mu_path: float | None
    evaluation: PathEvaluation | None
    start: Placement
    start_mu_path: float | None
    improvement_percent: float | None
    solver: SolverReport
    symmetric: bool
    spins: np.ndarray | None = None
    joint_path: np.ndarray | None = None
    mu_acc: float | None = None
    start_mu_acc: float | None = None
    active_waypoints: int | None = None
    start_evaluation: PathEvaluation | None = None
    failure: SearchFailure | None = None
