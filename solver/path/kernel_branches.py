"""The path checks' joint paths and next branches by the compiled kernels.

A map with a cell checks the joint path of each feasible placement's chosen branch, and where
the check refuses it, the placement's next feasible branches (:mod:`solver.path.path_checks`).
The numpy pipeline gave both: the family's IK on every branch of the chunk's placements, then
tracking, which cost a map about as much as the collision checks themselves (2026-12-03: 140 and
170 ms of a 420 ms ERK-size UR5e map with a cell, against 10 ms for the map without). Here the
map kernel answers each branch of the refused placements alone (its columns, the same as the
kernel gives when that branch is the one chosen) and :func:`solver.kernels.joint_paths.branch_paths`
makes the joint paths (in free spin :func:`~solver.kernels.joint_paths.spun_branch_paths`, along
each branch's spin schedule at its mu_path), all compiled. The numpy route stays for the
families without a kernel.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from solver.core.codes import ACC_TIE_RTOL, FEASIBLE, TIE_RTOL
from solver.path.branch_candidates import Candidates, tie_order
from solver.path.kernel_cells import KernelInputs, kernel_joint_paths, run_kernel
from solver.path.problem import PathProblem

_MU, _REASON, _MU_ACC = 0, 1, 7  # the columns (solver.path.placements._chunk) read here


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

    def candidates(
        self, problem: PathProblem, placements: np.ndarray, picks: np.ndarray
    ) -> Candidates:
        """Each placement's feasible branches but its chosen one ``picks[k]`` (family index).

        In :func:`solver.path.branch_candidates.tie_order` of mu_path (mu_acc with
        acceleration limits), as :func:`~solver.path.branch_candidates.branch_order` orders a
        pipeline run's.
        """
        branches = problem.branches  # axis B: family indices
        per_branch = [
            run_kernel(
                dataclasses.replace(self.inputs, branches=branches[b : b + 1]),
                placements,
                self.with_speeds,
            )
            for b in range(len(branches))
        ]
        accelerations = self.inputs.qddot_max.shape[0] > 0
        index_column = _MU_ACC if accelerations else _MU
        tie_rtol = ACC_TIE_RTOL if accelerations else TIE_RTOL
        feasible = np.array([columns[_REASON] == FEASIBLE for columns in per_branch])
        index = np.array([columns[index_column] for columns in per_branch])
        axis = {int(family_index): b for b, family_index in enumerate(branches)}
        orders = []
        for k in range(len(placements)):
            pick = axis.get(int(picks[k]), -1)
            # the pick left out: its joint path is the one refused (the same bits)
            others = [int(b) for b in np.flatnonzero(feasible[:, k]) if b != pick]
            orders.append(tie_order(index[:, k], others, tie_rtol))
        found: dict[tuple[int, int], np.ndarray] = {}

        def prepare(pairs: list[tuple[int, int]]) -> None:
            pairs = [pair for pair in pairs if pair not in found]
            paths = self.joint_paths(
                placements[[k for k, _ in pairs]],
                np.array([branches[b] for _, b in pairs], dtype=np.int64),
                np.array([per_branch[b][_MU][k] for k, b in pairs]),
            )
            found.update(zip(pairs, paths, strict=True))

        def joint_path(k: int, b: int) -> np.ndarray:
            if (k, b) not in found:
                prepare([(k, b)])
            return found[(k, b)]

        def columns(chosen: np.ndarray) -> tuple[np.ndarray, ...]:
            out = [np.array(column, copy=True) for column in per_branch[0]]
            for k, b in enumerate(chosen):
                if b >= 0:
                    for column, source in zip(out, per_branch[b], strict=True):
                        column[k] = source[k]
            return tuple(out)

        return Candidates(orders, joint_path, columns, prepare)
