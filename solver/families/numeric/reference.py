"""The numpy reference of the numeric family's solve: seeding, following, the status of each q.

robots.md section 4. :class:`solver.families.numeric.family.NumericFamily` runs these when it
is not compiled (a chain with mimic joints, or ``compiled=False``): the compiled chain
(:mod:`solver.families.numeric.ik_kernel`) is tested against them.
"""

from __future__ import annotations

import numpy as np

from solver.core.codes import UNREACHABLE
from solver.core.progress import Progress
from solver.core.spatial import wrap_angle
from solver.families.numeric import ik
from solver.families.numeric.chain import SerialChain
from solver.families.numeric.velocity import in_chunks


def seeded(
    chain: SerialChain,
    starts: tuple[np.ndarray, np.ndarray],
    box: tuple[np.ndarray, np.ndarray],
    rotation: np.ndarray,
    position: np.ndarray,
    progress: Progress | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Distinct solutions within the limits from every seed: (P, 3, 3), (P, 3) -> slots.

    Where the seeds found an odd number of solutions, the more seeds are tried too
    (:func:`ik.more_seeds`), their new solutions after the others, in the slots left.

    Args:
        chain: the arm's chain.
        starts: the seeds (K, n) and the more seeds (M, n; M may be 0).
        box: (lower, upper), each (n,): every iterate is clipped into the joint box.
        rotation: shape (P, 3, 3), R_B_F* of each pose.
        position: shape (P, 3), m in {B}.
        progress: called after each iteration of the seeds' solve.

    Returns:
        slots (P, K, n), rad, NaN after the solutions found; count (P,).
    """
    seeds, more = starts
    q, converged = _solved(chain, seeds, box, rotation, position, progress)
    slots, count = ik.distinct(q, converged, chain.q_revolute)
    odd = np.flatnonzero(count % 2 == 1) if len(more) else np.empty(0, dtype=int)
    if odd.size:
        q_more, converged_more = _solved(chain, more, box, rotation[odd], position[odd])
        every, total = ik.distinct(
            np.concatenate([q[odd], q_more], axis=1),
            np.concatenate([converged[odd], converged_more], axis=1),
            chain.q_revolute,
        )
        slots[odd] = every[:, : len(seeds)]  # more solutions than slots: the first ones kept
        count[odd] = np.minimum(total, len(seeds))
    return slots, count


def _solved(
    chain: SerialChain,
    seeds: np.ndarray,
    box: tuple[np.ndarray, np.ndarray],
    rotation: np.ndarray,
    position: np.ndarray,
    progress: Progress | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Each seed solved at each pose, in the joint box: q (P, K, n) and converged (P, K)."""
    n_poses, n_seeds = len(position), len(seeds)
    start = np.broadcast_to(seeds, (n_poses, n_seeds, chain.dof)).reshape(-1, chain.dof)
    q, converged = ik.solve(
        chain,
        start,
        np.repeat(rotation, n_seeds, axis=0),
        np.repeat(position, n_seeds, axis=0),
        iterations=ik.SEED_ITERATIONS,
        lower=box[0],
        upper=box[1],
        stall=(ik.STALL_STEPS, ik.STALL_RATIO),
        progress=progress,
    )
    return q.reshape(n_poses, n_seeds, chain.dof), converged.reshape(n_poses, n_seeds)


def followed(
    chain: SerialChain,
    start: np.ndarray,
    rotations: np.ndarray,
    positions: np.ndarray,
    *,
    progress: Progress | None = None,
) -> np.ndarray:
    """Each branch followed from its first solution, NaN from the waypoint where it is lost.

    Args:
        chain: the arm's chain.
        start: shape (M, n), the branches' solutions at the first waypoint.
        rotations: shape (M, W, 3, 3), R_B_F* of each branch's path.
        positions: shape (M, W, 3), m in {B}.
        progress: called after each waypoint with the fraction of waypoints followed.

    Returns:
        shape (M, W, n). A lost branch stays in the batch, frozen, until at least half of
        it is lost and it holds ``ik.COMPACT_MIN_ROWS`` rows, for the reason given there.
    """
    n_waypoints = positions.shape[1]
    track = np.full((len(start), n_waypoints, chain.dof), np.nan)
    rows = np.arange(len(start))  # the branch of each batch row
    local = track.copy()  # the batch's rows of track
    local[:, 0] = current = start
    lost = np.zeros(len(start), dtype=bool)
    for waypoint in range(1, n_waypoints):
        if lost.all():
            break
        if progress is not None:
            progress(waypoint / n_waypoints)
        begin = current  # six joints: from the extrapolation where the path is smooth
        if chain.dof == 6 and waypoint >= 5:
            begin, _ = ik.extrapolated(current, local[:, waypoint - 5 : waypoint])
        solved, converged = ik.solve(
            chain,
            begin,
            rotations[:, waypoint],
            positions[:, waypoint],
            iterations=ik.TRACK_ITERATIONS,
            frozen=lost,
        )
        lost |= ~converged
        current = np.where(lost[:, None], current, solved)  # a lost row keeps a finite q
        local[:, waypoint] = np.where(lost[:, None], np.nan, solved)
        if len(rows) >= ik.COMPACT_MIN_ROWS and 2 * np.count_nonzero(lost) >= len(rows):
            track[rows] = local
            keep = ~lost
            rows, local, current, lost = rows[keep], local[keep], current[keep], lost[keep]
            rotations, positions = rotations[keep], positions[keep]
    track[rows] = local
    return track


def wrapped_with_status(
    chain: SerialChain, q: np.ndarray, progress: Progress | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Revolute joints wrapped to [-pi, pi) and the status of each solution, q (..., n)."""
    flat = q.reshape(-1, chain.dof)
    status = np.full(len(flat), UNREACHABLE)
    solved = np.flatnonzero(np.isfinite(flat).all(axis=-1))
    for rows in in_chunks(solved, progress):
        status[rows] = ik.regular_status(chain, flat[rows])
    wrapped = np.where(chain.q_revolute, wrap_angle(q), q)
    return wrapped, status.reshape(q.shape[:-1])
