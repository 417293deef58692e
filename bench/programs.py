"""Synthetic CAM programs of a published size, as APT CL text (issue 23's benchmark).

The corpus program the issue names (an NX listing of 10,487 moves in 34 operations: cavity
and area milling with a vertical tool, pockets and guiding curves with the tool tilted by about
7 degrees, arcs interpolated to 0.01 mm) is not read at run time; :func:`pocket_program` writes
one of the same size and character: 34 operations of concentric rounded-rectangle pockets,
every corner an arc of GOTOs 0.01 mm from the true arc, one operation in four with the tool
tilted by 7.1 degrees, the part about 120 x 120 x 80 mm.
"""

from __future__ import annotations

import math

OPERATIONS = 34
CORNER_RADIUS = 3.0  # mm
CHORD = 0.01  # mm, the arcs' chordal tolerance
STEPOVER = 4.5  # mm between rectangles
CENTRE = (60.0, 60.0)  # mm
TILT = (0.99227788, 0.1240347)  # the corpus program's tilted axes: 7.1 degrees off vertical


def _corner(cx: float, cy: float, start: float) -> list[tuple[float, float]]:
    """A quarter arc of CORNER_RADIUS about (cx, cy) from angle ``start`` (rad), within CHORD."""
    step = 2.0 * math.acos(1.0 - CHORD / CORNER_RADIUS)
    count = math.ceil((math.pi / 2) / step)
    return [
        (
            cx + CORNER_RADIUS * math.cos(start + k * math.pi / 2 / count),
            cy + CORNER_RADIUS * math.sin(start + k * math.pi / 2 / count),
        )
        for k in range(1, count + 1)
    ]


def _rectangle(half: float) -> list[tuple[float, float]]:
    """A rounded rectangle of half-width ``half`` (mm) about CENTRE, counter-clockwise."""
    x0, y0 = CENTRE
    inner = half - CORNER_RADIUS
    points = [(x0 + half, y0 - inner)]
    for cx, cy, start in (
        (x0 + inner, y0 + inner, 0.0),
        (x0 - inner, y0 + inner, math.pi / 2),
        (x0 - inner, y0 - inner, math.pi),
        (x0 + inner, y0 - inner, 3 * math.pi / 2),
    ):
        points.append((cx + CORNER_RADIUS * math.cos(start), cy + CORNER_RADIUS * math.sin(start)))
        points += _corner(cx, cy, start)
    return points


def pocket_program(moves: int = 10_487, operations: int = OPERATIONS) -> str:
    """An APT CL program (mm) of ``moves`` cutting GOTOs in ``operations`` operations.

    Each operation cuts rounded rectangles from the centre out, a level lower than the last;
    every fourth is cut with the tool tilted (its axis turning towards +x, +y, -x, -y in turn).
    """
    lines = ["UNITS/MM"]
    per_operation = [
        moves // operations + (1 if k < moves % operations else 0) for k in range(operations)
    ]
    for k, count in enumerate(per_operation):
        depth = 80.0 - 2.0 * k
        if k % 4 == 3:
            turn = (k // 4) % 4 * math.pi / 2
            axis = (TILT[1] * math.cos(turn), TILT[1] * math.sin(turn), TILT[0])
        else:
            axis = (0.0, 0.0, 1.0)
        i, j, kk = axis
        lines += [
            f"TOOL PATH/POCKET_{k + 1},TOOL,MILL_6",
            "TLDATA/MILL,6.0000,0.5000,50.0000,0.0000,0.0000",
            "RAPID",
            f"GOTO/{CENTRE[0]:.4f},{CENTRE[1]:.4f},{depth + 20.0:.4f},{i:.7f},{j:.7f},{kk:.7f}",
            "FEDRAT/MMPM,250.0000",
        ]
        written, half = 0, CORNER_RADIUS + 2.0
        while written < count:
            for x, y in _rectangle(half):
                if written == count:
                    break
                lines.append(f"GOTO/{x:.4f},{y:.4f},{depth:.4f},{i:.7f},{j:.7f},{kk:.7f}")
                written += 1
            half = half + STEPOVER if half + STEPOVER <= 58.0 else CORNER_RADIUS + 2.0
        lines.append("END-OF-PATH")
    return "\n".join(lines) + "\n"
