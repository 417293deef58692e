"""Numeric inverse kinematics of a serial chain, batched: damped least squares on the log error.

robots.md section 4. Each problem is one flange pose T* in {B} and one start q0; the error is the
pose's log in {B} at the flange, e = [p* - p; log(R* R^T)], and each iteration takes the
Levenberg-Marquardt step (Sugihara, "Solvability-unconcerned inverse kinematics by the
Levenberg-Marquardt method", IEEE T-RO 2011, eq. 11 and 20):

    dq = J^T (J J^T + lambda I)^-1 e,     lambda = c E + DAMPING_FLOOR,   E = |e|^2 / 2

with J the Jacobian at the flange in {B} axes. The damping shrinks with the error, so the last
iterations are Gauss-Newton steps (of least joint motion for dof > 6) and converge
quadratically. Problems are solved together and drop out of the batch when converged.

Layout: batch first: q (M, n), rotations (M, 3, 3), positions (M, 3).
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from solver.core.codes import OK, OK_MIRRORED, SINGULAR
from solver.core.progress import Progress
from solver.core.spatial import wrap_angle
from solver.families.numeric.chain import SerialChain

# A problem is solved when every component of e is below this (m and rad): FK(IK(T)) then equals
# T to ~1e-12, well inside the 1e-9 the tests ask for.
TOLERANCE = 1e-12
# lambda's floor (m^2): keeps J J^T + lambda I regular at a singular start.
DAMPING_FLOOR = 1e-9
# c, the damping per unit of E: 0.1 found 3 % more of UR5's branches from 32 seeds than
# Sugihara's 1 (and 0.01 or 10 fewer), on 200 random poses.
DAMPING_SCALE = 0.1
# Iterations from a seed of the joint box (the first waypoint), and from the previous waypoint.
SEED_ITERATIONS = 150
TRACK_ITERATIONS = 12
# A seed is given up at every STALL_STEPS-th step where |e|_inf is above STALL_RATIO times what
# it was STALL_STEPS steps before: most seeds that do not converge sit at a joint limit, where
# the clipped steps no longer shrink e, and took all SEED_ITERATIONS steps (83 % of the UR5's
# seeding steps on the ERK grid, 91 % of the Panda's).
STALL_STEPS = 10
STALL_RATIO = 0.8
# Six joints: a waypoint is solved from the quartic extrapolation of the five solutions before
# it, q_(w-1) + 4 s_1 - 6 s_2 + 4 s_3 - s_4 (s_i the joint steps between them, newest first),
# where that step differs from the last one, s_1, by at most PREDICT_SMOOTH times s_1's largest
# joint move (a smooth stretch); elsewhere (a corner, the first five waypoints, a redundant
# chain, whose solution depends on its start) from q_(w-1) itself. The UR5 as a URDF on the ERK
# path: from q_(w-1) three steps left |e|_inf at about 1e-5, 1e-10, 1e-16; from the quartic
# extrapolation (about 2e-7 away) one step leaves about 2e-15, under TOLERANCE: one chain
# evaluation and one solve a waypoint instead of two and three (:func:`extrapolated`). The cubic
# one (about 1e-6 away) left about 1e-13 after its step: near a stretched elbow (the UR5 at x
# -0.5, y 0.55, z -0.1, yaw 2.5 on the ERK path) mu_path came 2.0e-10 off the closed form's, the
# quartic 4.5e-11 (from q_(w-1) under 7e-12; a cell of that grid is 1.1e-10 off with any start).
PREDICT_SMOOTH = 0.5
# Seeds tried where a six-joint chain's first ones found an odd number of solutions
# (:func:`more_seeds`), and the seed of their scrambled Sobol sequence.
MORE_SEEDS = 128
MORE_SEEDS_SEED = 0
# Two solutions are distinct when their wrapped joint distance exceeds this (rad, m).
DISTINCT = 1e-3
# A solution whose Jacobian has sigma_min / sigma_max below this is singular (the analytic
# families' 1e-7 on |sin q5| and |sin q3|, as a condition number).
SINGULAR_RCOND = 1e-7
# Below this many rows, converged problems stay in solve's batch (frozen) instead of being
# copied out. Copying rows by an index array releases the GIL for a moment (numpy's take and
# put), and a thread that does that every few hundred microseconds while holding the GIL the
# rest of the time starves every other thread: a waiting thread asks for the GIL only after a
# full switch interval with no hand-over, and each brief release is a hand-over. Tracking a
# 5,000-waypoint path on the Jaco2 kept /healthz waiting 20 to 300 ms at a time.
COMPACT_MIN_ROWS = 64


def rotation_log(rotation: np.ndarray) -> np.ndarray:
    """The rotation vector of rotations (M, 3, 3): log(R) in the frame R is expressed in, rad.

    Exact at every angle in [0, pi]: near pi (where the skew part vanishes) the axis comes from
    the symmetric part, (R + R^T) / 2 - cos(theta) I = (1 - cos(theta)) a a^T.
    """
    skew = 0.5 * np.stack(
        [
            rotation[:, 2, 1] - rotation[:, 1, 2],
            rotation[:, 0, 2] - rotation[:, 2, 0],
            rotation[:, 1, 0] - rotation[:, 0, 1],
        ],
        axis=-1,
    )  # sin(theta) a
    sin = np.linalg.norm(skew, axis=-1)
    cos = 0.5 * (np.trace(rotation, axis1=1, axis2=2) - 1.0)
    angle = np.arctan2(sin, cos)
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = np.where(sin > 1e-300, angle / sin, 1.0)  # theta / sin(theta), 1 at 0
    result = factor[:, None] * skew
    far = cos < -0.9  # theta > 2.69 rad: sin(theta) a loses the axis' digits
    if np.any(far):
        sym = 0.5 * (rotation[far] + rotation[far].transpose(0, 2, 1))
        sym -= cos[far, None, None] * np.eye(3)  # (1 - cos) a a^T
        column = np.argmax(np.diagonal(sym, axis1=1, axis2=2), axis=-1)
        axis = np.take_along_axis(sym, column[:, None, None], axis=2)[..., 0]
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        sign = np.where(np.einsum("mi,mi->m", axis, skew[far]) < 0.0, -1.0, 1.0)
        result[far] = (sign * angle[far])[:, None] * axis
    return result


def pose_error(
    rotation: np.ndarray, position: np.ndarray, target_rotation: np.ndarray, target: np.ndarray
) -> np.ndarray:
    """The error e = [p* - p; log(R* R^T)], (M, 6), m and rad, {B} axes at the flange."""
    relative = target_rotation @ rotation.transpose(0, 2, 1)
    return np.concatenate([target - position, rotation_log(relative)], axis=-1)


def solve(
    chain: SerialChain,
    start: np.ndarray,
    target_rotation: np.ndarray,
    target_position: np.ndarray,
    *,
    iterations: int,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
    frozen: np.ndarray | None = None,
    stall: tuple[int, float] = (0, 0.0),
    progress: Progress | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Levenberg-Marquardt from each start to its target, batched.

    A problem's iterates depend on its own row only. Converged rows stay in the batch, frozen,
    until at most half of it still iterates and it holds at least ``COMPACT_MIN_ROWS`` rows:
    only then are the rest copied out (see ``COMPACT_MIN_ROWS``).

    Args:
        chain: the arm's chain.
        start: shape (M, n), rad (m for prismatic joints), finite.
        target_rotation: shape (M, 3, 3), R_B_F*.
        target_position: shape (M, 3), m in {B}.
        iterations: the most steps any problem takes.
        lower: shape (n,), rad; with ``upper``, every iterate is clipped into the box (joint
            limits kept); ``None`` leaves the joints free (tracking checks the limits later).
        upper: shape (n,), rad.
        frozen: shape (M,), bool: rows left at their start and reported not converged (a
            tracked branch already lost); ``None`` solves every row.
        stall: (steps, ratio): a problem is given up (not converged) at every ``steps``-th step
            where its |e|_inf is above ``ratio`` times what it was ``steps`` steps before;
            steps 0: never (``STALL_STEPS``, ``STALL_RATIO`` for the seeds).
        progress: called with the fraction of ``iterations`` done after each step (it may
            raise :class:`solver.core.progress.Cancelled`).

    Returns:
        q: shape (M, n), the last iterate; converged: shape (M,), bool, |e|_inf < TOLERANCE.
    """
    q = np.array(start, dtype=float)
    converged = np.zeros(len(q), dtype=bool)
    iterating = np.ones(len(q), dtype=bool) if frozen is None else ~frozen
    given_up = np.zeros(len(q), dtype=bool) if frozen is None else frozen.copy()
    checkpoint = np.full(len(q), np.inf)  # |e|_inf at the last stall check
    rows: np.ndarray | None = None  # after a compaction: the problem of each batch row
    batch_q, batch_rotation, batch_position = q, target_rotation, target_position
    stall_steps, stall_ratio = stall
    for step in range(iterations + 1):
        if not iterating.any():
            break
        jacobian, rotation, position = chain.jacobian(batch_q)
        error = pose_error(rotation, position, batch_rotation, batch_position)
        largest = np.abs(error).max(axis=-1)
        iterating &= largest >= TOLERANCE
        if not iterating.any() or step == iterations:
            break
        if stall_steps > 0 and step % stall_steps == 0:
            stalled = iterating & (largest > stall_ratio * checkpoint)
            given_up |= stalled
            iterating &= ~stalled
            checkpoint = largest
            if not iterating.any():
                break
        damping = DAMPING_SCALE * 0.5 * np.einsum("mi,mi->m", error, error) + DAMPING_FLOOR
        normal = jacobian @ jacobian.transpose(0, 2, 1) + damping[:, None, None] * np.eye(6)
        dq = (jacobian.transpose(0, 2, 1) @ np.linalg.solve(normal, error[..., None]))[..., 0]
        moved = batch_q + dq
        if lower is not None and upper is not None:
            moved = np.clip(moved, lower, upper)
        batch_q = np.where(iterating[:, None], moved, batch_q)
        if progress is not None:
            progress((step + 1) / iterations)
        if len(batch_q) >= COMPACT_MIN_ROWS and 2 * np.count_nonzero(iterating) <= len(batch_q):
            q, converged = _settle(rows, q, converged, batch_q, iterating | given_up)
            rows = (np.arange(len(q)) if rows is None else rows)[iterating]
            batch_q, batch_rotation = batch_q[iterating], batch_rotation[iterating]
            batch_position, checkpoint = batch_position[iterating], checkpoint[iterating]
            given_up, iterating = given_up[iterating], iterating[iterating]
    return _settle(rows, q, converged, batch_q, iterating | given_up)


def _settle(
    rows: np.ndarray | None,
    q: np.ndarray,
    converged: np.ndarray,
    batch_q: np.ndarray,
    unsolved: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Write the batch's iterates back to their problems and which of them converged.

    Args:
        rows: the problem of each batch row; ``None`` while the batch is every problem.
        q: shape (M, n), the problems' iterates.
        converged: shape (M,), bool.
        batch_q: shape (len(batch), n), the batch's iterates.
        unsolved: shape (len(batch),), bool, the batch rows still iterating, given up or
            frozen: the others converged.

    Returns:
        q (M, n) and converged (M,), updated.
    """
    if rows is None:
        return batch_q.copy(), ~unsolved
    q[rows] = batch_q
    converged[rows] = ~unsolved
    return q, converged


def extrapolated(last: np.ndarray, history: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where each row's next solve starts: the extrapolation of its solutions, or its last one.

    The rule of :data:`PREDICT_SMOOTH` (six joints only: the caller asks for no other).

    Args:
        last: shape (M, n), each row's solution at the waypoint before (unwrapped).
        history: shape (M, 5, n), its solutions at the five waypoints before, oldest first and
            unwrapped (the last of them is ``last``); NaN where it has none.

    Returns:
        start: shape (M, n); predicted: shape (M,), bool, the rows that start extrapolated.
    """
    s1, s2, s3, s4 = (history[:, k] - history[:, k - 1] for k in (4, 3, 2, 1))
    step = 4.0 * s1 - 6.0 * s2 + 4.0 * s3 - s4
    with np.errstate(invalid="ignore"):
        largest = np.max(np.abs(s1), axis=1)
        deviation = np.max(np.abs(step - s1), axis=1)
        predicted = (largest > 0.0) & (deviation <= PREDICT_SMOOTH * largest)
    return np.where(predicted[:, None], last + step, last), predicted


def seeds(count: int, *, lower: np.ndarray, upper: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """``count`` deterministic starts that cover every joint's range: shape (count, n).

    A two-level fractional factorial design (Box, Hunter & Hunter, "Statistics for
    Experimenters", ch. 6) at the quartiles of each joint's range: ``count`` = 2^m runs, the
    first m joints at every combination of their lower and upper quartile, each further joint
    at the quartile that the product of the others' signs (all, then all but one in turn)
    gives. So each half of each joint's range holds count / 2 seeds, and any m joints see
    every combination of their halves, which is what tells an arm's branches apart (shoulder,
    elbow, wrist). On 200 random poses of the FANUC M10iA, 32 such seeds found 95.7 % of the
    solutions within the limits that the closed form gives, 32 scrambled Sobol points 89.8 %.

    A revolute joint whose range holds a full turn is seeded over [-pi, pi] only (every angle
    has a copy there; the others are 2 pi away).
    """
    low, high = _seeded_range(lower, upper, revolute)
    box: np.ndarray = low + (0.5 + 0.25 * _design(count, len(lower))) * (high - low)
    return box


def more_seeds(*, lower: np.ndarray, upper: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """The seeds tried where a six-joint chain's first seeds found an odd number of solutions.

    A six-joint chain's inverse kinematics has an even number of real solutions at any pose
    but a singular one: they are the real roots of a polynomial system of 16 complex roots for
    six revolute joints (Raghavan & Roth, "Inverse kinematics of the general 6R manipulator",
    J. Mech. Des. 1993; 16, 8 or 2 with prismatic joints among them), and the complex ones come
    in conjugate pairs. An odd count found says a solution was missed (or lies outside the
    joint box, which hides it).

    :data:`MORE_SEEDS` points of a scrambled Sobol sequence (a fixed seed) over the range the
    first seeds cover. Short of the closed form's solutions within the limits, at 3,000 random
    poses of the UR5 as a URDF and 2,000 of each OPW arm as a URDF (2026-12-07): 32 seeds alone
    119 poses (UR5), 291 (FANUC M20iA), 54 (KUKA KR 16-2), 130 (ABB IRB 4600); with 64 more at
    the eighths of each range (the first seeds' design there) 16, 112, 13, 43; with these 12,
    50, 11, 39. The seeding then took 15 %, 48 %, 10 % and 35 % longer on those poses (the
    closed form's own count is odd at 89 of the IRB 4600's: a solution outside its box).
    """
    low, high = _seeded_range(lower, upper, revolute)
    return np.asarray(low + _sobol(len(lower)) * (high - low))


@functools.cache
def _sobol(dimensions: int) -> np.ndarray:
    """:data:`MORE_SEEDS` scrambled Sobol points in [0, 1)^dimensions, the same each time.

    scipy.stats is imported here, at a six-joint numeric arm's first seeding: at the module's
    import it loaded scipy.optimize into every command of dtf-place (tests/service/test_cli.py).
    """
    from scipy.stats import qmc  # noqa: PLC0415 - heavy, and only numeric arms need it

    sobol = qmc.Sobol(d=dimensions, scramble=True, seed=MORE_SEEDS_SEED)
    points = np.asarray(sobol.random(MORE_SEEDS), dtype=float)
    points.setflags(write=False)
    return points


def _design(count: int, n: int) -> np.ndarray:
    """:func:`seeds`' two-level fractional factorial design: (count, n) of -1 and 1."""
    base = min(max(count.bit_length() - 1, 0), n)  # m, with 2^m <= count
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=base)), dtype=float)
    columns = [signs[:, j] for j in range(base)]
    for extra in range(n - base):  # the product of all the base columns, then all but one
        kept = signs if extra == 0 else np.delete(signs, (extra - 1) % base, axis=1)
        columns.append(np.prod(kept, axis=1))
    design: np.ndarray = np.resize(np.stack(columns, axis=1), (count, n))  # beyond 2^m: again
    return design


def _seeded_range(
    lower: np.ndarray, upper: np.ndarray, revolute: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's range the seeds cover: [-pi, pi] for a revolute joint of a full turn."""
    full_turn = revolute & (upper - lower >= 2 * math.pi)
    low = np.where(full_turn, np.maximum(lower, -math.pi), lower)
    high = np.where(full_turn, np.minimum(upper, math.pi), upper)
    return low, high


def joint_distance(a: np.ndarray, b: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """Euclidean joint distance, revolute differences wrapped to [-pi, pi): (..., n) -> (...)."""
    difference = a - b
    difference = np.where(revolute, wrap_angle(difference), difference)
    distance: np.ndarray = np.linalg.norm(difference, axis=-1)
    return distance


def distinct(
    q: np.ndarray, found: np.ndarray, revolute: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The distinct solutions of each problem, in seed order, packed to the front.

    Args:
        q: shape (P, K, n), the solution from each of K seeds at P poses.
        found: shape (P, K), bool, where a seed converged.
        revolute: shape (n,), bool.

    Returns:
        slots: shape (P, K, n), the distinct solutions first (each the first seed that reached
        it), NaN after them; count: shape (P,), how many.
    """
    n_poses, n_seeds, _ = q.shape
    keep = found.copy()
    for k in range(1, n_seeds):
        near = joint_distance(q[:, :k], q[:, k : k + 1], revolute) <= DISTINCT  # (P, k)
        keep[:, k] &= ~np.any(near & keep[:, :k], axis=1)
    order = np.argsort(~keep, axis=1, kind="stable")  # kept seeds first, in seed order
    slots = np.take_along_axis(q, order[..., None], axis=1)
    count = keep.sum(axis=1)
    slots[np.arange(n_seeds)[None, :] >= count[:, None]] = np.nan
    return slots, count


def is_singular(chain: SerialChain, q: np.ndarray) -> np.ndarray:
    """Where the Jacobian of q (M, n) loses rank: sigma_min / sigma_max < SINGULAR_RCOND."""
    jacobian, _, _ = chain.jacobian(q)
    return _singular(jacobian)


def _singular(jacobian: np.ndarray) -> np.ndarray:
    """:func:`is_singular` of Jacobians (M, 6, n)."""
    squares = np.linalg.eigvalsh(jacobian @ jacobian.transpose(0, 2, 1))  # sigma^2, ascending
    singular: np.ndarray = squares[:, 0] < SINGULAR_RCOND**2 * squares[:, -1]
    return singular


def regular_status(chain: SerialChain, q: np.ndarray) -> np.ndarray:
    """The status of solutions q (M, n), finite: ``SINGULAR``, else ``OK`` or ``OK_MIRRORED``.

    ``OK_MIRRORED`` where a six-joint chain's det J < 0 (J (6, 6) at the flange, {B} axes; its
    sign is the same at any point and in any axes); seven or more joints have no det J and are
    ``OK``. The sign is well defined where J is regular (sigma_min / sigma_max at least
    ``SINGULAR_RCOND``), so LU's rounding cannot flip it.
    """
    jacobian, _, _ = chain.jacobian(q)
    mirrored = np.linalg.det(jacobian) < 0.0 if chain.dof == 6 else np.zeros(len(q), dtype=bool)
    status: np.ndarray = np.where(
        _singular(jacobian), SINGULAR, np.where(mirrored, OK_MIRRORED, OK)
    )
    return status
