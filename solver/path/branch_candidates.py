"""The branches a refused placement may take next, best first: numpy's or the kernel's answers.

Where the path checks (:mod:`solver.path.path_checks`) refuse a placement's chosen branch, an
``auto`` placement takes its next feasible branch that passes. :class:`Candidates` holds what
that search reads: each placement's feasible branches in order, their joint paths and the
columns of the branch taken. :func:`run_candidates` reads them off a numpy pipeline run
(the map's own, or :func:`pipeline_candidates`' of the refused placements). A family with a
compiled kernel finds them round by round instead, the kernel run without the refused
branches (:class:`CompiledBranches`, :mod:`solver.path.kernel_branches`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Protocol

import numpy as np

from solver.core.codes import ACC_TIE_RTOL, FEASIBLE, TIE_RTOL
from solver.path.pipeline import ChunkResult, run_chunk
from solver.path.problem import PathProblem

# The columns of a pipeline run's placements, each at its ``pick`` (the branch to report).
Columns = Callable[[ChunkResult], tuple[np.ndarray, ...]]


def tie_order(index: np.ndarray, rows: list[int], tie_rtol: float) -> list[int]:
    """``rows`` in the order ``auto`` takes them as each one before is refused.

    :func:`solver.path.tracking.choose_branch`'s rule again and again: the highest ``index``
    (mu_path, or mu_acc) of the rows left, the first in ``rows``' order within ``tie_rtol`` of
    it. So the branch taken where the best ones collide is the one ``auto`` would choose among
    those that do not (cell.md section 3), whichever pass finds it (a run of every branch, or
    runs that leave the refused ones out).

    Args:
        index: shape (B,), the rows' index (any value at rows not in ``rows``).
        rows: the feasible rows (indices on axis B), in the family's order.
        tie_rtol: ``TIE_RTOL`` for mu_path, ``ACC_TIE_RTOL`` for mu_acc.
    """
    left, order = list(rows), []
    while left:
        top = max(float(index[b]) for b in left)
        taken = next(b for b in left if index[b] >= top - tie_rtol * abs(top))
        order.append(taken)
        left.remove(taken)
    return order


def branch_order(run: ChunkResult, cell: int) -> list[int]:
    """The feasible branches of placement ``cell`` (indices on axis B), best first.

    The pipeline's pick first (its tie rule), then the others in :func:`tie_order`.
    """
    index = run.mu_path if run.mu_acc is None else run.mu_acc
    tie_rtol = TIE_RTOL if run.mu_acc is None else ACC_TIE_RTOL
    feasible = [int(b) for b in np.flatnonzero(run.tracked.reason[:, cell] == FEASIBLE)]
    pick = int(run.pick[cell])
    others = tie_order(index[:, cell], [b for b in feasible if b != pick], tie_rtol)
    return ([pick] if pick in feasible else []) + others


@dataclasses.dataclass(frozen=True)
class Candidates:
    """The refused placements' feasible branches, best first, with their joint paths and columns.

    Attributes:
        orders: per refused placement k, its feasible branches (indices on axis B, the
            problem's branches) in :func:`branch_order`.
        joint_path: (k, b) -> shape (W, n), rad, branch b's joint path at placement k.
        columns: shape (K,) branches chosen (axis B; -1 where none is) -> the columns of the
            K placements (those with -1: any values), as :func:`refuse_colliding` takes them.
    """

    orders: list[list[int]]
    joint_path: Callable[[int, int], np.ndarray]
    columns: Callable[[np.ndarray], tuple[np.ndarray, ...]]


class CompiledBranches(Protocol):
    """The compiled kernel's side of the path checks (:mod:`solver.path.kernel_branches`)."""

    def joint_paths(
        self, placements: np.ndarray, rows: np.ndarray, feeds: np.ndarray
    ) -> np.ndarray:
        """The joint paths (C, W, n) of the family's branch ``rows[c]`` at each placement.

        ``feeds`` (C,), m/s: each branch's mu_path there (free spin's schedule runs at it).
        """

    def excluding(
        self, problem: PathProblem, placements: np.ndarray, excluded: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """The columns at placements (C, 5) of the branches left, ``excluded`` (C, K) left out."""


def run_candidates(run: ChunkResult, cells: np.ndarray, columns_of: Columns) -> Candidates:
    """The :class:`Candidates` of a pipeline run's placements ``cells`` (K,), from the run itself.

    Every branch of the run was tracked at every placement (a run that is not
    :attr:`ChunkResult.pruned`), so the refused placements' next branches are its rows: no IK
    is solved again.
    """

    def columns(chosen: np.ndarray) -> tuple[np.ndarray, ...]:
        pick = np.array(run.pick, copy=True)
        pick[cells] = np.where(chosen >= 0, chosen, pick[cells])
        return tuple(column[cells] for column in columns_of(dataclasses.replace(run, pick=pick)))

    return Candidates(
        [branch_order(run, int(c)) for c in cells],
        lambda k, b: run.tracked.q[:, b, cells[k]].T,
        columns,
    )


def pipeline_candidates(
    problem: PathProblem,
    rows: np.ndarray,
    columns_of: Columns,
    excluded: np.ndarray | None = None,
) -> Candidates:
    """The :class:`Candidates` of placements ``rows`` (K, 5) by one numpy pipeline run.

    ``excluded``: shape (K, branches), bool, branches left out (refused already).
    """
    run = run_chunk(problem, rows, excluded=excluded)
    return run_candidates(run, np.arange(len(rows)), columns_of)
