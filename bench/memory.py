"""Benchmark of a map's peak memory: prints figures, asserts nothing (called by bench/run.py).

Each figure is a fresh Python process that imports the solver, records its peak RSS, computes a
map of the given size (the README example path, UR5, one yaw) and records its peak RSS again;
the map's own cost is the difference.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# The child's own peak: VmHWM of /proc/self/status on Linux. getrusage's ru_maxrss would not
# do there: exec keeps the peak of the forked copy of the parent, so a child of the full
# benchmark run reported the parent's 730 MiB as its own.
_CHILD = """
import json, resource, sys
import numpy as np
def peak_mib():
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
from solver.path.capability_map import capability_map
from solver.path.problem import PathProblem
from service.schemas import EvaluateRequest
request = EvaluateRequest.model_validate(json.load(open(sys.argv[1])))
robot, path = request.robot.to_solver(), request.path.to_solver().poses
problem = PathProblem.of(robot, path)
capability_map(problem, xs=np.zeros(1), ys=np.full(1, 0.45), z=0.1, yaws=np.zeros(1))
before = peak_mib()
cells = int(sys.argv[2])
side = int(np.ceil(np.sqrt(cells)))
xs, ys = np.linspace(-0.6, 0.6, side), np.linspace(-0.6, 0.6, side)
capability_map(PathProblem.of(robot, path), xs=xs, ys=ys, z=0.1, yaws=np.zeros(1))
after = peak_mib()
print(side * side, len(path), before, after)
"""


def peak_rss(*, smoke: bool) -> None:
    """Peak RSS of a map of about 5 million placement-waypoint pairs (the route's limit)."""
    cells = 400 if smoke else 5_000_000 // 133
    out = subprocess.run(
        [
            sys.executable,
            "-c",
            _CHILD,
            str(ROOT / "examples" / "evaluate_request.json"),
            str(cells),
        ],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    ).stdout.split()
    placements, waypoints, before, after = int(out[0]), int(out[1]), float(out[2]), float(out[3])
    print(
        f"map of {placements:,} placements x {waypoints} waypoints = "
        f"{placements * waypoints:,} pairs: peak RSS {after:.0f} MiB "
        f"({after - before:.0f} MiB over the {before:.0f} MiB of the imports)"
    )
