"""The numeric family's compiled following: each slot from waypoint to waypoint of its path.

The compiled twin of :class:`~solver.families.numeric.family.NumericFamily`'s following
(robots.md section 4): each slot solved at each next waypoint from its solution at the one
before (:func:`solver.families.numeric.ik_kernel._levenberg_marquardt`; six joints from the
extrapolation of the solutions before, where the path is smooth:
:func:`~solver.families.numeric.ik_kernel.extrapolated`), its status
(:func:`~solver.families.numeric.ik_kernel.regular_status`), the same decisions as the numpy
reference the tests hold it to. Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.core.codes import UNREACHABLE
from solver.families.numeric import ik_kernel
from solver.families.numeric.chain_kernel import drop_stale_cache, frames, workspace
from solver.families.numeric.ik_kernel import (
    _levenberg_marquardt,
    extrapolated,
    regular_status,
)

_TWO_PI = 2.0 * math.pi

drop_stale_cache(Path(__file__), Path(ik_kernel.__file__))


@njit(cache=True, nogil=True, error_model="numpy")
def _follow(  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    chain,
    slot,
    rotations,
    positions,
    first,
    last,
    skip_first,
    track_iterations,
    rcond,
    revolute,
    smooth,
    constants,
    work,
    q,
    status,
    b,
    p,
):
    """One slot followed over waypoints ``first`` to ``last - 1`` of its path, into q and status.

    ``slot`` holds its solution at the waypoint before ``first``, or at ``first`` itself with
    ``skip_first`` (the path's first waypoint: the seed's solution, not solved again). Lost
    where a waypoint does not converge: ``slot`` NaN, and NaN / ``UNREACHABLE`` from there to
    ``last``. The serving loops of :func:`follow_paths` and :func:`follow_ranges`.
    """
    n = slot.shape[0]
    solved = q[:, b, p]
    if skip_first:
        frames(chain, slot, work)
    for w in range(first, last):
        solve = not (skip_first and w == first)
        predicted = solve and extrapolated(slot, solved, w, revolute, smooth)
        if solve and not _levenberg_marquardt(
            chain,
            slot,
            rotations[w],
            positions[w],
            track_iterations,
            None,
            constants,
            work,
            w > first and not predicted,  # the frames, J and J J^T of q_(w-1), from _singular
            (0, 0.0),
        ):
            slot[:] = np.nan
            for rest in range(w, last):
                status[b, p, rest] = UNREACHABLE
                for j in range(n):
                    q[j, b, p, rest] = np.nan
            return
        status[b, p, w] = regular_status(chain, rcond, work)
        for j in range(n):
            value = slot[j]
            q[j, b, p, w] = (value + math.pi) % _TWO_PI - math.pi if revolute[j] else value


@njit(cache=True, nogil=True, error_model="numpy")
def follow_paths(chain, current, rotations, positions, solve_first, settings, constants):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Each slot followed along one piece of its path, from its solution before the piece.

    A slot is followed to each next waypoint from its solution at the previous one, without the
    joint box, until it does not converge; it is then lost (NaN from there, and in every later
    piece). Six joints extrapolate from the solutions written in ``q``, this piece's only: a
    path cut in pieces gives the bits of one piece through :func:`follow_ranges`, which writes
    every piece into one array.

    Args:
        chain: :meth:`SerialChain.packed`.
        current: shape (P, K, n), rad, unwrapped, in and out: each slot's solution at the
            waypoint before the piece (``solve_first``) or at the piece's first waypoint (the
            path's first piece, from :func:`seed_paths`); NaN for a slot without one. On return,
            its solution at the piece's last waypoint, NaN where it was lost.
        rotations: shape (P, W, 3, 3), R_B_F* of the piece's waypoints.
        positions: shape (P, W, 3), m in {B}.
        solve_first: whether the piece's first waypoint is solved (every piece but the first).
        settings: as for :func:`seed_paths`.
        constants: as for :func:`_levenberg_marquardt`.

    Returns:
        q: shape (n, K, P, W), revolute joints wrapped to [-pi, pi), NaN where a slot has no
        solution; status: shape (K, P, W), ``OK``, ``SINGULAR`` or ``UNREACHABLE``.
    """
    n_paths, n_seeds, n = current.shape
    n_waypoints = positions.shape[1]
    track_iterations, rcond = int(settings[1]), settings[3]
    revolute = chain[3]
    q = np.full((n, n_seeds, n_paths, n_waypoints), np.nan)
    status = np.full((n_seeds, n_paths, n_waypoints), UNREACHABLE)
    slot = np.empty(n)
    work = workspace(n)
    for p in range(n_paths):
        for b in range(n_seeds):
            if math.isnan(current[p, b, 0]):
                continue
            slot[:] = current[p, b]
            _follow(
                chain,
                slot,
                rotations[p],
                positions[p],
                np.int64(0),  # not a literal 0: follow_ranges' signature, compiled once
                n_waypoints,
                not solve_first,
                track_iterations,
                rcond,
                revolute,
                settings[6],
                constants,
                work,
                q,
                status,
                b,
                p,
            )
            current[p, b] = slot
    return q, status


@njit(cache=True, nogil=True, error_model="numpy")
def follow_ranges(chain, current, rotations, positions, start, stop, out, settings, constants):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Each slot followed from its own waypoint ``start`` to before ``stop``, into q and status.

    :func:`follow_paths` with a piece per slot: the same decisions and numbers, a slot's
    waypoints solved as they would be in any pieces (the first piece's first waypoint is the
    seed's solution, not solved again; six joints extrapolate from the solutions ``out``
    holds before ``start``, written by the pieces before).

    Args:
        chain: :meth:`SerialChain.packed`.
        current: shape (P, K, n), in and out: each slot's solution at waypoint ``start - 1``
            (at waypoint 0 where ``start`` is 0); on return at ``stop - 1``, NaN where lost.
        rotations: shape (P, W, 3, 3), R_B_F* of every waypoint of the paths.
        positions: shape (P, W, 3), m in {B}.
        start: shape (K, P), the first waypoint of each slot's piece.
        stop: shape (K, P), the waypoint after its last; a slot with ``stop <= start``, or a
            NaN solution, is not followed.
        out: q (n, K, P, W), written with the pieces' solutions, wrapped (left alone
            elsewhere), and status (K, P, W), their statuses (``UNREACHABLE`` once lost).
        settings: as for :func:`seed_paths`.
        constants: as for :func:`_levenberg_marquardt`.
    """
    n_paths, n_seeds, n = current.shape
    q, status = out
    track_iterations, rcond = int(settings[1]), settings[3]
    revolute = chain[3]
    slot = np.empty(n)
    work = workspace(n)
    for p in range(n_paths):
        for b in range(n_seeds):
            first, last = start[b, p], stop[b, p]
            if last <= first or math.isnan(current[p, b, 0]):
                continue
            slot[:] = current[p, b]
            _follow(
                chain,
                slot,
                rotations[p],
                positions[p],
                first,
                last,
                first == 0,
                track_iterations,
                rcond,
                revolute,
                settings[6],
                constants,
                work,
                q,
                status,
                b,
                p,
            )
            current[p, b] = slot
