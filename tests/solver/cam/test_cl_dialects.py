"""CL programs as NX and SolidWorks CAM write them (cam.md section 9), read to known waypoints.

The fixtures are written here, record by record, in the style of each CAM system (an NX CLSF
listing with its header, TOOL PATH, TLDATA, MSYS, PAINT, mixed 3- and 6-number GOTOs and an
inch feed without UNITS; a SolidWorks CAM APT file with UNIT/MM, RAPID/, TRNTYP/CSYS, CIRCLE
without a radius, CUTCOM and CSI_* records). Every expected point is placed by the geometry the
fixture states (the MSYS or CSYS frame applied by hand below), never by the reader.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from solver.cam.cl_data import read_cl_data
from solver.cam.read_report import SkippedRecord
from solver.core.exceptions import InvalidInputError, InvalidLineError
from tests.solver.cam.dialects import NX_LISTING, SOLIDWORKS

INCH = 0.0254
MM = 1e-3


def nx_part(x: float, y: float, z: float) -> list[float]:
    """A point of the NX listing in the part frame (inch): MSYS at (1, 2, 0.5), x = +y, y = -x."""
    return [1.0 - y, 2.0 + x, 0.5 + z]


def test_nx_listing_reads_to_the_points_its_msys_places() -> None:
    path = read_cl_data("\n".join(NX_LISTING) + "\n")
    assert path.units == "inches"
    assert path.passes[0] == (0, 4)
    expected = [nx_part(0, 0, 0), nx_part(1, 0, 0), nx_part(1, 1, 0), nx_part(0, 1, 0)]
    np.testing.assert_allclose(path.positions[:4] / INCH, expected, rtol=0, atol=1e-12)
    assert path.lines[:4].tolist() == [19, 20, 22, 23]
    # 3-number GOTOs keep the last axis, written in MSYS: (0.6, 0, 0.8) there is (0, 0.6, 0.8)
    np.testing.assert_allclose(path.axes[:4], [[0, 0, 1], [0, 0, 1], [0, 0.6, 0.8], [0, 0.6, 0.8]])
    assert path.feed == pytest.approx(10 * INCH / 60, rel=1e-15)


def test_nx_arc_is_clockwise_about_its_axis_and_ends_at_its_goto() -> None:
    path = read_cl_data("\n".join(NX_LISTING) + "\n")
    start, stop = path.passes[1]
    assert path.lines[start] == 33 and path.lines[stop - 1] == 35
    points = path.positions[start:stop] / INCH
    centre = np.array(nx_part(1.5, 0, 0))
    np.testing.assert_allclose(points[0], nx_part(2, 0, 0), atol=1e-12)
    np.testing.assert_allclose(points[-1], nx_part(1.5, 0.5, 0), atol=1e-12)
    offsets = points - centre
    np.testing.assert_allclose(np.linalg.norm(offsets, axis=1), 0.5, atol=1e-12)
    angles = np.unwrap(np.arctan2(offsets[:, 1], offsets[:, 0]))
    # In the part frame the arc starts at 90 degrees and, clockwise, ends at -180 (270 swept).
    assert angles[0] == pytest.approx(math.pi / 2, abs=1e-12)
    assert angles[-1] == pytest.approx(-math.pi, abs=1e-12)
    assert np.all(np.diff(angles) < 0)
    chords = (points[1:] + points[:-1]) / 2 - centre
    assert np.max(0.5 - np.linalg.norm(chords, axis=1)) * INCH <= 1e-5  # the default 0.01 mm


def test_nx_listing_says_what_it_skipped_dropped_and_inferred() -> None:
    path = read_cl_data("\n".join(NX_LISTING) + "\n")
    report = path.report
    assert report is not None
    assert report.skipped_records == (
        SkippedRecord("NX listing header", 5, 2, True),
        SkippedRecord("TLDATA", 2, 8, True),
        SkippedRecord("$$", 1, 10, True),
        SkippedRecord("PAINT", 3, 11, True),
    )
    assert (report.units_source, report.repeated_points, report.arcs) == ("inferred", 1, 1)
    assert "FEDRAT/IPM" in report.units_note and "line 18" in report.units_note
    assert path.one_point_passes == 1
    assert path.pass_operations == ("FACE_POCKET", "ARC_FINISH")


def test_solidworks_program_reads_to_the_points_its_csys_places() -> None:
    path = read_cl_data("\n".join(SOLIDWORKS) + "\n")
    assert path.units == "mm" and path.passes == ((0, path.n_waypoints),)
    by_line = {int(n): path.positions[i] / MM for i, n in enumerate(path.lines) if n != 22}
    shift = np.array([10.0, 20.0, -5.0])
    for line, written in {
        18: [40, 0, -3],
        21: [40, 30, -3],
        23: [30, 40, -3],
        24: [0, 40, -3],
    }.items():
        np.testing.assert_allclose(by_line[line], np.array(written) + shift, atol=1e-12)
    assert path.feed == pytest.approx(1600 * MM / 60, rel=1e-15)
    assert path.pass_operations == ("1",)


@pytest.mark.parametrize(
    ("circle_line", "centre", "radius", "sweep"),
    [(22, [40.0, 50.0, -8.0], 10.0, math.pi / 2), (25, [10.0, 40.0, -8.0], 20.0, -2 * math.pi)],
    ids=["quarter, shorter way", "full circle"],
)
def test_solidworks_arcs_lie_on_their_circles(
    circle_line: int, centre: list[float], radius: float, sweep: float
) -> None:
    path = read_cl_data("\n".join(SOLIDWORKS) + "\n")
    lines = path.lines.tolist()
    first, last = lines.index(circle_line), len(lines) - 1 - lines[::-1].index(circle_line)
    points = path.positions[first - 1 : last + 2] / MM  # from the arc's start to its end
    offsets = points - np.array(centre)
    np.testing.assert_allclose(np.linalg.norm(offsets, axis=1), radius, atol=1e-9)
    angles = np.unwrap(np.arctan2(offsets[:, 1], offsets[:, 0]))
    assert angles[-1] - angles[0] == pytest.approx(sweep, abs=1e-9)
    chords = (points[1:] + points[:-1]) / 2 - np.array(centre)
    assert np.max(radius - np.linalg.norm(chords, axis=1)) <= 0.01  # mm: the default tolerance


def test_solidworks_skipped_records_are_counted_exactly() -> None:
    report = read_cl_data("\n".join(SOLIDWORKS) + "\n").report
    assert report is not None
    assert {s.word: (s.count, s.first_line) for s in report.skipped_records} == {
        "INSERT": (1, 3),
        "CUTTER": (1, 4),
        "CSI_SET_FLUTE_LENGTH": (1, 6),
        "CSI_SET_EXTENSION_LENGTH": (1, 7),
        "SELECT": (1, 8),
        "COOLNT": (1, 9),
        "SPINDL": (1, 10),
        "CUTCOM": (2, 20),
        "FINI": (1, 30),
    }
    assert (report.units_source, report.units_note) == ("stated", "UNIT/MM at line 2")
    assert report.arcs == 2


def test_a_finer_arc_tolerance_gives_more_points_each_within_it() -> None:
    text = "\n".join(SOLIDWORKS) + "\n"
    coarse, fine = read_cl_data(text), read_cl_data(text, arc_tolerance=1e-7)
    assert fine.n_waypoints > coarse.n_waypoints
    full = fine.positions[fine.lines == 25] / MM
    chords = (full[1:] + full[:-1]) / 2 - np.array([10.0, 40.0, -8.0])
    assert np.max(20.0 - np.linalg.norm(chords, axis=1)) <= 1e-4  # mm


BARE = ["GOTO/0,0,0", "FEDRAT/MMPM,250", "GOTO/10,0,0", "GOTO/10,5,0"]


def test_no_unit_and_no_inch_feed_is_refused_on_path_units_saying_what_the_file_gave() -> None:
    with pytest.raises(InvalidInputError) as caught:
        read_cl_data("\n".join(BARE))
    assert caught.value.field == "path.units"
    assert "FEDRAT/MMPM at line 2" in caught.value.message


def test_feeds_in_both_units_and_no_statement_are_refused_naming_both_lines() -> None:
    """An mm feed, then an inch feed: read as inches, the mm feed's evidence unsaid."""
    records = [*BARE, "FEDRAT/IPM,40", "GOTO/20,5,0"]
    with pytest.raises(InvalidInputError) as caught:
        read_cl_data("\n".join(records))
    assert caught.value.field == "path.units"
    assert "FEDRAT/IPM at line 5" in caught.value.message
    assert "FEDRAT/MMPM at line 2" in caught.value.message
    path = read_cl_data("\n".join(records), units="mm")  # the request settles it
    assert path.report is not None and path.report.units_source == "request"


@pytest.mark.parametrize(("units", "scale"), [("mm", MM), ("inches", INCH)])
def test_the_request_gives_the_units_a_file_does_not_state(units: str, scale: float) -> None:
    path = read_cl_data("\n".join(BARE), units=units)  # type: ignore[arg-type]
    np.testing.assert_allclose(
        path.positions, np.array([[0, 0, 0], [10, 0, 0], [10, 5, 0]]) * scale
    )
    assert path.report is not None and path.report.units_source == "request"


def test_a_request_that_contradicts_the_stated_units_is_refused() -> None:
    with pytest.raises(InvalidInputError, match="UNITS/INCHES at line 1") as caught:
        read_cl_data("\n".join(["UNITS/INCHES", *BARE]), units="mm")
    assert caught.value.field == "path.units"


@pytest.mark.parametrize("statement", ["UNITS/INCHES", "UNIT/INCH", "units/inch"])
def test_every_inch_statement_reads_as_inches(statement: str) -> None:
    path = read_cl_data("\n".join([statement, *BARE]))
    np.testing.assert_allclose(path.positions[1], [10 * INCH, 0, 0])


def test_an_msys_change_between_passes_is_followed_and_within_one_is_refused() -> None:
    moved = "MSYS/100,0,0,1,0,0,0,1,0"
    cuts = ["GOTO/0,0,0", "GOTO/10,0,0"]
    path = read_cl_data("\n".join(["UNITS/MM", *cuts, "RAPID", "GOTO/0,0,50", moved, *cuts]))
    np.testing.assert_allclose(
        path.positions / MM, [[0, 0, 0], [10, 0, 0], [100, 0, 0], [110, 0, 0]]
    )
    with pytest.raises(InvalidLineError) as caught:
        read_cl_data("\n".join(["UNITS/MM", *cuts, moved, "GOTO/20,0,0"]))
    assert caught.value.line == 4 and "between two cutting moves" in caught.value.message


def test_unknown_words_are_reported_and_canned_cycles_refused() -> None:
    path = read_cl_data("\n".join(["UNITS/MM", "WIBBLE/3", *BARE[::2], "CYCLE/OFF"]))
    report = path.report
    assert report is not None
    assert report.skipped_records == (
        SkippedRecord("WIBBLE", 1, 2, False),
        SkippedRecord("CYCLE", 1, 5, True),
    )
    with pytest.raises(InvalidLineError, match="canned cycle") as caught:
        read_cl_data("\n".join(["UNITS/MM", "CYCLE/DRILL,5,MMPM,100,2", *BARE]))
    assert caught.value.line == 2


def test_a_tool_change_starts_a_new_pass() -> None:
    path = read_cl_data("\n".join(["UNITS/MM", *BARE, "LOADTL/2", "GOTO/20,5,0", "GOTO/20,9,0"]))
    assert path.passes == ((0, 3), (3, 5))


def test_the_waypoint_limit_counts_interpolated_points() -> None:
    text = "\n".join(SOLIDWORKS) + "\n"
    n = read_cl_data(text).n_waypoints
    assert read_cl_data(text, max_waypoints=n).n_waypoints == n
    with pytest.raises(InvalidInputError, match=f"more than {n - 1} waypoints"):
        read_cl_data(text, max_waypoints=n - 1)


@pytest.mark.parametrize(
    ("records", "line", "words"),
    [
        (["RAPID", "CIRCLE/0,0,0,0,0,1", "GOTO/-10,0,0"], 5, "rapid arcs"),
        (["CIRCLE/0,0,0,0,0,1", "FROM/5,5,5", "GOTO/-10,0,0"], 5, "between a CIRCLE"),
        (["CIRCLE/0,0,0,0,0,1", "RAPID", "GOTO/-10,0,0"], 5, "between a CIRCLE"),
        (["CIRCLE/0,0,0,0,0,1", "LOADTL/2", "GOTO/-10,0,0"], 5, "between a CIRCLE"),
        (["CIRCLE/0,0,0,0,0,1"], 4, "not followed by the GOTO of its end"),
        (["CIRCLE/0,0,0,0,0,1,3", "GOTO/-10,0,0"], 4, "stated radius"),
        (["CIRCLE/0,0,0,0,0,1,10,TIMES,2", "GOTO/-10,0,0"], 4, "NX files only"),
    ],
)
def test_arcs_that_cannot_be_followed_name_their_line(
    records: list[str], line: int, words: str
) -> None:
    program = ["UNITS/MM", "GOTO/0,-10,0", "GOTO/10,0,0", *records]
    with pytest.raises(InvalidLineError, match=words) as caught:
        read_cl_data("\n".join(program))
    assert caught.value.line == line


CATIA = [
    "$$ -----------------------------------------------------------------",
    "$$*CATIA0",
    "$$ Manufacturing Program.1",
    "PARTNO PART TO BE MILLED",  # 4
    "$$ OPERATION NAME : Sweeping.1",
    "MULTAX",
    "TOOLNO/1,MILL,10.000000,0.000000,50.000000,0.000000",
    "TPRINT/T1 End Mill D 10,MILL,10.000000",  # 8
    "LOADTL/1,1",
    "SPINDL/  70.0000,RPM,CLW",
    "INTOL  /   0.0100",
    "OUTTOL /   0.0100",
    "AUTOPS",
    "RAPID",
    "GOTO  /   0.00000,   0.00000, 100.00000, 0.000000, 0.000000, 1.000000",
    "FEDRAT/  1000.0000,MMPM",
    "GOTO  /   0.00000,   0.00000,   0.00000, 0.000000, 0.000000, 1.000000",  # 17
    "GOTO  /  50.00000,   0.00000,   0.00000, 0.000000, 0.600000, 0.800000",
    "GOTO  /  50.00000,  20.00000,   0.00000",
    "END",
    "FINI",
]


def test_catia_program_with_blanks_before_the_slash_reads_with_the_request_units() -> None:
    path = read_cl_data("\n".join(CATIA), units="mm")
    np.testing.assert_allclose(path.positions / MM, [[0, 0, 0], [50, 0, 0], [50, 20, 0]])
    np.testing.assert_allclose(path.axes, [[0, 0, 1], [0, 0.6, 0.8], [0, 0.6, 0.8]])
    assert path.pass_operations == ("PART TO BE MILLED",)
    assert path.lines.tolist() == [17, 18, 19]
    report = path.report
    assert report is not None
    assert {s.word: (s.count, s.first_line) for s in report.skipped_records} == {
        "$$": (4, 1),
        "TOOLNO": (1, 7),
        "TPRINT": (1, 8),
        "SPINDL": (1, 10),
        "INTOL": (1, 11),
        "OUTTOL": (1, 12),
        "AUTOPS": (1, 13),
        "END": (1, 20),
        "FINI": (1, 21),
    }
    with pytest.raises(InvalidInputError, match="FEDRAT/MMPM at line 16"):
        read_cl_data("\n".join(CATIA))


def test_cycle_off_with_spaces_is_skipped_as_cycle_off() -> None:
    """``CYCLE / OFF`` was refused as a canned cycle where ``CYCLE/OFF`` was skipped."""
    for record in ("CYCLE/OFF", "CYCLE / OFF", "CYCLE/ off"):
        path = read_cl_data("\n".join(["UNITS/MM", *BARE, record]))
        assert path.report is not None
        assert path.report.skipped_records == (SkippedRecord("CYCLE", 1, 6, True),)


def test_a_byte_order_mark_is_the_files_encoding_not_its_first_record() -> None:
    """A program saved as UTF-8 by a Windows editor starts with U+FEFF: 'line 1: not a record'."""
    text = "\n".join(["UNITS/MM", *BARE])
    marked, plain = read_cl_data("\ufeff" + text), read_cl_data(text)
    np.testing.assert_array_equal(marked.positions, plain.positions)
    assert marked.passes == plain.passes and marked.report == plain.report


def test_digits_other_than_ascii_are_no_number() -> None:
    """A full-width 1 (U+FF11) read as 1 (Python's float takes every script's digits)."""
    with pytest.raises(InvalidLineError, match="is not a number") as caught:
        read_cl_data("\n".join(["UNITS/MM", "GOTO/\uff11,0,0", *BARE[1:]]))
    assert caught.value.line == 2


_LONG_TOKEN = """
import sys
from solver.cam.cl_data import read_cl_data
from solver.cam.csv_path import read_csv_path
from solver.core.exceptions import InvalidLineError
digits = "1" * 200_000 + "x"
for read in (
    lambda: read_cl_data("UNITS/MM\\nGOTO/0,0,0\\nGOTO/" + digits + ",0,0\\n"),
    lambda: read_csv_path("0,0,0,0,0,1\\n" + digits + ",0,0,0,0,1\\n", units="mm"),
):
    try:
        read()
    except InvalidLineError as error:
        print(error.line, error.message.split(" (in ")[0][-30:])
"""


def test_a_long_malformed_number_is_refused_in_one_pass_over_it() -> None:
    """200,000 digits and an x: the number pattern tried every split of the run of digits
    between its two digit classes (time square in its length: 32,000 digits took 16 s and
    held the event loop; 200,000 about 10 min). Refused naming the line, the echo cut; run in
    a process of its own, ended if it takes more than a minute (linear: milliseconds)."""
    done = subprocess.run(
        [sys.executable, "-c", _LONG_TOKEN],
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parents[3],
        timeout=60,
    )
    assert done.returncode == 0, done.stderr[-500:]
    lines = done.stdout.splitlines()
    assert [line.split()[0] for line in lines] == ["3", "2"]
    assert all("is not a number" in line for line in lines)


@pytest.mark.parametrize("record", ["PPRINT/TOOL COST 5$", "PARTNO BRACKET REV $", "INSERT/M01$"])
def test_a_dollar_ending_a_text_record_is_text_not_a_continuation(record: str) -> None:
    """APT takes these records literally to the end of their line: the next GOTO was joined
    to the text (the operation 'TOOL COST 5GOTO/0,0,0'), a move lost without a word."""
    path = read_cl_data("\n".join(["UNITS/MM", record, *BARE]))
    plain = read_cl_data("\n".join(["UNITS/MM", *BARE]))
    np.testing.assert_array_equal(path.positions, plain.positions)
    assert len(path.positions) == 3  # BARE's three GOTOs


@pytest.mark.parametrize(
    ("record", "what"),
    [("GOHOME", "FROM point"), ("INDIRV/0,-1,0", "direction of the next arc")],
)
def test_moves_and_arc_directions_the_reader_does_not_apply_are_refused(
    record: str, what: str
) -> None:
    """GOHOME's move was read as part of the cut to the next GOTO; INDIRV's direction was
    dropped, its arc taken the shorter way: both listed as 'not recognised' only."""
    with pytest.raises(InvalidLineError, match=what) as caught:
        read_cl_data("\n".join(["UNITS/MM", *BARE[:2], record, *BARE[2:]]))
    assert caught.value.line == 4


def test_a_request_in_mm_for_a_program_whose_feed_is_in_inches_is_refused() -> None:
    """A program with FEDRAT/IPM and no UNITS is in inches (cam.md 9); a request's mm was taken
    over that, exit 0, the part 25.4 times too small, the reading saying 'the file states
    none'. Inches or no units read it; with feeds in both units the request still settles it."""
    inch = ["GOTO/0,0,0", "FEDRAT/IPM,20", "GOTO/1,0,0", "GOTO/1,1,0"]
    with pytest.raises(InvalidInputError) as caught:
        read_cl_data("\n".join(inch), units="mm")
    assert caught.value.field == "path.units"
    assert "FEDRAT/IPM at line 2" in caught.value.message
    for units in ("inches", None):
        np.testing.assert_allclose(
            read_cl_data("\n".join(inch), units=units).positions[1], [INCH, 0.0, 0.0]
        )
    both = read_cl_data("\n".join([*inch, "FEDRAT/MMPM,500", "GOTO/2,1,0"]), units="mm")
    np.testing.assert_allclose(both.positions[1], [MM, 0.0, 0.0])


@pytest.mark.parametrize("header", [[], ["x,y,z,i,j,k"]], ids=["bare", "with its header"])
def test_a_csv_given_as_cl_data_is_refused_saying_it_is_a_csv(header: list[str]) -> None:
    """A CSV sent as CL data (or piped to dtf-place under another name) was 'not a record'."""
    lines = [*header, "10.0,20.0,5.0,0,0,1", "11.0,20.0,5.0,0,0,1"]
    with pytest.raises(InvalidLineError) as refused:
        read_cl_data("\n".join(lines) + "\n", units="mm")
    assert refused.value.line == len(header) + 1
    assert "numbers alone are a CSV's line; a CSV is read as one with its units" in str(
        refused.value
    )


def test_a_record_that_is_no_record_and_no_numbers_gets_no_csv_hint() -> None:
    with pytest.raises(InvalidLineError) as refused:
        read_cl_data("GOTO/0,0,0\n1,2\n", units="mm")
    assert "not a record (WORD/arguments)" in str(refused.value)
    assert "CSV" not in str(refused.value)
