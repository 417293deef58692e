"""Conversions between the API's schemas and the solver's objects, one module a resource.

A route and a job call the same functions: ``common`` (robots, paths, placements, branches),
``robots``, ``dtf``, ``evaluate``, ``maps`` and ``optimize``. The names are gathered here so a
route reads ``convert.map_response``.
"""

from __future__ import annotations

from service.convert.common import (
    api_placement,
    branch_of,
    branch_to_api,
    cell_of,
    check_path_size,
    h_of,
    h_to_api,
    joint_path_of,
    path_of,
    placement_of,
    problem_of,
    request_correction,
    robot_from_schema,
    spin_mode_of,
    spun_poses,
    wants_png,
)
from service.convert.dtf import dtf_response
from service.convert.evaluate import evaluate_response
from service.convert.maps import MapGrid, check_png_size, map_grid, map_response, png_panels_over
from service.convert.optimize import bounds_of, optimize_response
from service.convert.path_read import pass_at, path_read_of
from service.convert.robots import robot_info, robot_read_of

__all__ = [
    "MapGrid",
    "api_placement",
    "bounds_of",
    "branch_of",
    "branch_to_api",
    "check_path_size",
    "check_png_size",
    "dtf_response",
    "evaluate_response",
    "h_of",
    "h_to_api",
    "joint_path_of",
    "map_grid",
    "map_response",
    "png_panels_over",
    "optimize_response",
    "pass_at",
    "path_of",
    "path_read_of",
    "placement_of",
    "problem_of",
    "request_correction",
    "cell_of",
    "robot_from_schema",
    "robot_info",
    "robot_read_of",
    "spin_mode_of",
    "spun_poses",
    "wants_png",
]
