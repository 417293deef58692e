"""The README's five-axis example: the same path and placement with the tool spin fixed and free.

Run it against the service started by the README's first command:

    python3 examples/five_axis.py [http://127.0.0.1:8000]

Only the standard library is used, so any Python 3.11 runs it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from http_post import Post, run

HERE = Path(__file__).resolve().parent


def lines(post: Post) -> list[str]:
    """What the example prints, one string a line."""
    request = json.loads((HERE / "evaluate_request.json").read_text())
    fixed = post("/v1/evaluate", request)
    free = post("/v1/evaluate", {**request, "spin_mode": "free"})
    gain = 100 * (free["mu_path"] / fixed["mu_path"] - 1)
    bounds = {"x": [-0.25, 0.25], "y": [0.25, 0.65], "yaw": [-math.pi, math.pi]}
    optimum = post(
        "/v1/optimize",
        {"robot": request["robot"], "path": request["path"], "bounds": bounds, "z": 0.1}
        | {"spin_mode": "free"},
    )
    at = optimum["placement"]

    def limited(answer: dict[str, Any]) -> str:
        bottleneck = answer["bottleneck"]
        return f"limited by {bottleneck['joint_name']} at waypoint {bottleneck['waypoint']}"

    return [
        f"fixed spin: mu_path = {fixed['mu_path']:.6f} m/s, {limited(fixed)}",
        f"free spin:  mu_path = {free['mu_path']:.6f} m/s, {limited(free)} ({gain:+.0f} %)",
        f"free-spin optimum: mu_path = {optimum['mu_path']:.6f} m/s at x {at['x']:.4f} m, "
        f"y {at['y']:.4f} m, yaw {at['yaw']:.4f} rad",
    ]


if __name__ == "__main__":
    run(lines)
