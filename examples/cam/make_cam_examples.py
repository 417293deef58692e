"""Write the CAM example files of examples/cam (deterministic).

One path, a gentle 5-axis sweep: three zig-zag passes 6 inches (0.15 m) long across a curved
surface, the tool axis the surface normal tilted by a 10 degree lead (up to about 19 degrees
from vertical). It is written as

- ``sweep_mm.cl`` and ``sweep_inch.cl``: the same APT program in millimetres and in inches
  (MULTAX on, rapids between passes, every FEDRAT form, a feed change within the last pass);
  the coordinates are exact in both units (inch values of 4 decimals times 25.4), so both read
  to the same metres;
- ``sweep_3axis_mm.cl``: two passes with MULTAX off, the first with the default tool axis, the
  second with a tilted ``TLAXIS``;
- ``sweep_pass1.csv`` (x, y, z, i, j, k in mm, with a header) and ``sweep_pass1_pose.csv``
  (x, y, z, qx, qy, qz, qw in m, no header): the first pass; the quaternions are the
  parallel-transport frames of cam.md section 1;
- ``sweep_tool_axis_waypoints.json``: every pass as tool-axis waypoints (position in m, axis),
  the form a request gives, to check the readers against.

Run: ``python examples/cam/make_cam_examples.py``.
"""

from __future__ import annotations

import json
import math
from decimal import Decimal
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

HERE = Path(__file__).resolve().parent
LEAD = math.radians(10.0)
# Feeds in inch/min with their mm/min equal: 60 ipm = 1524 mm/min, 50 = 1270, 40 = 1016.
MM_PER_INCH = Decimal("25.4")


def sweep_passes() -> list[list[tuple[list[Decimal], list[float]]]]:
    """Three passes of 13 points: position (inch, exact decimals) and tool axis (6 decimals)."""
    passes = []
    for p in range(3):
        y = 0.5 + 0.75 * p
        direction = 1.0 if p % 2 == 0 else -1.0
        xs = np.arange(13) * 0.5 if direction > 0 else np.arange(12, -1, -1) * 0.5
        points = []
        across = math.pi * (y - 1.25) / 5.0  # the surface: z = 1 + 0.4 sin(pi x / 6) cos(across)
        for x in xs:
            along = math.pi * x / 6.0
            height = 1.0 + 0.4 * math.sin(along) * math.cos(across)
            gx = 0.4 * math.pi / 6.0 * math.cos(along) * math.cos(across)
            gy = -0.4 * math.pi / 5.0 * math.sin(along) * math.sin(across)
            normal = np.array([-gx, -gy, 1.0]) / math.hypot(gx, gy, 1.0)
            # Lead: the axis leans back against the feed direction (about y).
            axis = Rotation.from_euler("y", -direction * LEAD).apply(normal)
            position = [Decimal(f"{v:.4f}") for v in (x, y, height)]
            points.append((position, [round(float(v), 6) for v in axis]))
        passes.append(points)
    return passes


def _mm(value: Decimal) -> str:
    """An inch value in millimetres, exactly."""
    return f"{value * MM_PER_INCH:f}"


def _goto(position: list[Decimal], axis: list[float], *, inch: bool) -> str:
    """A MULTAX GOTO record."""
    xyz = ", ".join(f"{v:f}" if inch else _mm(v) for v in position)
    return f"GOTO/{xyz}, " + ", ".join(f"{v:.6f}" for v in axis)


def cl_program(*, inch: bool) -> str:
    """The sweep as an APT program in inches or millimetres."""
    passes = sweep_passes()
    feeds = (
        [["FEDRAT/IPM, 60.0"], ["FEDRAT/50.0"], ["FEDRAT/40.0, IPM", "FEDRAT/60.0"]]
        if inch
        else [["FEDRAT/MMPM, 1524.0"], ["FEDRAT/1270.0"], ["FEDRAT/MMPM, 1016.0", "FEDRAT/1524.0"]]
    )
    clear = Decimal("2.0")
    lines = [
        f"$$ A gentle 5-axis sweep, three passes, in {'inches' if inch else 'millimetres'}",
        f"PARTNO SWEEP_{'INCH' if inch else 'MM'}",
        "MACHIN/UNCX01, 1",
        f"UNITS/{'INCHES' if inch else 'MM'}",
        "CUTTER/0.25" if inch else "CUTTER/6.35",
        "LOADTL/1",
        "SPINDL/RPM, 12000, CLW",
        "COOLNT/ON",
        "MULTAX" if inch else "MULTAX/ON",
        "FROM/0.0, 0.0, 4.0, 0.0, 0.0, 1.0" if inch else "FROM/0.0, 0.0, 101.6, 0.0, 0.0, 1.0",
    ]
    if not inch:
        lines.append("CLRSRF/Z, 50.8")
    for number, points in enumerate(passes):
        first, last = points[0], points[-1]
        lines += ["RAPID", _goto([*first[0][:2], clear], first[1], inch=inch)]
        lines.append(feeds[number][0] + f"  $$ pass {number + 1}")
        for k, (position, axis) in enumerate(points):
            if number == 2 and k == 7:
                lines.append(feeds[number][1] + "  $$ faster for the rest of the pass")
            record = _goto(position, axis, inch=inch)
            if number == 0 and k == 3:  # one record continued over two lines
                head, tail = record.split(", ", 3)[:3], record.split(", ", 3)[3]
                lines += [", ".join(head) + ", $", "     " + tail]
            else:
                lines.append(record)
        lines += ["RAPID", _goto([*last[0][:2], clear], last[1], inch=inch)]
    lines += ["COOLNT/OFF", "SPINDL/OFF"]
    if inch:
        lines.append("INSERT G28 Z0")
    lines += ["PPRINT END OF SWEEP", "END", "FINI"]
    return "\n".join(lines) + "\n"


def three_axis_program() -> str:
    """Two passes with MULTAX off: the default axis, then a 10 degree TLAXIS (mm)."""
    passes = sweep_passes()[:2]
    tilt = [0.0, round(-math.sin(LEAD), 6), round(math.cos(LEAD), 6)]
    lines = ["$$ 3+2-axis: fixed tool axes", "PARTNO SWEEP_3AXIS", "UNITS/MM", "MULTAX/OFF"]
    for number, points in enumerate(passes):
        if number == 1:
            lines.append("TLAXIS/" + ", ".join(f"{v:.6f}" for v in tilt))
        first = points[0][0]
        lines += ["RAPID", f"GOTO/{_mm(first[0])}, {_mm(first[1])}, 50.8", "FEDRAT/1270.0"]
        lines += [f"GOTO/{', '.join(_mm(v) for v in position)}" for position, _ in points]
    lines += ["END", "FINI"]
    return "\n".join(lines) + "\n"


def main() -> None:
    """Write every example file."""
    from solver.core.tool_axis import poses_from_tool_axes  # run from the repository root

    (HERE / "sweep_mm.cl").write_text(cl_program(inch=False))
    (HERE / "sweep_inch.cl").write_text(cl_program(inch=True))
    (HERE / "sweep_3axis_mm.cl").write_text(three_axis_program())
    passes = sweep_passes()
    metres = [
        [{"position": [float(v * MM_PER_INCH) / 1000.0 for v in p], "axis": a} for p, a in points]
        for points in passes
    ]
    text = json.dumps({"passes": metres}, indent=1)
    (HERE / "sweep_tool_axis_waypoints.json").write_text(text + "\n")
    rows = ["x,y,z,i,j,k"]
    rows += [",".join([*(_mm(v) for v in p), *(f"{v:.6f}" for v in a)]) for p, a in passes[0]]
    (HERE / "sweep_pass1.csv").write_text("\n".join(rows) + "\n")
    poses, _ = poses_from_tool_axes(
        np.array([w["position"] for w in metres[0]]), np.array([w["axis"] for w in metres[0]])
    )
    quaternions = Rotation.from_matrix(poses[:, :3, :3]).as_quat()  # x, y, z, w
    rows = [
        ",".join([*(f"{v:.9f}" for v in pose[:3, 3]), *(f"{v:.9f}" for v in q)])
        for pose, q in zip(poses, quaternions, strict=True)
    ]
    (HERE / "sweep_pass1_pose.csv").write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
