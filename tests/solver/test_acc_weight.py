"""Joint acceleration limits weighed and bounded by their blend's span (audit 21, finding 1).

The compiled kernels form each stencil row's D from the steps its blend spans. They held the
steps' weights as a (K, S) table and its transpose, S the longest row's span, made at every
kernel call: a one-placement map of a 20,000-waypoint path whose blend spanned half of it
allocated 1.6 GB, and a map's work grew with the spans while the size limits weighed the limit
as nothing (a 196-placement map at 78 % of DTF_MAX_MAP_POSES ran 190 s). Now a row reads its own
span from four runs of equal weight (:func:`solver.kernels.limits.step_stencil`), and the limit
weighs ACC_ROW_COST plus ACC_STEP_COST a step of its rows' mean span
(:meth:`solver.path.limits.JointAccelerationLimit.pose_cost`).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from service.config import Settings
from service.operations.map import checked_grid
from service.schemas import MapRequest
from solver.core.exceptions import InvalidInputError
from solver.families import get_robot
from solver.path.limits import ACC_ROW_COST, ACC_STEP_COST, JointAccelerationLimit
from solver.path.problem import PathOptions, PathProblem
from tests.cases import ROOT


def straight_path(n: int, spacing: float) -> np.ndarray:
    """n poses along x, ``spacing`` apart, the tool pointing down, in {O} (N, 4, 4)."""
    poses = np.tile(np.diag([1.0, -1.0, -1.0, 1.0]), (n, 1, 1))
    poses[:, 0, 3] = spacing * np.arange(n)
    return poses


@pytest.mark.parametrize(("blend", "steps"), [(0.0025, 6), (0.0105, 22), (0.0505, 102)])
def test_the_weight_a_pose_grows_with_the_blends_span(blend: float, steps: int) -> None:
    # 1 mm apart on a straight line, b half-way between waypoints: s_i - b and s_i + b lie
    # inside segments, whose ends the stencil reads, so every row spans 2 b / h + 1 steps
    # (geometry), and a pose weighs ACC_ROW_COST + ACC_STEP_COST * that more than without
    path = straight_path(400, 0.001)
    bare = get_robot("ur5")
    limited = bare.with_options(qddot_max=[10.0] * 6)
    options = PathOptions(blend_length=blend)
    with_limits = PathProblem.of(limited, path, options)
    (limit,) = with_limits.final_path_limits
    assert isinstance(limit, JointAccelerationLimit)
    spans = limit.stencil.index[:, -1] - limit.stencil.index[:, 0]
    assert np.all(spans == steps)
    added = with_limits.path_cost(400) - PathProblem.of(bare, path, options).path_cost(400)
    assert added == pytest.approx(400 * (ACC_ROW_COST + ACC_STEP_COST * steps), rel=1e-12)


def dome(n: int) -> list[dict[str, list[float]]]:
    """The README example's dome pass resampled to n waypoints (about 16 um apart at 20,000)."""
    source = json.loads((ROOT / "examples" / "evaluate_request.json").read_text())
    waypoints = source["path"]["waypoints"]
    position = np.array([w["position"] for w in waypoints])
    orientation = np.array([w["orientation"] for w in waypoints])
    t = np.linspace(0.0, len(waypoints) - 1, n)
    i = np.minimum(t.astype(int), len(waypoints) - 2)
    f = (t - i)[:, None]
    p = position[i] * (1 - f) + position[i + 1] * f
    q = orientation[i] * (1 - f) + orientation[i + 1] * f
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return [{"position": list(a), "orientation": list(b)} for a, b in zip(p, q, strict=True)]


def test_a_long_blends_map_is_weighed_over_the_synchronous_limit() -> None:
    # audit 21: 20,000 waypoints, 14 x 14 placements (3.9 million poses, under the 5 million of
    # DTF_MAX_MAP_POSES), b = 5 cm: accepted and 190 s with the limits, 0.43 s without
    grid = {
        "x": {"min": 0.0, "max": 0.13, "step": 0.01},
        "y": {"min": 0.40, "max": 0.53, "step": 0.01},
        "z": 0.1,
        "yaw": [0.0],
    }
    body = {"robot": {"model": "ur5"}, "path": {"waypoints": dome(20_000)}, "grid": grid}
    checked_grid(MapRequest.model_validate(body), Settings())  # without the limits: accepted
    body["robot"] = {"model": "ur5", "joint_acceleration_limits": [10.0] * 6}
    body["ik"] = {"blend_length": 0.05}
    with pytest.raises(InvalidInputError, match="DTF_MAX_MAP_POSES"):
        checked_grid(MapRequest.model_validate(body), Settings())


def test_a_one_placement_map_of_a_dense_blend_stays_small() -> None:
    # audit 21: one placement, 20,000 waypoints of which 4,000 lie within 2 mm (the default
    # blend spans all of them): the kernel grew the process by 1.6 GB; run in a process of its
    # own, whose peak resident size is read before and after
    script = textwrap.dedent(
        """
        import resource, sys
        import numpy as np
        sys.path.insert(0, sys.argv[1])
        from solver.families import get_robot
        from solver.path.capability_map import capability_map
        from solver.path.problem import PathProblem
        s = np.concatenate([
            np.linspace(0.0, 0.159, 8000, endpoint=False),
            np.linspace(0.159, 0.161, 4000, endpoint=False),
            np.linspace(0.161, 0.32, 8000),
        ])
        poses = np.tile(np.diag([1.0, -1.0, -1.0, 1.0]), (len(s), 1, 1))
        poses[:, 0, 3] = s - 0.16
        robot = get_robot("ur5").with_options(qddot_max=[10.0] * 6)
        problem = PathProblem.of(robot, poses)
        one = np.array([0.0])
        warm = PathProblem.of(robot, poses[::400])  # the kernels loaded, on a small stencil
        capability_map(warm, xs=one, ys=one + 0.45, z=0.1, yaws=one)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        cmap = capability_map(problem, xs=one, ys=one + 0.45, z=0.1, yaws=one)
        after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(after - before, cmap.reason.ravel()[0], cmap.mu_acc.ravel()[0])
        """
    )
    run = subprocess.run(
        [sys.executable, "-c", script, str(ROOT)],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    grown_kib, reason, mu_acc = run.stdout.split()
    assert int(reason) == -1 and np.isfinite(float(mu_acc))  # feasible: the scan ran
    assert int(grown_kib) < 200 * 1024, f"grew {int(grown_kib) / 1024:.0f} MiB"
