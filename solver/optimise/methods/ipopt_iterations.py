"""IPOPT's iterations: their cap, and the hook that reports progress and stops on a cancel.

:class:`solver.optimise.methods.placement_nlp.PlacementNlp` passes the hook to IPOPT as its
``iteration_callback``; progress is the fraction of :data:`MAX_ITERATIONS` done.
"""

from __future__ import annotations

from typing import Any

import casadi

from solver.core.progress import Cancelled, Progress

# casadi's bundled stubs reject valid SX/MX expressions (DM + SX, MX in nlpsol): untyped here.
ca: Any = casadi
MAX_ITERATIONS = 300


class IterationHook(ca.Callback):  # type: ignore[misc]
    """IPOPT's call after each iteration: reports progress; a :class:`Cancelled` stops IPOPT."""

    def __init__(self, n_variables: int, n_constraints: int) -> None:
        """A hook for an NLP of ``n_variables`` variables and ``n_constraints`` constraints."""
        ca.Callback.__init__(self)
        self._sizes = {"x": n_variables, "lam_x": n_variables}
        self._sizes |= {"g": n_constraints, "lam_g": n_constraints, "f": 1}
        self.progress: Progress | None = None
        self.cancelled: Cancelled | None = None
        self.iteration = 0
        self.construct("iteration_hook", {})

    def get_n_in(self) -> int:
        """Its inputs: every output of the NLP solver."""
        return int(ca.nlpsol_n_out())

    def get_n_out(self) -> int:
        """One output: whether to stop."""
        return 1

    def get_name_in(self, i: int) -> str:
        """The NLP solver's name of input ``i``."""
        return str(ca.nlpsol_out(i))

    def get_name_out(self, i: int) -> str:
        """The output's name."""
        return "stop"

    def get_sparsity_in(self, i: int) -> Any:
        """Input ``i`` dense, of its size in this NLP (empty where it has none)."""
        size = self._sizes.get(str(ca.nlpsol_out(i)), 0)
        return ca.Sparsity.dense(size, 1) if size else ca.Sparsity(0, 0)

    def eval(self, arguments: Any) -> list[int]:
        """Count the iteration, report progress; 1 (stop) once a :class:`Cancelled` was raised."""
        self.iteration += 1
        if self.progress is not None and self.cancelled is None:
            try:
                self.progress(min(self.iteration / MAX_ITERATIONS, 1.0))
            except Cancelled as stop:
                self.cancelled = stop
        return [1 if self.cancelled is not None else 0]
