"""The path pipeline, written once for every robot family and any dof (robots.md section 1).

requirements -> IK -> tracking -> speeds -> limits -> branch choice -> bottleneck, for a chunk
of placements at once. :func:`solver.path.evaluate.evaluate_path` (one placement, with
per-waypoint detail) and :func:`solver.path.placements.evaluate_placements` (the map and the
optimisers) both run :func:`run_chunk`; only the robot's kinematics family
(:mod:`solver.core.family`) knows how IK and J^-1 t are solved, and only the problem's limits
(:mod:`solver.path.limits`, the DTF first) how fast each waypoint may run.

What makes it fast (dtf.md section 9): t_hat is computed once in {O} and only turned by each
placement's yaw (:mod:`solver.path.placed`); all placements of a chunk, all waypoints and all IK
branches are one set of component-first arrays with waypoints last. Free spin's schedule is
:mod:`solver.path.spin_schedule`, its spun paths solved exactly where the spin moves more than
the last joint in :mod:`solver.path.exact_spin`; the path checks (the cell) run after, in
:mod:`solver.path.path_checks`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from solver.core.codes import ACC_TIE_RTOL, FEASIBLE, UNREACHABLE
from solver.core.family import PathSolutions
from solver.core.progress import Progress, span
from solver.path.bounded import bounded_solutions, in_one_pass, pick_stands
from solver.path.exact_spin import ROUNDS, SCHEDULE_INSIDE, spun_exactly
from solver.path.in_pieces import bound_in_pieces, track_in_pieces
from solver.path.limits import JointMotion, bound_by_limits
from solver.path.placed import placed_flange, turn_by_yaw
from solver.path.problem import PathProblem
from solver.path.pruning import can_prune, pruned_solutions
from solver.path.spin_schedule import schedule, spin_schedule
from solver.path.tracking import Tracked, choose_branch


@dataclass(frozen=True)
class ChunkResult:
    """Every branch at every placement of a chunk, and the branch each placement takes.

    B branches, C placements, W waypoints, n joints.

    Attributes:
        tracked: the branches followed along the path (reason, failed waypoint: (B, C);
            q: (n, B, C, W), rad).
        qd_unit: shape (n, B, C, W), J^-1 t_hat (rad/s per m/s; per rad/s where h = 0).
        qd_spin: shape (n, B, C, W), J^-1 [0; z_tool] (rad/s per rad/s of tool spin); only in
            ``free`` spin mode, else None.
        qd_null: shape (n, B, C, W), a unit null-space vector of J of a seven-joint arm in
            ``free`` spin mode (the spin LP's third variable), else None.
        speed: shape (B, C, W), the DTF: V_max (Omega_max where h = 0), 1 / max_j |qd_unit_j| /
            qdot_max_j in ``fixed`` mode, the two-variable LP with the spin rate free in ``free``
            mode (cam.md section 2); meaningful only on feasible branches.
        limiting: shape (B, C, W), the joint on its limit.
        v_max: shape (B, C, W), m/s, 0 where h = 0.
        mu_path: shape (B, C), m/s, -inf on infeasible branches.
        spins: shape (B, C, W), rad, the spin schedule that realises mu_path in ``free`` mode
            (cam.md section 2: at the feed mu_path, the spin rate nearest zero at each waypoint,
            integrated along the path); None in ``fixed`` mode. ``tracked`` then holds the joint
            paths along that schedule, so its position limits and steps are checked.
        pick: shape (C,), the index on axis B of the branch each placement takes (``auto``: the
            highest mu_path; the furthest failure where none is feasible).
        ik_seeds: the seeds a numeric family started from (None for an analytic one).
        branches_found: shape (C,), the distinct IK solutions a numeric family found at the
            first waypoint (None for an analytic one).
        v_final: shape (B, C, W), m/s, the least bound of the problem's final-path limits
            (:attr:`PathProblem.final_path_limits`: V_acc,i of motion.md section 2) along the
            final tracked joint paths, inf where none bounds; None without such limits.
        final_limiting: shape (B, C, W), the joint that binds it (None likewise).
        final_binding: shape (B, C, W), which of the final-path limits binds (None likewise).
        mu_acc: shape (B, C), m/s, min(mu_path, min_i v_final), -inf on infeasible branches;
            None without final-path limits. With it, ``pick`` takes the highest mu_acc.
        branch_of: shape (B, C), the index on :attr:`PathProblem.branches` of each row at each
            placement, where the rows are a pruned map's (``PathSolutions.slots``); None:
            row b is branch b.
        pruned: branches that could not be the pick were dropped (a map's run,
            :func:`solver.path.pruning.can_prune`): they come back unreachable, so only the
            pick's row is the branch's answer. False: every branch was followed.
        first: shape (C, K, n), a run pruned in one compiled pass: the seeding's solutions
            at each placement's first waypoint (:attr:`PathSolutions.first`; its counts in
            ``branches_found``), which a run of the same placements again may take (``first``
            of :func:`run_chunk`); None otherwise.
    """

    tracked: Tracked
    qd_unit: np.ndarray
    qd_spin: np.ndarray | None
    speed: np.ndarray
    limiting: np.ndarray
    v_max: np.ndarray
    mu_path: np.ndarray
    pick: np.ndarray
    spins: np.ndarray | None = None
    ik_seeds: int | None = None
    branches_found: np.ndarray | None = None
    qd_null: np.ndarray | None = None
    v_final: np.ndarray | None = None
    final_limiting: np.ndarray | None = None
    final_binding: np.ndarray | None = None
    mu_acc: np.ndarray | None = None
    branch_of: np.ndarray | None = None
    pruned: bool = False
    first: np.ndarray | None = None


def run_chunk(
    problem: PathProblem,
    placements: np.ndarray,
    *,
    progress: Progress | None = None,
    prune: bool = False,
    solutions: PathSolutions | None = None,
    excluded: np.ndarray | None = None,
    first: tuple[np.ndarray, np.ndarray] | None = None,
    compiled: bool = True,
) -> ChunkResult:
    """The pipeline at C placements on the problem's branches.

    Args:
        problem: the robot (with a kinematics family), the path and the options, checked
            (:attr:`PathProblem.branches` made).
        placements: shape (C, 5), [x (m), y (m), z (m), yaw (rad), spin (rad)], checked; one
            spin for the whole chunk.
        progress: handed to the family's IK and joint speeds (a numeric family reports as
            it goes; it may raise :class:`solver.core.progress.Cancelled`).
        prune: a map's run: where :func:`solver.path.pruning.can_prune` admits it, branches
            that cannot be the chosen one are not followed to the end, and come back
            unreachable; the chosen branch's answer is the same (``progress`` then unused by
            the IK). False: every branch followed (an evaluation reports them).
        solutions: the family's IK at these placements, already solved (an analytic family's,
            the same arrays; not with ``prune``).
        excluded: shape (C, K), bool, the family's branches left out at each placement (K:
            its branches; the path checks refused them there): unreachable from the first
            waypoint, so the pick is the best of the others. A pruned run then does not follow
            them (a family that follows bounded; another runs unpruned).
        first: these placements' first-waypoint seeding from an earlier run of them
            (:attr:`ChunkResult.first` and ``branches_found``), taken by a run pruned in one
            pass instead of seeding again (the same arrays); ignored by other runs.
        compiled: free spin's spun paths on a closed-form family by the compiled kernel
            (:mod:`solver.kernels.spun_rows`); False: by numpy, the reference.
    """
    robot, path, branches = problem.robot, problem.prepared, problem.branches
    family = problem.family
    yaws, rotation, flange_position = placed_flange(problem, placements)
    offset = placements[:, :3].T[:, :, None]  # (3, C, 1)
    tool_position = turn_by_yaw(path.tool_position.T, yaws) + offset
    twist = np.concatenate(
        [turn_by_yaw(path.twist[:, :3].T, yaws), turn_by_yaw(path.twist[:, 3:].T, yaws)]
    )
    free = problem.options.spin_mode == "free"
    shares = REDUNDANT_FREE_SHARES if free and robot.dof > 6 else SHARES
    bounded = in_one_pass(problem)
    pruned = prune and can_prune(problem) and (excluded is None or bounded)
    if pruned and bounded:
        solutions = bounded_solutions(
            problem,
            rotation,
            flange_position,
            twist,
            tool_position,
            excluded=excluded,
            first=first,
        )
    elif pruned:
        solutions = pruned_solutions(problem, rotation, flange_position, twist, tool_position)
    elif solutions is None:
        solutions = family.solve_path(
            rotation, flange_position, progress=_part(progress, shares, 0)
        )
    if excluded is not None and not pruned:
        solutions = _without(solutions, excluded)
    q, status = solutions.q, solutions.status  # (n, B_all, C, W), (B_all, C, W)
    branches = without_empty_slots(branches, status)
    # In free mode the position limits hold along the spin schedule, checked there, not here.
    tracked = track_in_pieces(
        q[:, branches],
        status[branches],
        _part(progress, shares, 1),
        lower=np.full(robot.dof, -np.inf) if free else robot.q_lower,
        upper=np.full(robot.dof, np.inf) if free else robot.q_upper,
        max_joint_step=problem.options.max_joint_step,
        segment_checked=path.segment_in_pass,
    )
    spin = None
    if free:
        tool_z = turn_by_yaw(path.tool_rotation[:, :, 2].T, yaws)
        spin = np.concatenate([np.zeros_like(tool_z), np.broadcast_to(tool_z, twist[3:].shape)])
    motion = _joint_motion(
        problem,
        tracked.q,
        (twist, spin, tool_position),
        tuple(_part(progress, shares, k) for k in (2, 3, 4)),
    )
    qd_unit, qd_spin, qd_null = motion.qd_unit, motion.qd_spin, motion.qd_null
    speed, limiting = bound_in_pieces(problem.waypoint_limits, motion, _part(progress, shares, 5))
    v_max = np.where(path.pure_rotation, 0.0, speed)
    feasible = tracked.reason == FEASIBLE  # (B, C)
    mu_path = np.where(feasible, v_max.min(axis=-1), -np.inf)
    if solutions.bound is not None and not pick_stands(solutions, branches, mu_path):
        return run_chunk(  # unpruned
            problem, placements, progress=progress, excluded=excluded, compiled=compiled
        )
    spins = None
    if spin is not None and problem.exact_spin:  # an angled or offset spindle, 7 joints
        spins, tracked, qd_unit, speed, limiting = _exact_free_spin(
            problem,
            placements,
            (tracked, motion, mu_path),
            (twist, spin, tool_position),
            _part(progress, shares, 6),
            compiled=compiled,
        )
        v_max = np.where(path.pure_rotation, 0.0, speed)
        feasible = tracked.reason == FEASIBLE
        mu_path = np.where(feasible, v_max.min(axis=-1), -np.inf)
        qd_spin = qd_null = None  # the spun path's joint speeds are its own, as in fixed spin
    elif qd_spin is not None:
        spins, tracked = spin_schedule(
            problem, tracked, motion, qd_spin, mu_path, _part(progress, shares, 6)
        )
        feasible = tracked.reason == FEASIBLE
        mu_path = np.where(feasible, mu_path, -np.inf)
    if progress is not None:
        progress(1.0)
    final = _final_path_bounds(problem, tracked, qd_unit, qd_spin, mu_path, feasible)
    mu_acc = final[3]
    if mu_acc is None:
        pick = choose_branch(mu_path, feasible, tracked.failed_waypoint)
    else:
        pick = choose_branch(mu_acc, feasible, tracked.failed_waypoint, ACC_TIE_RTOL)
    return ChunkResult(
        tracked=tracked,
        qd_unit=qd_unit,
        qd_spin=qd_spin,
        qd_null=qd_null,
        speed=speed,
        limiting=limiting,
        v_max=v_max,
        mu_path=mu_path,
        pick=pick,
        spins=spins,
        ik_seeds=solutions.seeds,
        branches_found=solutions.branches_found,
        v_final=final[0],
        final_limiting=final[1],
        final_binding=final[2],
        mu_acc=mu_acc,
        branch_of=None if solutions.slots is None else solutions.slots[branches],
        pruned=pruned,
        first=solutions.first,
    )


def _exact_free_spin(
    problem: PathProblem,
    placements: np.ndarray,
    run: tuple[Tracked, JointMotion, np.ndarray],
    vectors: tuple[np.ndarray, np.ndarray, np.ndarray],
    progress: Progress | None,
    *,
    compiled: bool = True,
) -> tuple[np.ndarray, Tracked, np.ndarray, np.ndarray, np.ndarray]:
    """Free spin along each branch's spun path, solved exactly (:mod:`solver.path.exact_spin`).

    Round 1: the spin schedule of the LP at the unspun configurations, each branch solved at
    its spun poses and judged as that path. Each next round takes the schedule of the LP at the
    last round's spun configurations, where the spin rates are the ones those joints need;
    every branch runs :data:`solver.path.exact_spin.ROUNDS` rounds (fewer where its paths
    fail) and keeps the one whose path runs fastest, the first of equals: each row's answer
    is its own, whatever rows are computed with it.

    Args:
        problem: the robot, the path, the options.
        placements: shape (C, 5).
        run: the unspun tracking, its motion (J^-1 t_hat, J^-1 [0; z_tool], the null space)
            and the LP's mu_path (B, C).
        vectors: t_hat (6, C, W), [0; z_tool] (6, C, W) and the tool point (3, C, W) in {B}.
        progress: after each round's schedule and each round's paths.
        compiled: as :func:`run_chunk`'s.

    Returns:
        The spins (B, C, W), the tracking, J^-1 t_hat, the speed and the limiting joint of the
        kept rounds.
    """
    path, branches = problem.prepared, problem.branches
    unspun, motion, lp_mu = run
    unspun_motion = motion
    best: tuple[np.ndarray, Tracked, np.ndarray, np.ndarray, np.ndarray] | None = None
    best_mu = np.full(lp_mu.shape, -np.inf)
    for k in range(ROUNDS):
        part = span(progress, k / ROUNDS, (k + 1) / ROUNDS)
        assert motion.qd_spin is not None
        spins, _ = schedule(
            problem, motion, motion.qd_spin, lp_mu, span(part, 0.0, 0.5), inside=SCHEDULE_INSIDE
        )
        scheduled = np.isfinite(lp_mu)
        spun = spun_exactly(
            problem, placements, spins, branches, scheduled, unspun.q, compiled=compiled
        )
        rows, cells = np.nonzero(scheduled)
        reason, failed = unspun.reason.copy(), unspun.failed_waypoint.copy()
        q, qd_unit = unspun.q.copy(), unspun_motion.qd_unit.copy()
        reason[rows, cells] = spun.tracked.reason
        failed[rows, cells] = spun.tracked.failed_waypoint
        q[:, rows, cells], qd_unit[:, rows, cells] = spun.tracked.q, spun.qd_spun
        tracked = Tracked(reason=reason, failed_waypoint=failed, q=q)
        speed, limiting = bound_in_pieces(
            problem.waypoint_limits, JointMotion(q=q, qd_unit=qd_unit), span(part, 0.5, 1.0)
        )
        v_max = np.where(path.pure_rotation, 0.0, speed)
        # A row without a schedule this round (its last path failed) has no answer of it.
        mu = np.where(scheduled & (reason == FEASIBLE), v_max.min(axis=-1), -np.inf)
        round_ = (spins, tracked, qd_unit, speed, limiting)
        if best is None:
            best, best_mu = round_, mu
        else:
            gains = mu > best_mu
            best = _kept(gains, round_, best)
            best_mu = np.where(gains, mu, best_mu)
        if k + 1 < ROUNDS:  # the LP at this round's spun configurations
            on = reason == FEASIBLE
            if spun.qd_unit is not None and spun.qd_spin is not None:
                # The kernel's J^-1 at the spun joints; the other rows' joints are the unspun
                # ones, whose J^-1 is the first's.
                assert unspun_motion.qd_spin is not None  # free spin
                at_unit, at_spin = unspun_motion.qd_unit.copy(), unspun_motion.qd_spin.copy()
                at_unit[:, rows, cells], at_spin[:, rows, cells] = spun.qd_unit, spun.qd_spin
                motion = JointMotion(q=q, qd_unit=at_unit, qd_spin=at_spin)
            else:
                motion = _joint_motion(problem, q, vectors)
            lp, _ = bound_in_pieces(problem.waypoint_limits, motion, None)
            lp_mu = np.where(on, np.where(path.pure_rotation, 0.0, lp).min(axis=-1), -np.inf)
            if not np.isfinite(lp_mu).any():  # no row has a schedule: no round to run
                break
    if progress is not None:
        progress(1.0)
    assert best is not None
    return best


def _joint_motion(
    problem: PathProblem,
    q: np.ndarray,
    vectors: tuple[np.ndarray, np.ndarray | None, np.ndarray],
    progress: tuple[Progress | None, ...] = (None, None, None),
) -> JointMotion:
    """What the limits see of joint paths q (n, B, C, W): their joint speeds per unit feed.

    ``vectors``: t_hat (6, C, W), [0; z_tool] (6, C, W) or None in fixed spin, and the tool point
    (3, C, W), in {B}. For dof > 6 J^-1 t_hat is the exact DTF LP's joint speeds per unit speed
    (robots.md section 5), so 1 / max_j |qd_j| / qdot_max_j is the LP's V_max for every dof; in
    free spin J^-1 [0; z_tool] too (the least-norm solution for more than six joints) and, for
    seven joints, the null space of J. ``progress``: for each of the three.
    """
    robot, family = problem.robot, problem.family
    twist, spin, tool_point = vectors
    qd_unit = family.joint_speeds_per_unit_twist(
        q, twist[:, None], tool_point[:, None], qdot_max=robot.qdot_max, progress=progress[0]
    )
    if spin is None:
        return JointMotion(q=q, qd_unit=qd_unit)
    qd_spin = family.joint_speeds_per_unit_twist(
        q, spin[:, None], tool_point[:, None], progress=progress[1]
    )
    qd_null = (
        None if robot.dof <= 6 else family.null_space(q, tool_point[:, None], progress=progress[2])
    )
    return JointMotion(q=q, qd_unit=qd_unit, qd_spin=qd_spin, qd_null=qd_null)


def _kept(
    gains: np.ndarray,
    new: tuple[np.ndarray, Tracked, np.ndarray, np.ndarray, np.ndarray],
    old: tuple[np.ndarray, Tracked, np.ndarray, np.ndarray, np.ndarray],
) -> tuple[np.ndarray, Tracked, np.ndarray, np.ndarray, np.ndarray]:
    """Round ``new`` where ``gains`` (B, C), else ``old``: spins, tracking, J^-1 t_hat, bounds."""
    spins, tracked, qd_unit, speed, limiting = new
    was_spins, was, was_qd, was_speed, was_limiting = old
    rows, paths = gains[None, ..., None], gains[..., None]
    return (
        np.where(paths, spins, was_spins),
        Tracked(
            reason=np.where(gains, tracked.reason, was.reason),
            failed_waypoint=np.where(gains, tracked.failed_waypoint, was.failed_waypoint),
            q=np.where(rows, tracked.q, was.q),
        ),
        np.where(rows, qd_unit, was_qd),
        np.where(paths, speed, was_speed),
        np.where(paths, limiting, was_limiting),
    )


SHARES = (0.8, 0.85, 0.95, 1.0, 1.0, 1.0, 1.0)
"""Where each part of a chunk's work ends in its progress: the IK, the tracking, the joint
speeds per unit feed, those per unit spin (free spin), the null space, the limits, the spin
schedule."""
REDUNDANT_FREE_SHARES = (0.55, 0.6, 0.7, 0.75, 0.8, 0.9, 1.0)
"""The same for an arm of more than six joints in free spin, where the spin LP is work too."""


def _part(progress: Progress | None, shares: tuple[float, ...], k: int) -> Progress | None:
    """The progress callback of part ``k`` of a chunk's work (:data:`SHARES`)."""
    return span(progress, shares[k - 1] if k else 0.0, shares[k])


def _without(solutions: PathSolutions, excluded: np.ndarray) -> PathSolutions:
    """``solutions`` with the ``excluded`` (C, K) branches unreachable everywhere (no q)."""
    out = replace(
        solutions, q=np.array(solutions.q, copy=True), status=np.array(solutions.status, copy=True)
    )
    gone = excluded.T  # (K, C): the rows of q and status
    out.q[:, gone] = np.nan
    out.status[gone] = UNREACHABLE
    return out


def without_empty_slots(branches: np.ndarray, status: np.ndarray) -> np.ndarray:
    """The branches to follow, less the trailing ones no placement of the chunk has solved.

    A numeric family answers K slots and fills the first few (the distinct solutions it found);
    the slots after the last one solved anywhere in the chunk would be tracked, bounded and
    compared for nothing. Dropped, they change no answer: they are unreachable at the first
    waypoint, so ``auto`` never takes them (a failure at waypoint 0 loses every tie to an
    earlier branch). Only ``auto``'s branches 0..B-1 are trimmed, so the kept ones are a prefix
    and the result's branch axis still indexes :attr:`PathProblem.branches`; one is always kept.

    Args:
        branches: the problem's branch indices (:attr:`PathProblem.branches`).
        status: shape (B_all, C, W), the family's IK status of every slot.
    """
    if not np.array_equal(branches, np.arange(len(branches))):
        return branches
    given = status[: len(branches)]  # a pruned map's IK answers only the slots it solved
    solved = np.flatnonzero((given != UNREACHABLE).reshape(len(given), -1).any(axis=1))
    return branches[: solved[-1] + 1 if solved.size else 1]


_NoBounds = tuple[None, None, None, None]


def _final_path_bounds(
    problem: PathProblem,
    tracked: Tracked,
    qd_unit: np.ndarray,
    qd_spin: np.ndarray | None,
    mu_path: np.ndarray,
    feasible: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | _NoBounds:
    """The final-path limits along the final joint paths: bound, joint, limit, and mu_acc.

    mu_acc = min(mu_path, min_i bound_i) (motion.md section 2), -inf where infeasible; all
    None when the problem has no final-path limits.
    """
    limits = problem.final_path_limits
    if not limits:
        return None, None, None, None
    motion = JointMotion(q=tracked.q, qd_unit=qd_unit, qd_spin=qd_spin)
    bound, joint, binding = bound_by_limits(limits, motion)  # (B, C, W)
    lowest = bound.min(axis=-1) if bound.shape[-1] else np.full(mu_path.shape, np.inf)
    mu_acc = np.where(feasible, np.minimum(mu_path, lowest), -np.inf)
    return bound, joint, binding, mu_acc
