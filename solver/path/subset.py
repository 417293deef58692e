"""A problem on some of its waypoints: their rows only, for the optimisers' active sets.

The optimum of a long program is bound by a few waypoints (issue 23). The optimisers therefore
work on a subset of the waypoints, then evaluate the whole path at their answer and add the
waypoints that bind there (:mod:`solver.optimise.active_set`). :func:`on_waypoints` is that
subset as a problem of its own: every kept waypoint keeps its pose, its task requirements
(t_hat, h: made from the whole path, not from the subset's neighbours) and its limits' rows; a
segment is kept only where both its ends are (elsewhere the subset has a break, like a rapid
between passes: no step bound, and a free spin restarts); an acceleration row (motion.md
section 2) only where its five stencil waypoints are all kept. A waypoint's speed bound in the
subset is then exactly the whole path's at the same joint path, and the subset drops rows: its
optimum is at or above the whole path's.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from solver.path.blend_stencil import BlendStencil
from solver.path.limits import JointAccelerationLimit, Limit
from solver.path.prepare import PreparedPath
from solver.path.problem import PathProblem


def checked_rows(rows: np.ndarray, n_waypoints: int) -> np.ndarray:
    """Waypoint indices as a sorted array of distinct ints in [0, N).

    Raises:
        ValueError: an index outside the path, or none at all (a programming error: the
            optimisers make the indices).
    """
    kept = np.unique(np.asarray(rows, dtype=np.int64))
    if not kept.size or kept[0] < 0 or kept[-1] >= n_waypoints:
        raise ValueError(f"waypoint subset {kept[:3]}... must lie in [0, {n_waypoints})")
    return kept


def _prepared_on(path: PreparedPath, rows: np.ndarray) -> PreparedPath:
    """The prepared path's arrays at ``rows``; a segment kept where both its ends are."""
    joined = np.diff(rows) == 1
    segment_in_pass = joined & path.segment_in_pass[rows[:-1]]
    return dataclasses.replace(
        path,
        n_waypoints=len(rows),
        tool_rotation=path.tool_rotation[rows],
        flange_rotation=path.flange_rotation[rows],
        flange_position=path.flange_position[rows],
        tool_position=path.tool_position[rows],
        u_T=path.u_T[rows],
        u_R=path.u_R[rows],
        h=path.h[rows],
        twist=path.twist[rows],
        pure_rotation=path.pure_rotation[rows],
        segment_in_pass=segment_in_pass,
    )


def _stencil_on(stencil: BlendStencil, rows: np.ndarray, n_waypoints: int) -> BlendStencil:
    """The stencil's rows whose five waypoints are all in ``rows``, renumbered to the subset."""
    position = np.full(n_waypoints, -1, dtype=np.int64)
    position[rows] = np.arange(len(rows))
    index = position[stencil.index]  # (K, 5), -1 where a waypoint is left out
    whole = np.all(index >= 0, axis=1)
    return BlendStencil(
        stencil.blend_length,
        position[stencil.waypoints[whole]],
        index[whole],
        stencil.weight[whole],
    )


def _limit_on(limit: Limit, rows: np.ndarray, n_waypoints: int) -> Limit:
    """The limit on the subset: its rows there (a limit without path data is the same)."""
    if isinstance(limit, JointAccelerationLimit):
        return JointAccelerationLimit(
            limit.qddot_max, _stencil_on(limit.stencil, rows, n_waypoints)
        )
    return limit


def on_waypoints(problem: PathProblem, rows: np.ndarray) -> PathProblem:
    """The problem on the waypoints ``rows`` (indices into the whole path), their rows only.

    Its waypoint k is the whole path's ``rows[k]`` (sorted, distinct). Its prepared path and
    limits are the whole path's at those waypoints (see the module's docstring), not made anew
    from the subset (which would take t_hat from the wrong neighbours).

    Raises:
        ValueError: ``rows`` empty or outside the path.
    """
    path = problem.prepared
    kept = checked_rows(rows, path.n_waypoints)
    subset = dataclasses.replace(problem, waypoints=problem.waypoints[kept], passes=None)
    subset.__dict__["prepared"] = _prepared_on(path, kept)
    subset.__dict__["limits"] = tuple(
        _limit_on(limit, kept, path.n_waypoints) for limit in problem.limits
    )
    return subset
