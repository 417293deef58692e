"""The optimisation methods, a registry (qpsolvers' ``solve_function``).

Each method is a module with one entry point, ``search(problem, bounds, settings)``, which
returns candidates for the evaluator to judge, and optionally ``check(...)``, run before any
work (a search too large is refused first). The front door
(:func:`solver.optimise.optimize.optimize_placement`) looks a method up here by name; a new
method adds one module and one entry below.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from solver.core.exceptions import InvalidInputError, quoted
from solver.optimise.candidate import Candidate, Search
from solver.optimise.methods import casadi_method, scipy_method
from solver.optimise.search_space import PlacementBounds
from solver.path.problem import PathProblem

SearchFunction = Callable[[PathProblem, PlacementBounds, Search], tuple[list[Candidate], int]]
CheckFunction = Callable[[PathProblem, PlacementBounds, Search], None]


def _no_check(problem: PathProblem, bounds: PlacementBounds, settings: Search) -> None:
    """A method whose size is bounded by its search's own checks."""


@dataclass(frozen=True)
class Method:
    """An optimisation method.

    Attributes:
        description: what the answer's solver report calls it.
        search: the entry point: candidates and the solver's iterations.
        check: refuses a search too large before any work.
        spin_path: whether it also gives each waypoint its own spin (cam.md section 4).
        map_seeds: whether it also starts from the coarse map's maxima (where the map at most
            doubles the search's work, whatever the limits), a choice made before it
            runs (:func:`solver.optimise.work.seeds_from_map`; the casadi method always starts
            from them).
    """

    description: str
    search: SearchFunction
    check: CheckFunction = _no_check
    spin_path: bool = False
    map_seeds: bool = False


METHODS: dict[str, Method] = {
    "casadi": Method(
        casadi_method.DESCRIPTION, casadi_method.search, casadi_method.check, spin_path=True
    ),
    "scipy": Method(
        scipy_method.DESCRIPTION, scipy_method.search, scipy_method.check, map_seeds=True
    ),
}


def method_named(name: str) -> Method:
    """The method registered as ``name``.

    Raises:
        InvalidInputError: on ``method``, an unknown name; the message lists the methods.
    """
    if name not in METHODS:
        raise InvalidInputError(
            "method", f"unknown method {quoted(str(name))}; use {' or '.join(METHODS)}"
        )
    return METHODS[name]
