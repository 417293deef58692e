"""What the CAM reader audit (stop 54) found read wrong, each against geometry or the text.

- MSYS or CSYS between a CIRCLE and its end: a 500 (IndexError) where a refusal naming both
  lines is due;
- an arc outside NX taken the shorter way, though its CIRCLE's axis says the sense (APT's
  right-hand rule; SolidWorks CAM writes -z for an arc clockwise seen from above): an arc of
  three quarters read as a quarter the other way;
- words that move the tool (RETRCT, GOFWD, NURBS, ...) skipped as 'unknown', the path changed;
- line numbers one too many after a form feed (``str.splitlines`` breaks there);
- moves after FINI read; a UNITS record after the first move applied to the moves before it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.cam.cl_data import read_cl_data
from solver.cam.csv_path import read_csv_path
from solver.core.exceptions import InvalidLineError


def _program(*records: str) -> str:
    return "\n".join(["UNITS/MM", *records]) + "\n"


def _refused(text: str) -> InvalidLineError:
    with pytest.raises(InvalidLineError) as caught:
        read_cl_data(text, field="path.cl_data")
    return caught.value


@pytest.mark.parametrize(
    "system", ["MSYS/1,2,3,1,0,0,0,1,0", "TRNTYP/WORLD,0,0,0\nCSYS/1,0,0,5,0,1,0,0,0,0,1,0"]
)
def test_a_system_change_inside_an_arc_names_the_circle(system: str) -> None:
    text = _program("GOTO/10,0,0", "CIRCLE/0,0,0,0,0,1,10", *system.split("\n"), "GOTO/0,10,0")
    error = _refused(text)
    assert error.line == 4 + system.count("\n")  # the system's line (UNITS is line 1)
    assert "CIRCLE (line 3)" in str(error)


@pytest.mark.parametrize(
    ("axis", "end", "through"),
    [
        ("0,0,1", (0.0, -10.0), (-10.0, 0.0)),  # counter-clockwise seen from +z: three quarters
        ("0,0,-1", (0.0, 10.0), (0.0, -10.0)),  # clockwise seen from +z: three quarters
        ("0,0,1", (0.0, 10.0), (7.0710678, 7.0710678)),  # a quarter, the same either rule
    ],
)
def test_an_arc_turns_counter_clockwise_about_its_circle_axis(
    axis: str, end: tuple[float, float], through: tuple[float, float]
) -> None:
    text = _program("GOTO/10,0,0", f"CIRCLE/0,0,0,{axis},10", f"GOTO/{end[0]},{end[1]},0")
    path = read_cl_data(text, field="path.cl_data", arc_tolerance=1e-6)
    points = path.positions[:, :2] * 1000.0  # mm
    np.testing.assert_allclose(np.linalg.norm(points, axis=1), 10.0, atol=1e-6)
    assert np.min(np.linalg.norm(points - np.array(through), axis=1)) < 0.2  # 0.28 mm chords
    turned = np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1))
    quarters = 3 if through[0] < 0 or through[1] < 0 else 1
    assert turned == pytest.approx(quarters * math.pi / 2 * 10.0, rel=1e-4)


@pytest.mark.parametrize(
    "record",
    [
        "RETRCT",
        "GOFWD/(CIRCLE/0,0,0,5),PAST,(LINE/1,1,0,2,2,0)",
        "TLON,GOFWD/(CIRCLE/0,0,0,5),ON,(PLANE/0,0,1,0)",
        "NURBS/1,2,3",
        "SPLINE/1,2,3",
        "ARC/10,10,0",
        "REFSYS/1,0,0,0,0,1,0,0,0,0,1,0",
        "TRANS/100,0,0",
        "GO TO/10,10,0",
    ],
)
def test_a_word_that_moves_the_tool_is_refused_with_its_line(record: str) -> None:
    error = _refused(_program("GOTO/0,0,0", "GOTO/10,0,0", record, "GOTO/20,0,0"))
    assert error.line == 4
    assert record.split("/")[0].split(",")[0].split()[0] in str(error)


@pytest.mark.parametrize("breaker", ["\f", "\v", "\x1c", "\x85", "\u2028"])
def test_line_numbers_count_line_ends_only(breaker: str) -> None:
    cl = f"UNITS/MM\n$$ page 1{breaker}\nGOTO/0,0,0\nGOTO/1,0,0\nGOTO/x,0,0\n"
    assert _refused(cl).line == 5
    path = read_cl_data(f"UNITS/MM\n$$ a{breaker}b\nGOTO/0,0,0\nGOTO/1,0,0\n", field="p")
    assert path.lines.tolist() == [3, 4]
    csv = f"x,y,z,i,j,k{breaker}\n0,0,0,0,0,1\n1,0,0,0,0,1\n2,0,0,0,0,5\n"
    with pytest.raises(InvalidLineError) as caught:
        read_csv_path(csv, units="mm", field="path.csv")
    assert caught.value.line == 4


def test_a_move_after_fini_is_refused() -> None:
    error = _refused(_program("GOTO/0,0,0", "GOTO/10,0,0", "FINI", "GOTO/500,0,0"))
    assert error.line == 5 and "FINI (line 4)" in str(error)
    path = read_cl_data(
        _program("GOTO/0,0,0", "GOTO/10,0,0", "FINI", "$$ the end", "END"), field="p"
    )
    assert len(path.positions) == 2


def test_units_after_the_first_move_are_refused() -> None:
    error = _refused("GOTO/1,0,0\nGOTO/2,0,0\nUNITS/INCHES\nGOTO/3,0,0\n")
    assert error.line == 3 and "GOTO at line 1" in str(error)


def test_the_waypoint_limit_counts_what_import_shows() -> None:
    """cam.md 9, 'counts are one rule': a pass of one point is dropped, so it does not count
    (20,000 points and a one-point pass were refused as 'more than 20000 waypoints')."""
    three = ["GOTO/0,0,0", "GOTO/1,0,0", "GOTO/2,0,0"]
    single = ["RAPID", "GOTO/0,0,50", "GOTO/0,0,40"]  # a rapid, then a pass of one point
    path = read_cl_data(_program(*three, *single), field="p", max_waypoints=3)
    assert len(path.positions) == 3 and path.one_point_passes == 1
    first = ["GOTO/0,0,40", "RAPID", "GOTO/0,0,50"]  # a pass of one point, then a rapid
    path = read_cl_data(_program(*first, *three), field="p", max_waypoints=3)
    assert len(path.positions) == 3 and path.one_point_passes == 1
    with pytest.raises(Exception, match="more than 3 waypoints by line 5"):
        read_cl_data(_program(*three, "GOTO/3,0,0"), field="p", max_waypoints=3)


def test_pprint_text_keeps_its_double_dollar() -> None:
    path = read_cl_data(_program("PPRINT/ROUGH $$ 2", "GOTO/0,0,0", "GOTO/1,0,0"), field="p")
    assert path.pass_operations[0] == "ROUGH $$ 2"
    assert all(record.word != "$$" for record in path.report.skipped_records)
