"""The numeric family's joint speeds: J^-1 t (six joints), the DTF LP's (more), J's null space.

robots.md section 4: a batched 6 x 6 solve for six joints; for more, the joint speeds of the
exact DTF LP (:mod:`solver.core.dtf_redundant`), which the pipeline's ratio turns into V_max
unchanged. :class:`solver.families.numeric.family.NumericFamily` delegates here.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import NamedTuple

import numpy as np

from solver.core.dtf_redundant import redundant_speed
from solver.core.kernel_arrays import kernel_array
from solver.core.progress import Progress
from solver.families.numeric import chain_kernel, redundant_kernel
from solver.families.numeric.chain import SerialChain

CHUNK_ROWS = 2048
"""Configurations checked (singularity, joint speeds) between two progress reports: about
0.2 s for seven joints under load, so that a cancelled evaluation stops within a second."""


class VelocityChain(NamedTuple):
    """The chain, its packed form for the compiled kernels, and whether to use them."""

    chain: SerialChain
    packed: tuple[np.ndarray, ...]
    compiled: bool

    @property
    def dof(self) -> int:
        """Number of joints."""
        return self.chain.dof


def joint_speeds_per_unit_twist(
    arm: VelocityChain,
    q: np.ndarray,
    twist: np.ndarray,
    tool_point: np.ndarray,
    *,
    qdot_max: np.ndarray | None = None,
    progress: Progress | None = None,
) -> np.ndarray:
    """J^-1 t (six joints) or the exact DTF LP's joint speeds per unit speed (more).

    See :meth:`KinematicsFamily.joint_speeds_per_unit_twist`. Only configurations with
    finite joints are computed; the others come back NaN. With ``progress``, CHUNK_ROWS
    configurations at a time, ``progress`` called after each (the same numbers).

    For dof > 6 without ``qdot_max``, the least-norm J^+ t (the free spin's direction).
    """
    shape = np.broadcast_shapes(q.shape[1:], twist.shape[1:], tool_point.shape[1:])
    q_flat = np.moveaxis(np.broadcast_to(q, (arm.dof, *shape)), 0, -1).reshape(-1, arm.dof)
    twist_flat = np.moveaxis(np.broadcast_to(twist, (6, *shape)), 0, -1).reshape(-1, 6)
    point_flat = np.moveaxis(np.broadcast_to(tool_point, (3, *shape)), 0, -1).reshape(-1, 3)
    if progress is None:
        speeds = _speeds(arm, q_flat, twist_flat, point_flat, qdot_max)
    else:  # the finite rows in chunks: each row's speeds as alone
        speeds = np.full(q_flat.shape, np.nan)
        finite = np.flatnonzero(np.isfinite(q_flat).all(axis=-1))
        for rows in in_chunks(finite, progress):
            speeds[rows] = _speeds(arm, q_flat[rows], twist_flat[rows], point_flat[rows], qdot_max)
    return np.moveaxis(speeds.reshape(*shape, arm.dof), -1, 0)


def _speeds(
    arm: VelocityChain,
    q_flat: np.ndarray,
    twist_flat: np.ndarray,
    point_flat: np.ndarray,
    qdot_max: np.ndarray | None,
) -> np.ndarray:
    """Joint speeds per unit twist at M configurations: (M, n), (M, 6), (M, 3) -> (M, n)."""
    if arm.compiled and arm.dof == 6:
        six: np.ndarray = chain_kernel.speeds_per_twist(
            arm.packed, *(kernel_array(a) for a in (q_flat, twist_flat, point_flat))
        )
        return six
    speeds = np.full(q_flat.shape, np.nan)
    rows = np.flatnonzero(np.isfinite(q_flat).all(axis=-1))
    if arm.compiled and arm.dof == 7 and qdot_max is not None:
        speeds, irregular = redundant_kernel.redundant_speeds(
            arm.packed,
            *(kernel_array(a) for a in (q_flat, twist_flat, point_flat)),
            kernel_array(qdot_max),
        )
        rows = np.flatnonzero(irregular)  # J near rank loss: numpy's SVD or the LP decides
    elif arm.compiled and arm.dof == 7:  # the free spin's least-norm direction
        speeds, _, irregular = redundant_kernel.least_norm_and_null(
            arm.packed,
            *(kernel_array(a) for a in (q_flat, twist_flat, point_flat)),
        )
        rows = np.flatnonzero(irregular)
    if arm.compiled:
        jacobian = chain_kernel.jacobians(
            arm.packed,
            kernel_array(q_flat[rows]),
            kernel_array(point_flat[rows]),
        )
    else:
        jacobian, _, _ = arm.chain.jacobian(q_flat[rows], point_flat[rows])
    if arm.dof == 6:
        speeds[rows] = solve_or_nan(jacobian, twist_flat[rows])
    elif arm.dof > 6 and qdot_max is not None:
        speed, qdot = redundant_speed(jacobian, twist_flat[rows], qdot_max)
        with np.errstate(divide="ignore", invalid="ignore"):
            speeds[rows] = qdot / speed[:, None]
    else:  # fewer than six joints: least squares; more, without limits: the least norm
        speeds[rows] = (np.linalg.pinv(jacobian) @ twist_flat[rows, :, None])[..., 0]
    return speeds


def null_space(
    arm: VelocityChain, q: np.ndarray, tool_point: np.ndarray, *, progress: Progress | None = None
) -> np.ndarray:
    """The last right singular vector of J at the tool point (see the base), batched.

    Seven joints on the compiled chain: the QR's (:mod:`redundant_kernel`; its sign may
    differ from the SVD's, which no LP answer depends on), the SVD's where J nears rank
    loss. CHUNK_ROWS configurations at a time, ``progress`` called after each.
    """
    shape = np.broadcast_shapes(q.shape[1:], tool_point.shape[1:])
    q_flat = np.moveaxis(np.broadcast_to(q, (arm.dof, *shape)), 0, -1).reshape(-1, arm.dof)
    point_flat = np.moveaxis(np.broadcast_to(tool_point, (3, *shape)), 0, -1).reshape(-1, 3)
    null = np.full(q_flat.shape, np.nan)
    for rows in in_chunks(np.flatnonzero(np.isfinite(q_flat).all(axis=-1)), progress):
        if arm.compiled and arm.dof == 7:
            _, null[rows], irregular = redundant_kernel.least_norm_and_null(
                arm.packed,
                kernel_array(q_flat[rows]),
                np.zeros((len(rows), 6)),
                kernel_array(point_flat[rows]),
            )
            rows = rows[irregular]
        jacobian, _, _ = arm.chain.jacobian(q_flat[rows], point_flat[rows])
        null[rows] = np.linalg.svd(jacobian)[2][:, -1]
    return np.moveaxis(null.reshape(*shape, arm.dof), -1, 0)


def in_chunks(rows: np.ndarray, progress: Progress | None) -> Iterator[np.ndarray]:
    """``rows`` in pieces of CHUNK_ROWS, ``progress`` called after each piece is done."""
    for start in range(0, len(rows), CHUNK_ROWS):
        yield rows[start : start + CHUNK_ROWS]
        if progress is not None:
            progress(min(start + CHUNK_ROWS, len(rows)) / len(rows))


def solve_or_nan(jacobian: np.ndarray, twist: np.ndarray) -> np.ndarray:
    """J^-1 t for (M, 6, 6) and (M, 6); NaN rows where J is exactly singular."""
    try:
        speeds: np.ndarray = np.linalg.solve(jacobian, twist[..., None])[..., 0]
    except np.linalg.LinAlgError:  # one exactly singular J stops the batch: go one by one
        speeds = np.full(twist.shape, np.nan)
        for m in range(len(twist)):
            try:
                speeds[m] = np.linalg.solve(jacobian[m], twist[m])
            except np.linalg.LinAlgError:
                continue
    return speeds
