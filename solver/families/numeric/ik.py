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

import math

import numpy as np

from solver.families.numeric.chain import SerialChain
from solver.spatial import wrap_angle

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
# Two solutions are distinct when their wrapped joint distance exceeds this (rad, m).
DISTINCT = 1e-3
# A solution whose Jacobian has sigma_min / sigma_max below this is singular (the analytic
# families' 1e-7 on |sin q5| and |sin q3|, as a condition number).
SINGULAR_RCOND = 1e-7


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
) -> tuple[np.ndarray, np.ndarray]:
    """Levenberg-Marquardt from each start to its target, batched.

    Args:
        chain: the arm's chain.
        start: shape (M, n), rad (m for prismatic joints), finite.
        target_rotation: shape (M, 3, 3), R_B_F*.
        target_position: shape (M, 3), m in {B}.
        iterations: the most steps any problem takes.
        lower: shape (n,), rad; with ``upper``, every iterate is clipped into the box (joint
            limits kept); ``None`` leaves the joints free (tracking checks the limits later).
        upper: shape (n,), rad.

    Returns:
        q: shape (M, n), the last iterate; converged: shape (M,), bool, |e|_inf < TOLERANCE.
    """
    q = np.array(start, dtype=float)
    converged = np.zeros(len(q), dtype=bool)
    active = np.arange(len(q))
    for step in range(iterations + 1):
        jacobian, rotation, position = chain.jacobian(q[active])
        error = pose_error(rotation, position, target_rotation[active], target_position[active])
        done = np.abs(error).max(axis=-1) < TOLERANCE
        converged[active[done]] = True
        active, jacobian, error = active[~done], jacobian[~done], error[~done]
        if active.size == 0 or step == iterations:
            break
        damping = DAMPING_SCALE * 0.5 * np.einsum("mi,mi->m", error, error) + DAMPING_FLOOR
        normal = jacobian @ jacobian.transpose(0, 2, 1) + damping[:, None, None] * np.eye(6)
        dq = (jacobian.transpose(0, 2, 1) @ np.linalg.solve(normal, error[..., None]))[..., 0]
        moved = q[active] + dq
        if lower is not None and upper is not None:
            moved = np.clip(moved, lower, upper)
        q[active] = moved
    return q, converged


def seeds(
    count: int, *, lower: np.ndarray, upper: np.ndarray, revolute: np.ndarray, seed: int
) -> np.ndarray:
    """``count`` deterministic starts in the joint box: scrambled Sobol points, shape (count, n).

    A revolute joint whose range holds a full turn is seeded over [-pi, pi] only (every angle
    has a copy there; the others are 2 pi away).
    """
    from scipy.stats import qmc

    full_turn = revolute & (upper - lower >= 2 * math.pi)
    low = np.where(full_turn, np.maximum(lower, -math.pi), lower)
    high = np.where(full_turn, np.minimum(upper, math.pi), upper)
    points = qmc.Sobol(d=len(lower), scramble=True, seed=seed).random(count)
    box: np.ndarray = low + points * (high - low)
    return box


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
    squares = np.linalg.eigvalsh(jacobian @ jacobian.transpose(0, 2, 1))  # sigma^2, ascending
    singular: np.ndarray = squares[:, 0] < SINGULAR_RCOND**2 * squares[:, -1]
    return singular
