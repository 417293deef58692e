"""What a method proposes for the evaluator to judge, and the settings of one search.

Every method (:mod:`solver.optimise.methods`) takes the problem, the bounds and a
:class:`Search`, and returns :class:`Candidate` decision vectors; the front door
(:func:`solver.optimise.optimize.optimize_placement`) evaluates each and keeps the best.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.parallel import SERIAL, TaskRunner
from solver.core.progress import Progress
from solver.optimise.failures import Tried

# The candidate of a search whose path turns on the spot somewhere: no placement is better.
ZERO_SPEED = "mu_path is 0 everywhere: the path turns on the spot"


@dataclass(frozen=True)
class Candidate:
    """What a method proposes, for the evaluator to judge.

    Attributes:
        vector: the decision vector (:mod:`solver.optimise.search_space`).
        status: what the method said of it.
        spins: shape (N,), rad, each waypoint's spin on top of the placement's (spin path).
        joint_path: shape (N, n), rad, the NLP's own joint path for a redundant arm (dof > 6),
            judged as it is (:mod:`solver.path.joint_path`) beside the tracked one.
        rows: the whole-path waypoints of the active set the local solve ended on
            (:mod:`solver.optimise.active_set`); None where it solved the whole path or none.
    """

    vector: np.ndarray
    status: str
    spins: np.ndarray | None = None
    joint_path: np.ndarray | None = None
    rows: np.ndarray | None = None


@dataclass(frozen=True)
class Search:
    """The settings of one search, beside the problem and the bounds.

    Attributes:
        symmetric: whether joint 1 turns about the base z axis (search over (r, psi)).
        near: rad, the polar angle of the start: each arc's point nearest it is reported.
        max_spin_step: rad, > 0: a spin per waypoint with steps at most this (cam.md section
            4, casadi only); None keeps one spin.
        max_coarse_cells: the largest coarse map the casadi method may make.
        max_coarse_poses: the most placement-waypoint pairs of that map (None: no limit),
            each weighed by the family's cost.
        max_search_poses: the same for the scipy method's differential evolution.
        max_solver_seconds: the longest one IPOPT solve may take (None: IPOPT's default).
        progress: called with the fraction done; a ``Cancelled`` it raises stops the search.
        runner: where the placements of maps and generations run; the same answer on any.
        active_set: the local solves work on the waypoints that bind
            (:mod:`solver.optimise.active_set`); False solves the whole path (the reference).
        tried: where the search keeps the placements it tries on the whole path (its coarse
            map's, its evolution's), for a failure's tally (:mod:`solver.optimise.failures`);
            None keeps none.
        seed_map: the scipy method also starts from the coarse map's maxima, as the casadi
            method does (:func:`solver.optimise.work.seeds_from_map`).
    """

    symmetric: bool
    near: float
    max_spin_step: float | None = None
    max_coarse_cells: int = 50_000
    max_coarse_poses: int | None = None
    max_search_poses: int | None = None
    max_solver_seconds: float | None = None
    progress: Progress | None = None
    runner: TaskRunner = SERIAL
    active_set: bool = True
    tried: Tried | None = None
    seed_map: bool = False
