"""The path checks (:class:`solver.path.limits.PathCheck`, the cell) applied after the speed limits.

The speed limits choose, at each placement, the branch with the highest index; a path check
then runs on that branch's joint path only where it is feasible (a collision check costs far
more than the speed limits). Where it refuses the path and the branch is ``auto``, the next
feasible branch by index is checked, and so on; where every feasible branch is refused the
placement is infeasible with the check's reason, at the best branch's refused waypoint.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from solver.core.codes import FEASIBLE
from solver.path.bounded import in_one_pass
from solver.path.branch_candidates import (
    Candidates,
    Columns,
    CompiledBranches,
    branch_order,
    pipeline_candidates,
    run_candidates,
)
from solver.path.limits import PathVerdict, refused_reason
from solver.path.pipeline import ChunkResult, run_chunk
from solver.path.problem import PathProblem


def checks_model(problem: PathProblem) -> dict[str, Any]:
    """What the problem's path checks report of their model, as an answer's fields.

    :meth:`solver.path.limits.PathCheck.model` of each check (the cell's capsules and the
    parts it does not check); the same for every placement, so an evaluation and a map take
    it from the checks, not from each verdict.
    """
    model: dict[str, Any] = {}
    for check in problem.path_checks:
        model.update(check.model())
    return model


def check_path(
    problem: PathProblem, q: np.ndarray, placement: np.ndarray, *, thorough: bool
) -> PathVerdict | None:
    """The first check that refuses ``q`` (W, n) at ``placement`` (5,); else the last verdict.

    None when the problem has no path checks.
    """
    verdict = None
    for check in problem.path_checks:
        verdict = check.check(q, placement, thorough=thorough)
        if verdict.failed_waypoint is not None:
            return verdict
    return verdict


def clear_pick(
    problem: PathProblem,
    run: ChunkResult,
    placements: np.ndarray,
    cell: int,
    *,
    thorough: bool,
    known: tuple[np.ndarray, PathVerdict] | None = None,
) -> tuple[int | None, PathVerdict | None, PathVerdict | None]:
    """The branch placement ``cell`` takes with the path checks: the best that passes them.

    With a fixed branch only the pipeline's pick is checked. ``known``: a joint path already
    checked, and its verdict, taken for a branch whose joint path equals it to the bit.

    Returns:
        the branch (axis B) or None when every feasible branch is refused; the verdict of the
        branch taken; the verdict that refused the pipeline's pick (None if it passed).
    """
    order = branch_order(run, cell)
    first_refusal = None
    for b in order if problem.options.branch is None else order[:1]:
        q = run.tracked.q[:, b, cell].T
        if known is not None and np.array_equal(q, known[0]):
            verdict: PathVerdict | None = known[1]
        else:
            verdict = check_path(problem, q, placements[cell], thorough=thorough)
        if verdict is None or verdict.failed_waypoint is None:
            return b, verdict, first_refusal
        first_refusal = first_refusal or verdict
    return None, None, first_refusal


def check_paths(
    problem: PathProblem, joint_paths: np.ndarray, placements: np.ndarray
) -> list[PathVerdict | None]:
    """:func:`check_path` (not thorough) of N joint paths (N, W, n) at placements (N, 5).

    Each check takes every path not yet refused at once (:meth:`PathCheck.check_many`).
    """
    verdicts: list[PathVerdict | None] = [None] * len(joint_paths)
    open_ = np.arange(len(joint_paths))
    for check in problem.path_checks:
        if not len(open_):
            break
        answers = check.check_many(joint_paths[open_], placements[open_])
        for k, verdict in zip(open_, answers, strict=True):
            verdicts[k] = verdict
        open_ = np.array([k for k in open_ if not _refused(verdicts[k])], dtype=int)
    return verdicts


def _refused(verdict: PathVerdict | None) -> bool:
    """Whether a verdict refuses its path."""
    return verdict is not None and verdict.failed_waypoint is not None


def refuse_colliding(
    problem: PathProblem,
    placements: np.ndarray,
    columns: tuple[np.ndarray, ...],
    columns_of: Columns,
    *,
    compiled: CompiledBranches | None = None,
    run: ChunkResult | None = None,
) -> tuple[np.ndarray, ...]:
    """The placements' columns with the path checks applied (cell.md section 3).

    The chosen branches' joint paths of every feasible placement are checked together
    (:func:`check_paths`), then the refused placements' next branches (:func:`_next_branches`).

    Args:
        problem: the robot, the path, the options (with the cell).
        placements: shape (C, 5), one spin, as the columns were computed.
        columns: mu, reason, failed waypoint, branch (family index), ... as
            :func:`solver.path.placements.columns_of_run` gives them.
        columns_of: the columns of a pipeline run, each placement at its ``pick``.
        compiled: the compiled kernel's joint paths and next branches (a family with a
            kernel: the columns are the kernel's; in free spin, its paths along the spin
            schedules).
        run: the numpy pipeline's run of these placements (the columns are its own), whose
            tracked joint paths are checked, as :func:`clear_pick` checks an evaluation's: no
            IK solved again (a numeric family's map with a cell solved it three times). The
            refused placements' next branches are its rows where it followed every branch;
            after a pruned run (:attr:`ChunkResult.pruned`: its dropped rows are not branches'
            answers) they come from pruned runs that leave the refused branches out
            (:func:`_next_by_pruned_runs`). One of ``compiled`` and ``run`` is given.
    """
    if not problem.path_checks:
        return columns
    if (compiled is None) == (run is None):
        raise ValueError("refuse_colliding takes the kernel's branches or a run, one of them")
    out = [np.array(c, copy=True) for c in columns]
    reason, branch = out[1], out[3]
    order = np.flatnonzero(reason == FEASIBLE)
    if compiled is not None:
        joint_paths = compiled.joint_paths(placements[order], branch[order], out[0][order])
    else:
        assert run is not None
        joint_paths = run.tracked.q[:, run.pick[order], order].transpose(1, 2, 0)
    verdicts = check_paths(problem, joint_paths, placements[order])
    refused = {
        int(c): (q, verdict)
        for c, q, verdict in zip(order, joint_paths, verdicts, strict=True)
        if verdict is not None and verdict.failed_waypoint is not None
    }
    if not refused:
        return tuple(out)
    cells = np.array(sorted(refused))
    candidates = None
    if problem.options.branch is None and run is not None and run.pruned:
        _next_by_pruned_runs(problem, placements, out, refused, columns_of, run)
        return tuple(out)
    if problem.options.branch is None and compiled is not None:
        _next_by_kernel_runs(problem, placements, out, refused, compiled)
        return tuple(out)
    if problem.options.branch is None and run is not None:
        candidates = run_candidates(run, cells, columns_of)
    _next_branches(problem, placements, out, refused, candidates)
    return tuple(out)


def _next_branches(
    problem: PathProblem,
    placements: np.ndarray,
    out: list[np.ndarray],
    refused: dict[int, tuple[np.ndarray, PathVerdict]],
    candidates: Candidates | None,
) -> None:
    """The refused placements' columns from their best branches that pass (auto), else refused.

    Round by round, each placement's next branch in its ``candidates`` order is checked, all of
    a round together (:func:`check_paths`): the branch :func:`clear_pick` takes. The refused
    joint path is not checked again. ``candidates`` None (a fixed branch): refused.
    """
    cells = np.array(sorted(refused))
    taken = np.zeros(len(cells), dtype=bool)
    if candidates is not None:
        rows = placements[cells]
        chosen = np.full(len(cells), -1)
        orders = candidates.orders
        step = [0] * len(cells)
        hints = [refused[int(c)][1] for c in cells]  # each placement's last refusal
        while True:
            due: list[tuple[int, int]] = []  # (placement k, branch) checked this round
            for k, c in enumerate(cells):
                while not taken[k] and step[k] < len(orders[k]):
                    b = orders[k][step[k]]
                    q = candidates.joint_path(k, b)
                    if not np.array_equal(q, refused[int(c)][0]) and not _refused_again(
                        problem, q, rows[k], hints[k]
                    ):
                        due.append((k, b))
                        break
                    step[k] += 1  # the refused joint path itself, or one refused where it was
            if not due:
                break
            joint_paths = np.array([candidates.joint_path(k, b) for k, b in due])
            verdicts = check_paths(problem, joint_paths, rows[[k for k, _ in due]])
            for (k, b), verdict in zip(due, verdicts, strict=True):
                step[k] += 1
                if not _refused(verdict):
                    chosen[k], taken[k] = b, True
                elif verdict is not None:
                    hints[k] = verdict
        if taken.any():
            picked = candidates.columns(chosen)
            for column, value in zip(out, picked, strict=True):
                column[cells[taken]] = value[taken]
    _refuse_the_rest(problem, out, refused, cells[~taken])


# The next picks of the placements still refused, given their rows (k) and placements and the
# branches excluded there: their columns, and the joint path of the pick of row i.
NextPicks = Callable[
    [np.ndarray, np.ndarray, np.ndarray],
    tuple[tuple[np.ndarray, ...], Callable[[int], np.ndarray]],
]


def _next_in_rounds(
    problem: PathProblem,
    placements: np.ndarray,
    out: list[np.ndarray],
    refused: dict[int, tuple[np.ndarray, PathVerdict]],
    next_picks: NextPicks,
    rounds: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Up to ``rounds`` rounds of next picks for the refused placements, their refused branches out.

    Each round's pick is the best branch left by ``auto``'s rule
    (:func:`~solver.path.branch_candidates.tie_order`), as the order of a run of every branch
    gives it; the picks of a round are checked together, a refused one (or one whose joint
    path is the first refused one) is excluded in the next round. A placement whose pick
    passes takes its columns. Returns the refused placements (sorted), their branches excluded
    (K, the family's branches), the rows still refused with a branch left and those taken.
    """
    cells = np.array(sorted(refused))
    rows = placements[cells]
    excluded = np.zeros((len(cells), len(problem.family.branches)), dtype=bool)
    excluded[np.arange(len(cells)), out[3][cells]] = True  # the refused picks (family indices)
    hints = [refused[int(c)][1] for c in cells]  # each placement's last refusal
    taken = np.zeros(len(cells), dtype=bool)
    open_ = np.arange(len(cells))
    for _ in range(rounds):
        if not len(open_):
            break
        picked, path_of = next_picks(open_, rows[open_], excluded[open_])
        due: list[tuple[int, int, np.ndarray]] = []  # (row of the picks, placement k, joint path)
        still: list[int] = []
        for i, k in enumerate(open_.tolist()):
            if picked[1][i] != FEASIBLE:  # no feasible branch left
                continue
            q = path_of(i)
            excluded[k, picked[3][i]] = True
            first = refused[int(cells[k])][0]
            if np.array_equal(q, first) or _refused_again(problem, q, rows[k], hints[k]):
                still.append(k)
            else:
                due.append((i, k, q))
        verdicts = check_paths(
            problem, np.array([q for _, _, q in due]), rows[[k for _, k, _ in due]]
        )
        for (i, k, _), verdict in zip(due, verdicts, strict=True):
            if not _refused(verdict):
                taken[k] = True
                for column, value in zip(out, picked, strict=True):
                    column[cells[k]] = value[i]
            else:
                hints[k] = verdict if verdict is not None else hints[k]
                still.append(k)
        open_ = np.array(sorted(still), dtype=int)
    return cells, excluded, open_, taken


def _refuse_the_rest(
    problem: PathProblem,
    out: list[np.ndarray],
    refused: dict[int, tuple[np.ndarray, PathVerdict]],
    cells: np.ndarray,
) -> None:
    """The ``cells`` among the refused placements refused where their first pick was."""
    for c in cells.tolist():
        verdict = refused[int(c)][1]
        _refuse(out, int(c), refused_reason(verdict), int(verdict.failed_waypoint or 0))


PRUNED_ROUNDS = 2
"""Pruned runs :func:`_next_by_pruned_runs` makes before it follows every branch left.

A pruned run finds one next branch a placement at about a third of the cost of following
every branch (the UR5 read as a numeric URDF: 0.7 against 1.9 ms a placement with the
seeding, the Panda 3.4 against 11), so two rounds, then one run of every branch left for the
placements still refused (the most a placement then costs: about twice the run of every
branch)."""


def _next_by_pruned_runs(
    problem: PathProblem,
    placements: np.ndarray,
    out: list[np.ndarray],
    refused: dict[int, tuple[np.ndarray, PathVerdict]],
    columns_of: Columns,
    run: ChunkResult,
) -> None:
    """:func:`_next_branches` after a pruned run: its refused branches left out of the next runs.

    :data:`PRUNED_ROUNDS` rounds (:func:`_next_in_rounds`) of pruned runs of the refused
    placements with every branch refused there excluded (:func:`solver.path.pipeline.run_chunk`'s
    ``excluded``): each pick's joint path and columns are that run's (the pick is followed to
    the end, the same bits). Then the placements still refused take their next branches from
    one run of every branch left (:func:`pipeline_candidates`); a family that does not follow
    bounded (more than seven joints: its runs would not leave the refused branches out) goes
    there at once. A placement left without a branch is refused where its first pick was. The
    pruned runs take the placements' first-waypoint seeding from ``run``
    (:attr:`ChunkResult.first`), where it has it, rather than seeding again: the same solutions
    (a fifth of the UR5-as-URDF's map with a cell was seeding the refused placements again).
    """
    cells = np.array(sorted(refused))
    seeded = None
    if run.first is not None and run.branches_found is not None:
        seeded = (run.first[cells], run.branches_found[cells])

    def next_picks(
        open_: np.ndarray, rows: np.ndarray, excluded: np.ndarray
    ) -> tuple[tuple[np.ndarray, ...], Callable[[int], np.ndarray]]:
        first = None if seeded is None else (seeded[0][open_], seeded[1][open_])
        again = run_chunk(problem, rows, prune=True, excluded=excluded, first=first)
        return columns_of(again), lambda i: again.tracked.q[:, again.pick[i], i].T

    rounds = PRUNED_ROUNDS if in_one_pass(problem) else 0
    cells, excluded, open_, taken = _next_in_rounds(
        problem, placements, out, refused, next_picks, rounds
    )
    decided = taken.copy()
    if len(open_):  # every branch left in one run: their candidates in auto's order
        rest = {int(cells[k]): refused[int(cells[k])] for k in open_}
        rows = placements[cells[open_]]
        candidates = pipeline_candidates(problem, rows, columns_of, excluded[open_])
        _next_branches(problem, placements, out, rest, candidates)
        decided[open_] = True  # decided there, taken or refused
    _refuse_the_rest(problem, out, refused, cells[~decided])


def _next_by_kernel_runs(
    problem: PathProblem,
    placements: np.ndarray,
    out: list[np.ndarray],
    refused: dict[int, tuple[np.ndarray, PathVerdict]],
    compiled: CompiledBranches,
) -> None:
    """:func:`_next_branches` by the compiled kernel: rounds of runs without the refused branches.

    Each round runs the kernel on the placements still refused with their refused branches
    left out (:meth:`CompiledBranches.excluding`): its pick is ``auto``'s among the branches
    left, pruned as the map's own run is, where running every branch alone at each refused
    placement to order them cost as much again. Rounds until every placement passes or has no
    feasible branch left (at most one a branch); those are refused where their first pick was.
    """

    def next_picks(
        open_: np.ndarray, rows: np.ndarray, excluded: np.ndarray
    ) -> tuple[tuple[np.ndarray, ...], Callable[[int], np.ndarray]]:
        picked = compiled.excluding(problem, rows, excluded)
        feasible = np.flatnonzero(picked[1] == FEASIBLE)
        paths = compiled.joint_paths(rows[feasible], picked[3][feasible], picked[0][feasible])
        at = {int(i): n for n, i in enumerate(feasible)}
        return picked, lambda i: paths[at[i]]

    rounds = len(problem.family.branches)
    cells, _, _, taken = _next_in_rounds(problem, placements, out, refused, next_picks, rounds)
    _refuse_the_rest(problem, out, refused, cells[~taken])


def _refused_again(
    problem: PathProblem, q: np.ndarray, placement: np.ndarray, refusal: PathVerdict
) -> bool:
    """Whether a check refuses ``q`` (W, n) where it refused another path of the placement.

    Of the next branches only whether they pass counts (the pick's refusal is reported): a
    quick test never wrong when it refuses (:meth:`PathCheck.refuses_at`) spares a whole check.
    """
    return any(check.refuses_at(q, placement, refusal) for check in problem.path_checks)


def _refuse(columns: list[np.ndarray], c: int, reason: int, waypoint: int) -> None:
    """Mark placement ``c`` infeasible with ``reason`` at ``waypoint`` (its branch kept)."""
    columns[0][c] = np.nan  # mu_path
    columns[1][c] = reason
    columns[2][c] = waypoint
    columns[4][c] = columns[5][c] = -1  # bottleneck waypoint and joint
    columns[6][c] = np.nan  # V_max (if kept)
    columns[7][c] = np.nan  # mu_acc
    columns[8][c] = columns[9][c] = columns[10][c] = -1
    columns[11][c] = np.nan  # V_acc (if kept)
