"""The numeric family's compiled seeding: every seed solved at each path's first pose.

The compiled twin of :class:`~solver.families.numeric.family.NumericFamily`'s seeding and of
:func:`solver.families.numeric.ik.distinct` (robots.md section 4), each solve
:func:`solver.families.numeric.ik_kernel._levenberg_marquardt`: the same algorithm, constants
and decisions as the numpy reference the tests hold it to. Every function releases the GIL.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

from solver.families.numeric import ik_kernel
from solver.families.numeric.chain_kernel import drop_stale_cache, frames, jacobian_at, workspace
from solver.families.numeric.ik_kernel import _levenberg_marquardt, _normal

_TWO_PI = 2.0 * math.pi

drop_stale_cache(Path(__file__), Path(ik_kernel.__file__))


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _wrapped_distance(a, b, revolute):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """``ik.joint_distance`` of two configurations (n,): revolute differences wrapped."""
    total = 0.0
    for j in range(len(a)):
        d = a[j] - b[j]
        if revolute[j]:
            d = (d + math.pi) % _TWO_PI - math.pi
        total += d * d
    return math.sqrt(total)


@njit(cache=True, nogil=True, error_model="numpy")
def seed_paths(chain, seeds, more, box, rotations, positions, settings, constants):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The distinct solutions at each path's first pose, from every seed, within the joint box.

    The distinct solutions (``ik.distinct``: wrapped joint distance above ``settings[2]`` from
    every earlier kept one) fill the slots in seed order. Where the seeds found an odd number,
    the ``more`` seeds are tried after them (``ik.more_seeds``: a six-joint chain's count is
    even but at a singular pose), their new solutions in the slots that are left.

    Args:
        chain: :meth:`SerialChain.packed`.
        seeds: shape (K, n), the starts.
        more: shape (M, n), the starts tried where the count is odd (M may be 0).
        box: (lower, upper), each (n,), the joint box.
        rotations: shape (P, 3, 3), R_B_F* of each path's first waypoint.
        positions: shape (P, 3), m in {B}.
        settings: ik.SEED_ITERATIONS, ik.TRACK_ITERATIONS, ik.DISTINCT, ik.SINGULAR_RCOND,
            ik.STALL_STEPS, ik.STALL_RATIO.
        constants: as for :func:`_levenberg_marquardt`.

    Returns:
        found: shape (P, K, n), rad, unwrapped, NaN in the slots after the solutions found;
        count: shape (P,), the distinct solutions found.
    """
    n_seeds, n = seeds.shape
    n_paths = positions.shape[0]
    found = np.full((n_paths, n_seeds, n), np.nan)
    count = np.zeros(n_paths, dtype=np.int64)
    starts = np.concatenate((seeds, more))
    n_all = len(starts)
    first = (
        np.empty((n_all, n, 3)),
        np.empty((n_all, n, 3)),
        np.empty((n_all, 3, 3)),
        np.empty((n_all, 3)),
        np.empty((n_all, 6, n)),
        np.empty((n_all, 6, 6)),
    )
    _seed_all(
        chain,
        starts,
        box,
        (rotations, positions),
        settings,
        constants,
        (workspace(n), np.empty(n), first),
        (found, count),
    )
    return found, count


@njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _seed_all(chain, seeds, box, poses, settings, constants, buffers, out):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """:func:`seed_paths`' loop into its preallocated ``out`` (found, count).

    ``seeds``: the first seeds (``found``'s K), then the more seeds.

    Compiled without numba's reference counting (``_nrt=False``: it allocates nothing), which
    the inlined helpers' tuples of arrays otherwise cost at every step (atomic increments and
    decrements); the same arithmetic, the same bits. ``poses``: rotations and positions;
    ``buffers``: the chain's workspace, the iterate (n,), and ``first``: each seed's frames (axes
    (K, n, 3), origins (K, n, 3), rotation (K, 3, 3), position (K, 3)), its Jacobian at the
    flange (K, 6, n) and J J^T (K, 6, 6). A seed's frames do not depend on the pose sought, so
    they are computed once for all the paths and copied into the workspace before each
    solve's first step (``cached``): the numbers the step would compute, not computed again.
    """
    rotations, positions = poses
    found, count = out
    work, current, first = buffers
    n_all, n = seeds.shape
    n_seeds = found.shape[1]  # the first seeds; the rest are tried where their count is odd
    seed_iterations, apart = int(settings[0]), settings[2]
    stall = (int(settings[4]), settings[5])
    revolute = chain[3]
    for k in range(n_all):
        frames(chain, seeds[k], work)
        jacobian_at(revolute, work[0], work[1], work[3], work[6])
        _normal(work[6], work[7])
        _copy_frames(work, first, k, True)
    for p in range(positions.shape[0]):
        kept = 0
        for k in range(n_all):
            if k == n_seeds and kept % 2 == 0:
                break  # an even count: the more seeds are not tried
            for j in range(n):
                current[j] = seeds[k, j]
            _copy_frames(work, first, k, False)
            if not _levenberg_marquardt(
                chain,
                current,
                rotations[p],
                positions[p],
                seed_iterations,
                box,
                constants,
                work,
                True,  # the seed's frames, J and J J^T, copied in
                stall,
            ):
                continue
            new = True
            for other in range(kept):
                if _wrapped_distance(found[p, other], current, revolute) <= apart:
                    new = False
                    break
            if new and kept < n_seeds:  # more solutions than slots: the first ones kept
                for j in range(n):
                    found[p, kept, j] = current[j]
                kept += 1
        count[p] = kept


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _copy_frames(work, first, k, into_first):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Seed k's frames, J and J J^T between the workspace and ``first`` (:func:`_seed_all`).

    ``into_first``: from the workspace into row k of ``first``; else from there into it.
    """
    axes, origins, rot, pos, jac, normal = first
    for j in range(axes.shape[1]):
        for i in range(3):
            if into_first:
                axes[k, j, i], origins[k, j, i] = work[0][j, i], work[1][j, i]
            else:
                work[0][j, i], work[1][j, i] = axes[k, j, i], origins[k, j, i]
    for i in range(3):
        if into_first:
            pos[k, i] = work[3][i]
        else:
            work[3][i] = pos[k, i]
        for c in range(3):
            if into_first:
                rot[k, i, c] = work[2][i, c]
            else:
                work[2][i, c] = rot[k, i, c]
    for i in range(6):
        for c in range(jac.shape[2]):
            if into_first:
                jac[k, i, c] = work[6][i, c]
            else:
                work[6][i, c] = jac[k, i, c]
        for c in range(6):
            if into_first:
                normal[k, i, c] = work[7][i, c]
            else:
                work[7][i, c] = normal[k, i, c]
