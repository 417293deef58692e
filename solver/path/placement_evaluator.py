"""mu_path at placements asked for one or a few at a time: the local searches' evaluator.

The same answers as :func:`solver.path.placements.evaluate_placements` with the same settings,
without planning tasks for each call (see :class:`PlacementEvaluator`).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from solver.path.kernel_branches import KernelBranches
from solver.path.kernel_cells import KernelInputs, kernel_inputs, kernel_of, run_kernel
from solver.path.path_checks import refuse_colliding
from solver.path.placed import check_placements
from solver.path.placements import (
    PlacementResults,
    columns_of_run,
    evaluate_placements,
    results_of_columns,
)
from solver.path.problem import PathProblem


class PlacementEvaluator:
    """mu_path of one path at placements asked for one or a few at a time (the local searches).

    The same answers as :func:`evaluate_placements` with the same settings: the same compiled
    kernel, or that function itself where the family has no kernel. The
    kernel's inputs are made once per spin, not once per call, and no tasks are planned: the
    optimisers' Nelder-Mead climbs ask for one placement at a time, 1,200 times an
    optimisation, and that preparation cost twice the kernel's own time.
    """

    def __init__(self, problem: PathProblem) -> None:
        """An evaluator of the problem's path on its robot, on the ``auto`` branch.

        Raises:
            NoAnalyticIkError, InvalidInputError: as :func:`evaluate_placements`.
        """
        self._problem = problem.with_options(branch=None)
        _ = self._problem.branches  # the options checked first
        _ = self._problem.path_checks
        self._kernel = kernel_of(self._problem)
        self._last: tuple[float, KernelInputs] | None = None  # the spin asked for last

    def __call__(self, placements: np.ndarray) -> PlacementResults:
        """mu_path at P placements, shape (P, 5) as :func:`evaluate_placements` takes them."""
        cells = check_placements(placements)
        if self._kernel is None or np.any(cells[:, 4] != cells[0, 4]):
            return evaluate_placements(self._problem, cells)
        spin = float(cells[0, 4])
        if self._last is None or self._last[0] != spin:
            self._last = (spin, kernel_inputs(self._problem, spin, self._kernel))
        columns = run_kernel(self._last[1], cells, False)
        if self._problem.path_checks:
            columns_of = partial(columns_of_run, self._problem, with_speeds=False)
            compiled = KernelBranches(self._last[1], False)
            columns = refuse_colliding(self._problem, cells, columns, columns_of, compiled=compiled)
        return results_of_columns(self._problem, list(columns), False)
