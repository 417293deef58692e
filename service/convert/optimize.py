"""``POST /v1/optimize``: the solver's box from the request; the answer from the optimum."""

from __future__ import annotations

from service import schemas
from service.convert.common import api_placement
from service.convert.evaluate import evaluate_response
from solver.core.robots import Robot
from solver.optimise.optimize import PlacementOptimum
from solver.optimise.search_space import PlacementBounds


def bounds_of(bounds: schemas.Bounds, *, z: float | None) -> PlacementBounds:
    """The solver's placement box (m, m, rad) at height z (m), or with the height's range."""
    return PlacementBounds(
        x=(bounds.x[0], bounds.x[1]),
        y=(bounds.y[0], bounds.y[1]),
        yaw=(bounds.yaw[0], bounds.yaw[1]),
        z=(bounds.z[0], bounds.z[1]) if bounds.z is not None else float(z or 0.0),
        spin=(bounds.spin[0], bounds.spin[1]),
    )


def optimize_response(
    optimum: PlacementOptimum,
    robot: Robot,
    *,
    axis_correction: float = 0.0,
    path_read: schemas.PathRead | None = None,
) -> schemas.OptimizeResponse:
    """The answer of ``POST /v1/optimize`` (``found: false`` when nothing was feasible).

    ``path_read``: how the CAM program was read, None for poses and tool axes.
    """
    report = optimum.solver
    return schemas.OptimizeResponse(
        found=optimum.found,
        placement=None if optimum.placement is None else api_placement(optimum.placement),
        mu_path=optimum.mu_path,
        mu_acc=optimum.mu_acc,
        evaluation=None
        if optimum.evaluation is None
        else evaluate_response(optimum.evaluation, robot, axis_correction=axis_correction),
        start=schemas.StartInfo(
            placement=api_placement(optimum.start),
            mu_path=optimum.start_mu_path,
            mu_acc=optimum.start_mu_acc,
        ),
        improvement_percent=optimum.improvement_percent,
        spins=None if optimum.spins is None else optimum.spins.tolist(),
        joint_path=None if optimum.joint_path is None else optimum.joint_path.tolist(),
        solver=schemas.SolverInfo(
            name=report.name,
            status=report.status,
            iterations=report.iterations,
            seconds=report.seconds,
        ),
        path_read=path_read,
    )
