"""Free spin where the spin moves more than the last joint: its joint paths solved exactly.

cam.md section 2. The spin schedule (:mod:`solver.path.spin_schedule`) moves the joints by
sigma dt J^-1 [0; z_tool] at each step: exact where six joints turn the tool about the last
joint's own axis (a straight spindle: only that joint moves), first order otherwise (an angled
or offset spindle, seven joints), and there the joint path drifted from the path (the published
KR210 L150 URDF, whose tool z is square to joint 6, on the published fan-shaped CSV: 22.6 mm and
0.16 rad off) while mu_path, the LP's bound at the unspun configurations, promised a feed the
spun path cannot run (0.5934 against 0.5288 m/s, 12 % too high; the robots audit of stop 55).

Here each branch is solved again at its spun poses, R_i Rz(phi_i) (a closed-form family at any
pose by its branch label; a numeric family followed from its solution at the first waypoint,
which no spin turns: :meth:`solver.core.family.KinematicsFamily.follow_from`), and the spun path
is judged as in fixed mode with those spins (`/v1/evaluate` with the answer's ``spins`` gives
the same answer): its own task requirements (the spin turns each segment's rotation), the step
test, the position limits and V_max. :func:`solver.path.pipeline.run_chunk` then takes the LP
again at each round's spun configurations, up to :data:`ROUNDS` rounds, each branch keeping
its fastest; the feed reported is the one the spun path runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.spatial import rotation_about_z, rotation_vectors
from solver.core.task import segment_requirements, twists_of
from solver.kernels.spun_rows import spun_rows
from solver.path.problem import PathProblem
from solver.path.tracking import Tracked, track

ROUNDS = 4
"""Rounds of schedule and spun paths (solver.path.pipeline): the LP at the unspun
configurations puts the spin where the joints are not; each round takes the LP where the last
round's joints were. The UR5 with its tool tilted 0.5 rad and 3 cm off the flange axis, on the
README path: its spun path runs 0.7291, 1.0325, 1.1007, 1.1037 m/s in rounds 1 to 4, the LP at
its own configurations 1.1052 (6 rounds: 1.1038); the KR210 L150 on the fan-shaped CSV at
(2.0, 0.4, 0.3, 1.57): 0.5288, 0.5684, 0.5762, 0.5765 (the LP there 0.5801). The rounds need
not rise: an IRB 2400 with a tool tilted 0.4 rad ran 0.7292, 0.6993, 1.0384, 1.0146 (then
about 1.012), another placement 0.1974, 0.1957, 0.3197 and round again. Every branch runs
them all and keeps its fastest: a branch's answer is its own, whatever else is computed with
it (when the rounds stopped for a whole chunk once none of its branches gained, a map's cell
and the same placement evaluated alone differed by up to 42 %)."""
SCHEDULE_INSIDE = 1.0 - 1e-9
"""The share of the LP's feed the schedule's spin rates are taken at here (1 - 1e-12 where the
schedule's joint speeds are the answer's). Where two joints' bounds on the rate are nearly
parallel, the rates' interval at (1 - 1e-12) is within rounding of a point, and its place moves
with the rounding: the UR5's URDF read to wrist_3_link (recognised) and to tool0 with that frame
as its tcp, one arm, had spins 2 % apart and mu_path 4e-5. The spun path is judged on its own,
so the rates need only be well placed: at (1 - 1e-9) the two agree to 2e-12."""


def spun_twists(problem: PathProblem, spins: np.ndarray) -> np.ndarray:
    """t_hat in {O} of the path turned by ``spins`` (..., W) about each tool z, (6, ..., W).

    As :func:`solver.core.task.task_requirements` forms it from the spun poses (its
    :func:`~solver.core.task.segment_requirements` and :func:`~solver.core.task.twists_of`):
    the segment's displacement (a spin leaves the tool point where it is) and the rotation
    vector of R'_{i+1} R'_i^T with R'_i = R_i Rz(phi_i); the last waypoint takes its segment's.
    """
    path = problem.prepared
    turned = path.tool_rotation @ rotation_about_z(spins)  # (..., W, 3, 3)
    relative = np.einsum("...nij,...nkj->...nik", turned[..., 1:, :, :], turned[..., :-1, :, :])
    u_t, u_r, h = segment_requirements(
        np.diff(path.tool_position, axis=0), rotation_vectors(relative)
    )
    twist = twists_of(u_t, u_r, h)  # (..., W - 1, 6)
    twist = np.concatenate([twist, twist[..., -1:, :]], axis=-2)  # the last reuses its segment's
    return np.moveaxis(twist, -1, 0)


@dataclass(frozen=True)
class SpunPaths:
    """K branches at placements solved at their spun poses (:func:`spun_exactly`).

    Attributes:
        tracked: their tracking: q (n, K, W), the position limits and the step test applied.
        qd_spun: shape (n, K, W), their joint speeds per unit feed, t_hat the spun path's own.
        qd_unit: shape (n, K, W), J^-1 of the unspun t_hat at their joints (the next round's
            LP), where the compiled kernel solved them; None: not computed.
        qd_spin: shape (n, K, W), J^-1 [0; z_tool] there; None with ``qd_unit``.
    """

    tracked: Tracked
    qd_spun: np.ndarray
    qd_unit: np.ndarray | None = None
    qd_spin: np.ndarray | None = None


def spun_exactly(
    problem: PathProblem,
    placements: np.ndarray,
    spins: np.ndarray,
    branches: np.ndarray,
    which: np.ndarray,
    start: np.ndarray,
    *,
    compiled: bool = True,
) -> SpunPaths:
    """The ``which`` branches solved at their spun poses and tracked; their J^-1 t_hat.

    Args:
        problem: the robot (any family: a closed-form one solves each pose by its branch
            label, a numeric one follows from ``start``), the path and the options.
        placements: shape (C, 5), one spin.
        spins: shape (B, C, W), rad, each branch's schedule at each placement.
        branches: shape (B,), the family's branch of each row.
        which: shape (B, C), bool: the K rows at placements to solve (``np.nonzero`` order).
        start: shape (n, B, C, W), rad: the unspun joint paths, whose first waypoint a numeric
            family follows from (no spin turns a pass's first pose).
        compiled: a closed-form family's rows by the compiled kernel; False: by numpy.

    Returns:
        The K spun paths, in ``np.nonzero(which)`` order. A closed-form family's are solved by
        the compiled kernel (:mod:`solver.kernels.spun_rows`, which gives the next round's J^-1
        too); the numpy arithmetic below is its reference, and solves a numeric family's.
    """
    family = problem.family
    rows, cells = np.nonzero(which)
    angles = spins[rows, cells] + float(placements[0, 4])  # (K, W)
    kernel = family.map_kernel() if compiled else None
    if kernel is not None:
        solved = _compiled(problem, kernel, placements[cells], angles, branches[rows])
        if solved is not None:
            q, status, qd_spun, qd_unit, qd_spin = solved
            return SpunPaths(_tracked(problem, q, status), qd_spun, qd_unit, qd_spin)
    return _spun_numpy(problem, placements, angles, branches[rows], rows, cells, start)


def _tracked(problem: PathProblem, q: np.ndarray, status: np.ndarray) -> Tracked:
    """Spun joint paths q (n, K, W) tracked: the position limits and the step test applied."""
    return track(
        q,
        status,
        lower=problem.robot.q_lower,
        upper=problem.robot.q_upper,
        max_joint_step=problem.options.max_joint_step,
        segment_checked=problem.prepared.segment_in_pass,
    )


def _compiled(
    problem: PathProblem,
    kernel: tuple[int, np.ndarray],
    placements: np.ndarray,
    angles: np.ndarray,
    branch_rows: np.ndarray,
) -> tuple[np.ndarray, ...] | None:
    """:func:`solver.kernels.spun_rows.spun_rows` of K rows: q, status, J^-1 of three vectors.

    ``placements``: shape (K, 5), each row's; ``angles``: (K, W), its spins; ``branch_rows``:
    (K,), the family's branch of each. None where a spun segment turns within 1e-2 rad of a
    half turn (the numpy rotation vector reads pinocchio's log3 there).
    """
    family, path = problem.family, problem.prepared
    if family.base_turn is not None and family.base_turn.tilt is None:
        placements = family.base_turn.placements_in(placements)  # as the map kernels place
    own_flange = np.eye(4) if family.flange_offset is None else family.flange_offset.matrix
    n_rows, n_waypoints = angles.shape
    q, *speeds = (np.empty((6, n_rows, n_waypoints)) for _ in range(4))
    status = np.empty((n_rows, n_waypoints), dtype=np.int64)
    near_half_turn = np.empty(n_rows, dtype=bool)
    contiguous = np.ascontiguousarray
    spun_rows(
        kernel[0],
        kernel[1],
        contiguous(path.tool_rotation),
        contiguous(path.tool_position),
        contiguous(path.tool_to_flange),
        contiguous(own_flange),
        contiguous(path.twist),
        np.cos(placements[:, 3]),
        np.sin(placements[:, 3]),
        contiguous(placements[:, :3]),
        contiguous(angles),
        contiguous(branch_rows, dtype=np.int64),
        q,
        status,
        *speeds,
        near_half_turn,
    )
    if near_half_turn.any():
        return None
    return (q, status, *speeds)


def _spun_numpy(
    problem: PathProblem,
    placements: np.ndarray,
    angles: np.ndarray,
    branch_rows: np.ndarray,
    rows: np.ndarray,
    cells: np.ndarray,
    start: np.ndarray,
) -> SpunPaths:
    """:func:`spun_exactly` in numpy: the reference, and a numeric family's way."""
    robot, path, family = problem.robot, problem.prepared, problem.family
    yaw = placements[cells, 3][:, None]  # (K, 1)
    cos, sin = np.cos(yaw), np.sin(yaw)
    offset = placements[cells, :3].T[:, :, None]  # (3, K, 1)
    turned = path.tool_rotation @ rotation_about_z(angles)  # (K, W, 3, 3) in {O}
    flange_rotation = turned @ path.tool_to_flange[:3, :3]
    flange_position = path.tool_position + turned @ path.tool_to_flange[:3, 3]  # (K, W, 3)

    def to_base(vectors: np.ndarray) -> np.ndarray:
        """Vectors (3, K, W, ...) in {O} turned by each one's placement's yaw into {B}."""
        extra = (None,) * (vectors.ndim - 3)
        c, s = cos[(...,) + extra], sin[(...,) + extra]
        x, y = c * vectors[0] - s * vectors[1], s * vectors[0] + c * vectors[1]
        return np.stack([x, y, np.broadcast_to(vectors[2], x.shape)])

    rotation = np.moveaxis(to_base(np.moveaxis(flange_rotation, -2, 0)), -1, 1)  # (3, 3, K, W)
    position = to_base(np.moveaxis(flange_position, -1, 0)) + offset  # (3, K, W)
    if family.map_kernel() is not None:  # closed form: each branch's own label at any pose
        q_all, status_all = family.solve(rotation, position)  # (n, B_all, K, W), (B_all, K, W)
        k = np.arange(len(rows))
        q, status = q_all[:, branch_rows, k], status_all[branch_rows, k]
    else:  # numeric: each followed from its solution at the first waypoint, which no spin moves
        q, status = family.follow_from(
            np.ascontiguousarray(start[:, rows, cells, 0].T),
            np.ascontiguousarray(np.moveaxis(rotation, (0, 1), (-2, -1))),
            np.ascontiguousarray(np.moveaxis(position, 0, -1)),
        )
    tracked = _tracked(problem, q, status)
    twist_o = spun_twists(problem, angles)  # (6, K, W) in {O}
    twist = np.concatenate([to_base(twist_o[:3]), to_base(twist_o[3:])])
    tool_position = to_base(
        np.broadcast_to(path.tool_position.T[:, None], (3, 1, path.n_waypoints))
    )
    qd_unit = family.joint_speeds_per_unit_twist(
        tracked.q, twist, tool_position + offset, qdot_max=robot.qdot_max
    )
    return SpunPaths(tracked, qd_unit)
