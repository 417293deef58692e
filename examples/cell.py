"""The README's cell example: the velocity-best placement hits a fixture; the cell's optimum.

Run it against the service started by the README's first command:

    python3 examples/cell.py [http://127.0.0.1:8000]

Only the standard library is used, so any Python 3.11 runs it.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from http_post import Post, http_post

HERE = Path(__file__).resolve().parent
BOUNDS = {"x": [-0.1, 0.1], "y": [0.35, 0.55], "yaw": [-0.3, 0.3]}
CELL = {
    "fixed": [
        {"shape": "halfspace", "name": "table", "normal": [0, 0, 1], "offset": 0.0},
        {
            "shape": "box",
            "name": "fixture",
            "size": [0.04, 0.04, 0.04],
            "pose": {"position": [0.085, 0.32, 0.35], "orientation": [0, 0, 0, 1]},
        },
    ]
}


def lines(post: Post) -> list[str]:
    """What the example prints, one string a line."""
    request = json.loads((HERE / "evaluate_request.json").read_text())
    box = {"robot": request["robot"], "path": request["path"], "bounds": BOUNDS, "z": 0.1}
    fastest = post("/v1/optimize", box)
    placement = _placement(fastest["placement"])
    blocked = post(
        "/v1/evaluate",
        {"robot": request["robot"], "path": request["path"], "placement": placement, "cell": CELL},
    )
    hit = blocked["collision"]
    free = post("/v1/optimize", {**box, "cell": CELL})
    at, near = free["placement"], free["evaluation"]["min_clearance"]
    return [
        f"velocity-best: mu_path = {fastest['mu_path']:.6f} m/s at x {placement['x']:.4f} m, "
        f"y {placement['y']:.4f} m, yaw {placement['yaw']:.4f} rad",
        f"in the cell: {blocked['reason']} of {hit['robot_part']} with {hit['obstacle_name']} "
        f"at waypoint {hit['waypoint']} ({1000 * hit['distance']:.1f} mm < 5 mm clearance)",
        f"collision-free optimum: mu_path = {free['mu_path']:.6f} m/s at x {at['x']:.4f} m, "
        f"y {at['y']:.4f} m, yaw {at['yaw']:.4f} rad; min clearance "
        f"{1000 * near['distance']:.1f} mm ({near['robot_part']} to {near['obstacle_name']})",
    ]


def _placement(answer: dict[str, Any]) -> dict[str, Any]:
    """An answer's placement as a request takes it (its controller frames left out)."""
    return {key: answer[key] for key in ("x", "y", "z", "yaw", "spin")}


if __name__ == "__main__":
    for line in lines(http_post(sys.argv[1] if len(sys.argv) > 1 else "http://127.0.0.1:8000")):
        print(line)
