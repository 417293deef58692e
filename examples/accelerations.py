"""The README's acceleration example: the worked example with every joint limited to 10 rad/s^2.

Run it against the service started by the README's first command:

    python3 examples/accelerations.py [http://127.0.0.1:8000]

Only the standard library is used, so any Python 3.11 runs it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from http_post import Post, run

HERE = Path(__file__).resolve().parent
LIMITS = [10.0] * 6  # rad/s^2, every joint of the UR5


def lines(post: Post) -> list[str]:
    """What the example prints, one string a line."""
    request = json.loads((HERE / "evaluate_request.json").read_text())
    limited_robot = {**request["robot"], "joint_acceleration_limits": LIMITS}
    answer = post("/v1/evaluate", {**request, "robot": limited_robot})
    acc, times = answer["acceleration"], answer["cycle_time"]
    drop = 100 * (acc["mu_acc"] / answer["mu_path"] - 1)
    bounds = {"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-math.pi, math.pi]}
    box = {"path": request["path"], "bounds": bounds, "z": 0.1}
    speed_only = post("/v1/optimize", {"robot": request["robot"], **box})
    placement = _placement(speed_only["placement"])
    judged = post(
        "/v1/evaluate", {"robot": limited_robot, "path": request["path"], "placement": placement}
    )
    aware = post("/v1/optimize", {"robot": limited_robot, **box})
    gain = 100 * (aware["mu_acc"] / judged["acceleration"]["mu_acc"] - 1)
    at = aware["placement"]
    return [
        f"mu_path = {answer['mu_path']:.6f} m/s (joint speeds only), limited by "
        f"{answer['bottleneck']['joint_name']} at waypoint {answer['bottleneck']['waypoint']}",
        f"mu_acc  = {acc['mu_acc']:.6f} m/s at 10 rad/s^2 ({drop:+.1f} %), limited by the "
        f"{acc['limited_by']} of {acc['joint_name']} at waypoint {acc['waypoint']}",
        f"cycle time: {times['constant_feed_time']:.3f} s at mu_acc, {times['ramp']:.3f} s with "
        f"the ramps, {times['time_optimal']:.3f} s time-optimal",
        f"velocity-only optimum: mu_path = {speed_only['mu_path']:.6f} m/s, runs at mu_acc = "
        f"{judged['acceleration']['mu_acc']:.6f} m/s",
        f"acceleration-aware optimum: mu_acc = {aware['mu_acc']:.6f} m/s at x {at['x']:.4f} m, "
        f"y {at['y']:.4f} m, yaw {at['yaw']:.4f} rad ({gain:+.1f} %)",
    ]


def _placement(answer: dict[str, Any]) -> dict[str, Any]:
    """An answer's placement as a request takes it (its controller frames left out)."""
    return {key: answer[key] for key in ("x", "y", "z", "yaw", "spin")}


if __name__ == "__main__":
    run(lines)
