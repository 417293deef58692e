"""The Decomposed Twist Feasibility (DTF) index at one configuration (spec section 3).

Given the task direction (u_T, u_R) and the ratio h = V / Omega of a path segment, the DTF is the
largest linear tool speed V_max such that the twist [V u_T; (V / h) u_R] needs no joint faster
than its limit. For a non-singular 6-DOF arm it has a closed form (Sensors 2022 eq. 30); for every
arm it is the optimum of a linear programme, solved here with HiGHS.

Shapes: a Jacobian is (6, n), linear rows first, at the tool point with {B} axes
(LOCAL_WORLD_ALIGNED); joint speeds are rad/s; batched functions put the batch axes first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from solver.core.exceptions import InvalidInputError

UNIT_TOLERANCE = 1e-3  # cam.md section 6: a direction within it is normalised, beyond refused
# Below this reciprocal condition number a 6x6 Jacobian is treated as singular and the LP is used.
SINGULAR_RCOND = 1e-12
JACOBIAN_NOISE = 1e-12
"""Relative to its largest, a coefficient of J diag(qdot_max) at most this is the LP's zero
(:func:`lp_speed`): far above J's rounding (a few 1e-16 of its largest), far below any length
or speed an arm has beside its largest (lengths within 100 m, speed limits within their
bounds)."""

Method = Literal["auto", "closed_form", "lp"]


@dataclass(frozen=True)
class DtfResult:
    """The DTF at one configuration.

    Attributes:
        v_max: largest feasible linear tool speed (m/s); 0 for pure reorientation (h = 0).
        omega_max: the angular speed that goes with it, V_max / h (rad/s); 0 for h = inf.
        qdot: shape (n,), rad/s, the joint speeds at that maximum; one sits on its limit.
        limiting_joint: index of the joint on its limit.
        method: ``"closed_form"`` (J^-1) or ``"lp"`` (the linear programme).
    """

    v_max: float
    omega_max: float
    qdot: np.ndarray
    limiting_joint: int
    method: Literal["closed_form", "lp"]


def _unit(vector: np.ndarray | list[float], field: str) -> np.ndarray:
    """``vector`` normalised, if it is a finite 3-vector of unit norm to 1e-3 (cam.md section 6).

    Papers print 4 decimals and CAM writes 4-6: the Sensors 2022 table 4 directions typed as
    printed are off unit by up to about 1e-4.
    """
    arr = np.asarray(vector, dtype=float)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise InvalidInputError(field, f"needs 3 finite numbers, got {arr.tolist()}")
    largest = float(np.max(np.abs(arr)))
    # Scaled first, so that neither 1e-200 nor 1e200 under- or overflows the squares.
    norm = largest * float(np.linalg.norm(arr / largest)) if largest > 0.0 else 0.0
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise InvalidInputError(
            field, f"norm is {norm:.6g}; a unit vector is needed (within 1e-3, then normalised)"
        )
    return arr / norm


def twist_per_unit_speed(
    u_T: np.ndarray | list[float] | None, u_R: np.ndarray | list[float] | None, h: float
) -> np.ndarray:
    """Task twist direction t_hat = [u_T; u_R / h] (spec section 3).

    Args:
        u_T: shape (3,), unit direction of the linear velocity in {B}; unused when h = 0.
        u_R: shape (3,), unit direction of the angular velocity in {B}; unused when h = inf.
        h: V / Omega in metres (>= 0); ``math.inf`` for pure translation, 0 for pure
            reorientation, in which case the twist is per unit angular speed, [0; u_R].

    Returns:
        shape (6,): [m/s; rad/s] per m/s of linear speed (per rad/s when h = 0).

    Raises:
        InvalidInputError: a direction that is not a unit vector, or h < 0 or NaN.
    """
    if not (h >= 0.0):
        raise InvalidInputError(
            "h", f"h = {h:.6g} m; it must be >= 0 (or null for pure translation)"
        )
    twist = np.zeros(6)
    if h > 0.0:
        twist[:3] = _unit(np.zeros(3) if u_T is None else u_T, "u_T")
    if math.isfinite(h):
        rotation = _unit(np.zeros(3) if u_R is None else u_R, "u_R")
        with np.errstate(over="ignore"):
            twist[3:] = rotation if h == 0.0 else rotation / h
    if not np.all(np.isfinite(twist)):
        raise InvalidInputError(
            "h", f"h = {h:.6g} m is too small to divide by; use 0 for pure reorientation"
        )
    return twist


def closed_form_batch(
    jacobian: np.ndarray, twist: np.ndarray, qdot_max: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spec section 3, closed form, batched: qd = J^-1 t_hat, speed = 1 / ||W qd||_inf.

    Args:
        jacobian: shape (..., 6, 6), non-singular, {B} axes at the tool point.
        twist: shape (..., 6), t_hat per unit speed.
        qdot_max: shape (6,), rad/s.

    Returns:
        speed: shape (...), the largest feasible speed (m/s, or rad/s for h = 0);
        qdot: shape (..., 6), rad/s at that speed; limiting: shape (...), the joint on its limit.
    """
    qd_unit = np.linalg.solve(jacobian, twist[..., None])[..., 0]
    ratio = np.abs(qd_unit) / qdot_max
    limiting = np.argmax(ratio, axis=-1)
    worst = np.take_along_axis(ratio, limiting[..., None], axis=-1)[..., 0]
    with np.errstate(divide="ignore"):
        speed = 1.0 / worst
    return speed, qd_unit * speed[..., None], limiting


def decomposed_speed(
    jacobian: np.ndarray, u_T: np.ndarray, u_R: np.ndarray, h: float, qdot_max: np.ndarray
) -> float:
    """Sensors 2022 eq. (30): V_max = || W (J~_T^+ u_T + h^-1 J~_R^+ u_R) ||_inf^-1.

    J~_T = J_T P_R is the translational Jacobian restricted to the null space of J_R (P_R the
    projector onto it), and J~_R = J_R P_T likewise (eq. 23); for a non-singular 6x6 J their
    pseudo-inverses are the two column blocks of J^-1.

    Args:
        jacobian: shape (6, 6), non-singular.
        u_T: shape (3,), unit linear direction in {B}.
        u_R: shape (3,), unit angular direction in {B}.
        h: V / Omega (m), > 0 (inf allowed).
        qdot_max: shape (6,), rad/s.
    """
    j_t, j_r = jacobian[:3], jacobian[3:]
    eye = np.eye(jacobian.shape[1])
    project_null_r = eye - np.linalg.pinv(j_r) @ j_r
    project_null_t = eye - np.linalg.pinv(j_t) @ j_t
    joint_speeds = np.linalg.pinv(j_t @ project_null_r) @ u_T
    if math.isfinite(h):
        joint_speeds = joint_speeds + np.linalg.pinv(j_r @ project_null_t) @ (u_R / h)
    return float(1.0 / np.max(np.abs(joint_speeds) / qdot_max))


def lp_speed(
    jacobian: np.ndarray, twist: np.ndarray, *, qdot_max: np.ndarray
) -> tuple[float, np.ndarray]:
    """Spec section 3, exact for every n: max s s.t. J qdot = s t_hat, |qdot| <= qdot_max.

    Args:
        jacobian: shape (6, n).
        twist: shape (6,), t_hat.
        qdot_max: shape (n,), rad/s.

    Returns:
        The optimum s and the joint speeds qdot there, shape (n,).
    """
    # Solved in scaled variables, x = qdot / qdot_max in [-1, 1] and t / max|t|, so that a tiny h
    # (u_R / h large) or unusual limits do not reach HiGHS as extreme coefficients.
    import scipy.optimize  # 0.27 s to import: only where a redundant or singular arm needs it

    n = jacobian.shape[1]
    scale = float(np.max(np.abs(twist)))
    cost = np.zeros(n + 1)
    cost[-1] = -1.0
    weighted = jacobian * qdot_max
    # The Jacobian's rounding is no constraint: at a singular configuration written with a turn
    # (sin 2 pi is -2.4e-16) J holds ~1e-16 where it holds 0 at the same configuration without
    # it, and the row scaling below made a row of such noise a constraint of unit size (the
    # UR5e at q = 0 had V_max 0.391, the same pose with q2 = 2 pi 0.0; audit 23).
    weighted[np.abs(weighted) <= JACOBIAN_NOISE * np.max(np.abs(weighted))] = 0.0
    a_eq = np.hstack([weighted, -twist[:, None] / scale])
    # Each row to its largest coefficient (the same equalities): a robot of hundreds of metres
    # with speed limits of thousands of rad/s put coefficients of 1e6 beside ones of 1e-3, and
    # HiGHS stopped without proving its answer (a contract test's case: a 500).
    largest = np.max(np.abs(a_eq), axis=1, keepdims=True)
    a_eq = a_eq / np.where(largest > 0.0, largest, 1.0)
    # and s to its column's largest, so that s is of the joints' size (s = s' / s_scale)
    s_scale = float(np.max(np.abs(a_eq[:, -1])))
    a_eq[:, -1] /= s_scale
    bounds = [(-1.0, 1.0)] * n + [(0.0, None)]
    result = None
    for method in ("highs", "highs-ipm"):  # the dual simplex, then the interior point method
        result = scipy.optimize.linprog(
            cost,
            A_eq=a_eq,
            b_eq=np.zeros(6),
            bounds=bounds,
            method=method,
            options={"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10},
        )
        if result.status == 0:
            break
    assert result is not None
    if result.status != 0:  # the origin is feasible and s bounded: the numbers defeat HiGHS
        raise InvalidInputError(
            "robot",
            "the DTF LP could not be solved to its tolerances at this configuration (HiGHS: "
            f"{result.message}); its Jacobian times the speed limits spans "
            f"{float(np.min(largest)):.3g} to {float(np.max(largest)):.3g} a row: check the "
            "robot's lengths (m) and speed limits (rad/s)",
        )
    # + 0.0: HiGHS answers -0.0 where the optimum is 0 (a chain that cannot move along t_hat)
    return float(result.x[-1]) / s_scale / scale + 0.0, np.asarray(result.x[:n]) * qdot_max + 0.0


def dtf(
    jacobian: np.ndarray,
    *,
    u_T: np.ndarray | list[float] | None,
    u_R: np.ndarray | list[float] | None,
    h: float,
    qdot_max: np.ndarray | list[float],
    method: Method = "auto",
) -> DtfResult:
    """The DTF index: Sensors 2022 eq. (29)-(33), ERK 2021 eq. (18).

    ``auto`` uses the closed form for a non-singular 6x6 Jacobian and the LP otherwise (redundant
    arms, singular configurations).

    Args:
        jacobian: shape (6, n), {B} axes at the tool point, linear rows first.
        u_T: shape (3,), unit linear direction; unused when h = 0.
        u_R: shape (3,), unit angular direction; unused when h = inf.
        h: V / Omega (m), >= 0; ``math.inf`` for pure translation, 0 for pure reorientation.
        qdot_max: shape (n,), rad/s, > 0.
        method: ``"auto"``, ``"closed_form"`` or ``"lp"``.

    Raises:
        InvalidInputError: bad directions, h, limits, or ``closed_form`` asked for where J is not
            square and invertible.
    """
    jac = np.asarray(jacobian, dtype=float)
    limits = np.asarray(qdot_max, dtype=float)
    n = jac.shape[1] if jac.ndim == 2 else -1
    if jac.shape != (6, n) or not np.all(np.isfinite(jac)):
        raise InvalidInputError("jacobian", f"{jac.shape=}, needs (6, n) finite values")
    if limits.shape != (n,) or not np.all(np.isfinite(limits)) or np.any(limits <= 0):
        raise InvalidInputError("qdot_max", f"{limits.shape=}, needs ({n},) values > 0")
    twist = twist_per_unit_speed(u_T, u_R, h)
    square_regular = n == 6 and np.linalg.cond(jac) * SINGULAR_RCOND < 1.0
    if method == "closed_form" and not square_regular:
        raise InvalidInputError(
            "method", "closed_form needs a non-singular 6x6 Jacobian; use lp or auto"
        )
    if method == "closed_form" or (method == "auto" and square_regular):
        speed_arr, qdot_arr, limiting_arr = closed_form_batch(jac, twist, limits)
        speed, qdot, limiting = float(speed_arr), qdot_arr, int(limiting_arr)
        used: Literal["closed_form", "lp"] = "closed_form"
    else:
        speed, qdot = lp_speed(jac, twist, qdot_max=limits)
        limiting = int(np.argmax(np.abs(qdot) / limits))
        used = "lp"
    if h == 0.0:
        return DtfResult(0.0, speed, qdot, limiting, used)
    omega = 0.0 if math.isinf(h) else speed / h
    return DtfResult(speed, omega, qdot, limiting, used)


def yoshikawa(jacobian: np.ndarray) -> float:
    """Yoshikawa's manipulability w = sqrt(det(J J^T)) (Sensors 2022 eq. 4)."""
    jac = np.asarray(jacobian, dtype=float)
    return float(math.sqrt(max(np.linalg.det(jac @ jac.T), 0.0)))


def chiu(jacobian: np.ndarray, twist_direction: np.ndarray) -> float:
    """Chiu's velocity transmission ratio [t^T (J J^T)^-1 t]^(-1/2), t = t_hat / |t_hat|.

    Sensors 2022 eq. (6). It mixes metres and radians in one norm, which is why DTF exists;
    reported for comparison only. 0 when t is outside the range of J.
    """
    jac = np.asarray(jacobian, dtype=float)
    t = np.asarray(twist_direction, dtype=float)
    t = t / np.max(np.abs(t))  # first, so that the norm cannot overflow
    t = t / np.linalg.norm(t)
    solution, _, rank, _ = np.linalg.lstsq(jac @ jac.T, t, rcond=None)
    if rank < 6 and np.linalg.norm(jac @ np.linalg.pinv(jac) @ t - t) > 1e-9:
        return 0.0
    return float(1.0 / math.sqrt(float(t @ solution)))
