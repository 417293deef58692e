"""Write the example machining paths and the README's evaluate request (deterministic).

Each path is a line of waypoints across a curved surface z = f(x, y) of the workpiece, with the
tool z axis along the inward surface normal and the tool x axis along the feed direction, as a
CAM system writes a ball-end finishing pass. Run: ``python examples/make_paths.py``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def _quaternion_xyzw(rotation: np.ndarray) -> list[float]:
    """Unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method)."""
    m = rotation
    trace = float(np.trace(m))
    if trace > 0:
        s = math.sqrt(trace + 1.0) * 2
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k]) * 2
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = s / 4
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    quat = np.array(q)
    quat /= np.linalg.norm(quat)
    return [round(float(v), 12) for v in quat]


def surface_path(surface, gradient, xs: np.ndarray, ys: np.ndarray) -> list[dict]:
    """Waypoints along (xs, ys) on the surface, tool z into the surface, tool x along the feed."""
    points = np.stack([xs, ys, surface(xs, ys)], axis=1)
    waypoints = []
    for i, point in enumerate(points):
        gx, gy = gradient(point[0], point[1])
        normal = np.array([-gx, -gy, 1.0])
        normal /= np.linalg.norm(normal)
        z_axis = -normal
        feed = points[min(i + 1, len(points) - 1)] - points[max(i - 1, 0)]
        x_axis = feed - (feed @ z_axis) * z_axis
        x_axis /= np.linalg.norm(x_axis)
        rotation = np.column_stack([x_axis, np.cross(z_axis, x_axis), z_axis])
        waypoints.append(
            {
                "position": [round(float(v), 12) for v in point],
                "orientation": _quaternion_xyzw(rotation),
            }
        )
    return waypoints


def curved_line() -> list[dict]:
    """133 waypoints over 0.3 m across a doubly curved dome, off its crest."""
    amplitude, length_x, length_y = 0.05, 0.4, 0.6

    def surface(x, y):
        return amplitude * np.cos(math.pi * x / length_x) * np.cos(math.pi * y / length_y)

    def gradient(x, y):
        return (
            -amplitude
            * math.pi
            / length_x
            * math.sin(math.pi * x / length_x)
            * math.cos(math.pi * y / length_y),
            -amplitude
            * math.pi
            / length_y
            * math.cos(math.pi * x / length_x)
            * math.sin(math.pi * y / length_y),
        )

    xs = np.linspace(-0.15, 0.15, 133)
    ys = 0.06 + 0.02 * np.sin(math.pi * xs / 0.15)
    return surface_path(surface, gradient, xs, ys)


def s_curve() -> list[dict]:
    """120 waypoints along an S on a saddle (a second, more twisting path)."""
    curvature_x, curvature_y = 1.2, -0.8

    def surface(x, y):
        return 0.5 * (curvature_x * x**2 + curvature_y * y**2)

    def gradient(x, y):
        return curvature_x * x, curvature_y * y

    t = np.linspace(0.0, 1.0, 120)
    xs = 0.2 * (t - 0.5)
    ys = 0.06 * np.sin(2 * math.pi * t)
    return surface_path(surface, gradient, xs, ys)


def main() -> None:
    """Write examples/paths/*.json and examples/evaluate_request.json."""
    paths = {"curved_line": curved_line(), "s_curve": s_curve()}
    (HERE / "paths").mkdir(exist_ok=True)
    for name, waypoints in paths.items():
        text = json.dumps({"waypoints": waypoints}, indent=1)
        (HERE / "paths" / f"{name}.json").write_text(text + "\n")
    request = {
        "robot": {"model": "ur5"},
        "path": {"waypoints": paths["curved_line"]},
        "placement": {"x": 0.0, "y": 0.45, "z": 0.1, "yaw": 0.0},
        "ik": {"branch": "auto", "max_joint_step": 0.35},
    }
    (HERE / "evaluate_request.json").write_text(json.dumps(request, indent=1) + "\n")


if __name__ == "__main__":
    main()
