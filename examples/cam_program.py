"""The README's CAM example: a CL program, its best placement, its KUKA base frame, the feed check.

Run it against the service started by the README's first command:

    python3 examples/cam_program.py [http://127.0.0.1:8000]

Only the standard library is used, so any Python 3.11 runs it.
"""

from __future__ import annotations

import math
from pathlib import Path

from http_post import Post, run

HERE = Path(__file__).resolve().parent


def lines(post: Post) -> list[str]:
    """What the example prints, one string a line."""
    path = {"cl_data": (HERE / "cam" / "sweep_mm.cl").read_text()}
    read = post("/v1/paths/import", {"path": path})
    robot = {"model": "ur5e"}
    bounds = {"x": [-0.4, 0.2], "y": [0.2, 0.6], "yaw": [-math.pi, math.pi]}
    optimum = post("/v1/optimize", {"robot": robot, "path": path, "bounds": bounds, "z": 0.0})
    at = optimum["placement"]
    kuka = at["frames"]["kuka"]
    placement = {key: at[key] for key in ("x", "y", "z", "yaw", "spin")}
    check = post("/v1/evaluate", {"robot": robot, "path": path, "placement": placement})
    feed = check["feed_check"]
    return [
        f"program: {len(read['waypoints'])} waypoints in {len(read['passes'])} passes, "
        f"FEDRAT {read['feed'] * 60000:.0f} mm/min ({read['units']})",
        f"best placement: mu_path = {optimum['mu_path']:.4f} m/s "
        f"({optimum['improvement_percent']:+.0f} % over the centre of the box)",
        "KUKA base frame: "
        + ", ".join(
            f"{key} {round(kuka[key], 2) + 0.0:.2f}" for key in ("X", "Y", "Z", "A", "B", "C")
        ),
        f"feed check: {feed['feed'] * 60000:.0f} mm/min "
        f"{'runs' if feed['feasible'] else 'does not run'}, margin {feed['margin']:.1f}",
    ]


if __name__ == "__main__":
    run(lines)
