"""The use cases the routes and the job workers share (spec/architecture.md section 1).

Each takes a validated request schema and the settings, checks the request's size, converts it,
calls the solver and converts the answer back: a route adds HTTP (the body, the ``Accept``
header, cancellation when the client leaves) and a job worker adds the store, but the answer is
the same code's. The optimisation is imported from its module
(``service.operations.optimize``), not here: it brings the optimisers' libraries (scipy's
optimisers, casadi), which a command line that evaluates or maps never loads.
"""

from service.operations.dtf import dtf_of
from service.operations.evaluate import evaluation_of, joint_use_png
from service.operations.map import checked_grid, computed_map, map_png
from service.operations.paths import import_of, imported

__all__ = [
    "checked_grid",
    "computed_map",
    "dtf_of",
    "evaluation_of",
    "import_of",
    "imported",
    "joint_use_png",
    "map_png",
]
