"""The path checks' joint paths and next branches by the compiled kernels.

A map with a cell checks the joint path of each feasible placement's chosen branch, and where
the check refuses it, the placement's next feasible branches (:mod:`solver.path.path_checks`).
The numpy pipeline gave both: the family's IK on every branch of the chunk's placements, then
tracking, which cost a map about as much as the collision checks themselves (2026-12-03: 140 and
170 ms of a 420 ms ERK-size UR5e map with a cell, against 10 ms for the map without). Here the
map kernel runs the refused placements again with their refused branches left out
(:meth:`KernelBranches.excluding`: its pick is ``auto``'s among the branches left, with the
columns the kernel gives that branch when it is the one chosen), round by round
(:func:`solver.path.path_checks.refuse_colliding`), and
:func:`solver.kernels.joint_paths.branch_paths` makes the picks' joint paths (in free spin
:func:`~solver.kernels.joint_paths.spun_branch_paths`, along each branch's spin schedule at
its mu_path), all compiled. The numpy route stays for the
families without a kernel.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from solver.core.codes import REASON_UNREACHABLE
from solver.path.kernel_cells import KernelInputs, kernel_joint_paths, run_kernel
from solver.path.problem import PathProblem

_REASON = 1  # the column (solver.path.placements._chunk) written here


@dataclass(frozen=True)
class KernelBranches:
    """The compiled kernel at one spin, as :class:`solver.path.branch_candidates.CompiledBranches`.

    Attributes:
        inputs: the kernel's inputs of the problem at the chunk's spin.
        with_speeds: whether the columns carry V_max (and V_acc) along the path.
    """

    inputs: KernelInputs
    with_speeds: bool

    def joint_paths(
        self, placements: np.ndarray, rows: np.ndarray, feeds: np.ndarray
    ) -> np.ndarray:
        """The joint paths (C, W, 6) of the family's branch ``rows[c]`` at each placement.

        ``feeds`` (C,), m/s: each branch's mu_path there (free spin's schedule runs at it).
        """
        return kernel_joint_paths(self.inputs, placements, rows, feeds)

    def excluding(
        self, problem: PathProblem, placements: np.ndarray, excluded: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """The kernel's columns at each placement with the branches ``excluded`` (C, K) left out.

        The placements with the same branches left run together (the kernel takes one set of
        branches a call): each one's pick is ``auto``'s among its branches left, with the
        columns the kernel gives that branch when it is the one chosen. A placement with no
        branch left gets reason ``unreachable`` (no feasible pick).
        """
        branches = problem.branches  # axis B: family indices
        left = ~excluded[:, branches]  # (C, B)
        groups: dict[bytes, list[int]] = {}
        for c in range(len(placements)):
            groups.setdefault(left[c].tobytes(), []).append(c)
        parts = []
        for members in groups.values():
            kept = branches[left[members[0]]]
            if len(kept):
                inputs = dataclasses.replace(self.inputs, branches=np.ascontiguousarray(kept))
                parts.append((members, run_kernel(inputs, placements[members], self.with_speeds)))
        # the columns' shapes and types: any part's, or a run of no placement where none ran
        like = parts[0][1] if parts else run_kernel(self.inputs, placements[:0], self.with_speeds)
        columns = [np.empty((len(placements), *c.shape[1:]), c.dtype) for c in like]
        columns[_REASON][:] = REASON_UNREACHABLE  # where no branch is left
        for members, part in parts:
            for column, values in zip(columns, part, strict=True):
                column[members] = values
        return tuple(columns)
