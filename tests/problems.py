"""The solver's entry points called with loose keyword options, for the tests written that way.

Since the problem object (spec/architecture.md section 2) the entry points take a
:class:`PathProblem` (robot, waypoints, passes, :class:`PathOptions`) instead of the keyword
options ``branch``, ``max_joint_step``, ``spin_mode`` and ``passes``. These helpers build the
problem from those keywords and call the real entry point, so the known answers and invariants
of the tests written before stay as they were; new tests build problems themselves.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from solver.core.robots import Robot
from solver.core.spatial import Placement
from solver.optimise import optimize
from solver.optimise.optimum import PlacementOptimum
from solver.path import capability_map as capability
from solver.path import evaluate, placements
from solver.path.problem import PathOptions, PathProblem

OPTIONS = ("branch", "max_joint_step", "spin_mode", "blend_length", "cell")


def problem(
    robot: Robot,
    waypoints: np.ndarray,
    *,
    passes: Sequence[tuple[int, int]] | None = None,
    **options: Any,
) -> PathProblem:
    """The problem of ``robot`` along ``waypoints`` with the options given by keyword."""
    return PathProblem.of(robot, waypoints, PathOptions(**options), passes=passes)


def _split(keywords: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """The path options among ``keywords``, and the rest."""
    options = {k: v for k, v in keywords.items() if k in OPTIONS}
    return options, {k: v for k, v in keywords.items() if k not in OPTIONS}


def evaluate_path(
    robot: Robot, waypoints: np.ndarray, placement: Placement, **keywords: Any
) -> evaluate.PathEvaluation:
    """:func:`solver.path.evaluate.evaluate_path` with keyword options (and ``passes``)."""
    passes = keywords.pop("passes", None)
    return evaluate.evaluate_path(problem(robot, waypoints, passes=passes, **keywords), placement)


def capability_map(
    robot: Robot, waypoints: np.ndarray, **keywords: Any
) -> capability.CapabilityMap:
    """:func:`solver.path.capability_map.capability_map` with keyword options (and ``passes``)."""
    passes = keywords.pop("passes", None)
    options, rest = _split(keywords)
    return capability.capability_map(problem(robot, waypoints, passes=passes, **options), **rest)


def optimize_placement(robot: Robot, waypoints: np.ndarray, **keywords: Any) -> PlacementOptimum:
    """:func:`solver.optimise.optimize.optimize_placement` with keyword options."""
    passes = keywords.pop("passes", None)
    options, rest = _split(keywords)
    return optimize.optimize_placement(problem(robot, waypoints, passes=passes, **options), **rest)


def prepare_path(
    robot: Robot, waypoints: np.ndarray, *, passes: Sequence[tuple[int, int]] | None = None
) -> PathProblem:
    """The problem with default options (its path prepared), for :func:`evaluate_placements`."""
    prepared = problem(robot, waypoints, passes=passes)
    _ = prepared.prepared
    return prepared


def evaluate_placements(
    robot: Robot, path: PathProblem, cells: np.ndarray, **keywords: Any
) -> placements.PlacementResults:
    """:func:`solver.path.placements.evaluate_placements` of a :func:`prepare_path` problem."""
    if path.robot is not robot:
        raise ValueError("the problem was prepared for another robot")
    options, rest = _split(keywords)
    return placements.evaluate_placements(path.with_options(**options), cells, **rest)
