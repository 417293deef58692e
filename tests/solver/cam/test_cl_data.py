"""APT CL data (cam.md section 5): every record kind, the examples, and each bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from solver.cam.cam_path import CamPath
from solver.cam.cl_data import IGNORED
from solver.cam.cl_data import read_cl_data as read_program
from solver.core.exceptions import InvalidInputError, InvalidLineError
from solver.core.tool_axis import poses_from_tool_axes
from tests.cases import CAM_EXAMPLES, INCH_MM_ATOL

TWO_CUTS = ["GOTO/0, 0, 0, 0, 0, 1", "GOTO/10, 0, 0, 0, 0, 1"]


def read_cl_data(text: str) -> CamPath:
    """The reader, given mm by the request for a program that states no units and writes no
    inch feed (such a program is in inches, cam.md 9, and a request's mm is refused)."""
    stated_or_inferred = "UNITS/" in text.upper() or "IPM" in text.upper()
    return read_program(text, units=None if stated_or_inferred else "mm")


def program(*records: str) -> str:
    return "\n".join(records) + "\n"


def multax(*records: str) -> str:
    return program("MULTAX/ON", *records)


def line_error(text: str) -> InvalidLineError:
    with pytest.raises(InvalidLineError) as caught:
        read_cl_data(text)
    return caught.value


# --- the examples -------------------------------------------------------------------------


def test_inch_and_mm_programs_of_one_path_read_the_same() -> None:
    mm = read_cl_data((CAM_EXAMPLES / "sweep_mm.cl").read_text())
    inch = read_cl_data((CAM_EXAMPLES / "sweep_inch.cl").read_text())
    assert (mm.units, inch.units) == ("mm", "inches")
    np.testing.assert_allclose(inch.positions, mm.positions, rtol=0, atol=INCH_MM_ATOL)
    np.testing.assert_array_equal(inch.axes, mm.axes)
    np.testing.assert_allclose(inch.feeds, mm.feeds, rtol=1e-15)
    assert inch.passes == mm.passes == ((0, 13), (13, 26), (26, 39))


def test_example_feeds_per_pass_and_within_a_pass() -> None:
    path = read_cl_data((CAM_EXAMPLES / "sweep_mm.cl").read_text())
    per_minute = path.feeds * 60e3
    np.testing.assert_allclose(per_minute[:13], 1524.0)
    np.testing.assert_allclose(per_minute[13:26], 1270.0)
    # Pass 3 runs at 1016 mm/min up to its 7th point, then 1524 (segment 6 -> 7 onwards).
    np.testing.assert_allclose(per_minute[26:32], 1016.0)
    np.testing.assert_allclose(per_minute[32:], 1524.0)
    assert path.feed == pytest.approx(1524.0 / 60e3)
    assert path.pass_feeds == pytest.approx((1524.0 / 60e3, 1270.0 / 60e3, 1524.0 / 60e3))


def test_cl_poses_equal_the_path_given_as_tool_axis_waypoints() -> None:
    """Each pass starts its own parallel transport (cam.md section 5)."""
    given = json.loads((CAM_EXAMPLES / "sweep_tool_axis_waypoints.json").read_text())["passes"]
    for name in ("sweep_mm.cl", "sweep_inch.cl"):
        path = read_cl_data((CAM_EXAMPLES / name).read_text())
        poses = path.waypoints_in_workpiece()
        for (start, stop), waypoints in zip(path.passes, given, strict=True):
            expected, _ = poses_from_tool_axes(
                np.array([w["position"] for w in waypoints]),
                np.array([w["axis"] for w in waypoints]),
            )
            np.testing.assert_allclose(poses[start:stop], expected, rtol=0, atol=INCH_MM_ATOL)


def test_spin_turns_every_waypoint_about_its_tool_z() -> None:
    path = read_cl_data((CAM_EXAMPLES / "sweep_mm.cl").read_text())
    turned = path.waypoints_in_workpiece(spin=0.3)
    plain = path.waypoints_in_workpiece()
    np.testing.assert_allclose(turned[:, :3, 2], plain[:, :3, 2], atol=1e-15)
    cos = np.einsum("ni,ni->n", turned[:, :3, 0], plain[:, :3, 0])
    np.testing.assert_allclose(cos, math.cos(0.3), atol=1e-12)


def test_three_axis_example_uses_default_then_tlaxis() -> None:
    path = read_cl_data((CAM_EXAMPLES / "sweep_3axis_mm.cl").read_text())
    assert path.passes == ((0, 13), (13, 26))
    np.testing.assert_array_equal(path.axes[:13], np.tile([0.0, 0.0, 1.0], (13, 1)))
    tilt = np.array([0.0, -math.sin(math.radians(10)), math.cos(math.radians(10))])
    np.testing.assert_allclose(path.axes[13:], np.tile(tilt, (13, 1)), atol=1e-6)


def test_waypoints_remember_their_lines() -> None:
    text = (CAM_EXAMPLES / "sweep_mm.cl").read_text()
    path = read_cl_data(text)
    lines = text.splitlines()
    assert all(lines[n - 1].startswith("GOTO/") for n in path.lines)
    assert lines[path.lines[3]].startswith("     ")  # the continued record starts a line above


# --- every record kind --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("units", "scale", "name"),
    [(None, 1e-3, "mm"), ("UNITS/MM", 1e-3, "mm"), ("UNITS/INCHES", 0.0254, "inches")],
)
def test_units_convert_to_metres(units: str | None, scale: float, name: str) -> None:
    records = [units] if units else []
    path = read_cl_data(multax(*records, "GOTO/1, 2, 3, 0, 0, 1", "GOTO/4, 5, 6, 0, 0, 1"))
    np.testing.assert_allclose(path.positions, np.array([[1, 2, 3], [4, 5, 6]]) * scale)
    assert path.units == name


@pytest.mark.parametrize("switch", ["MULTAX/ON", "MULTAX", "multax/on"])
def test_multax_on_reads_six_numbers(switch: str) -> None:
    path = read_cl_data(program(switch, "GOTO/0, 0, 0, 0, 0.6, 0.8", "GOTO/1, 0, 0, 0.6, 0, 0.8"))
    np.testing.assert_allclose(path.axes, [[0, 0.6, 0.8], [0.6, 0, 0.8]])
    assert path.default_spin_mode == "free"


def test_multax_off_reads_three_numbers_with_tlaxis() -> None:
    path = read_cl_data(
        program(
            "MULTAX/ON",
            "MULTAX/OFF",
            "GOTO/0, 0, 0",
            "GOTO/1, 0, 0",
            "TLAXIS/0, 0.6, 0.8",
            "GOTO/2, 0, 0",
        )
    )
    np.testing.assert_allclose(path.axes, [[0, 0, 1], [0, 0, 1], [0, 0.6, 0.8]])


@pytest.mark.parametrize(
    ("records", "metres_per_minute"),
    [
        (["FEDRAT/600"], 0.6),
        (["UNITS/INCHES", "FEDRAT/100"], 2.54),
        (["FEDRAT/MMPM, 600"], 0.6),
        (["UNITS/INCHES", "FEDRAT/MMPM, 600"], 0.6),
        (["FEDRAT/600, MMPM"], 0.6),
        (["FEDRAT/IPM, 100"], 2.54),
        (["FEDRAT/100, IPM"], 2.54),
        (["FEDRAT/ipm, 100"], 2.54),
    ],
)
def test_fedrat_forms(records: list[str], metres_per_minute: float) -> None:
    path = read_cl_data(multax(*records, *TWO_CUTS))
    assert path.feed == pytest.approx(metres_per_minute / 60.0, rel=1e-15)
    np.testing.assert_allclose(path.feeds, metres_per_minute / 60.0, rtol=1e-15)


def test_no_fedrat_no_feed() -> None:
    path = read_cl_data(multax(*TWO_CUTS))
    assert path.feed is None
    assert np.all(np.isnan(path.feeds))
    assert path.pass_feeds == (None,)


def test_feed_change_within_a_pass_is_kept_per_waypoint() -> None:
    path = read_cl_data(
        multax(
            "GOTO/0, 0, 0, 0, 0, 1",
            "FEDRAT/600",
            "GOTO/10, 0, 0, 0, 0, 1",
            "FEDRAT/1200",
            "GOTO/20, 0, 0, 0, 0, 1",
            "GOTO/30, 0, 0, 0, 0, 1",
        )
    )
    # Waypoint i carries the feed of the move i -> i+1; the last one that of the move into it.
    np.testing.assert_allclose(path.feeds, [0.01, 0.02, 0.02, 0.02])
    assert path.feed == pytest.approx(0.02)  # the highest: what the path must sustain


def test_rapids_split_passes_and_their_targets_belong_to_none() -> None:
    path = read_cl_data(
        multax(
            "RAPID",
            "GOTO/0, 0, 50, 0, 0, 1",
            "GOTO/0, 0, 0, 0, 0, 1",
            "GOTO/10, 0, 0, 0, 0, 1",
            "RAPID",
            "GOTO/10, 0, 50, 0, 0, 1",
            "RAPID",
            "GOTO/0, 10, 50, 0, 0, 1",
            "GOTO/0, 10, 0, 0, 0, 1",
            "GOTO/10, 10, 0, 0, 0, 1",
            "GOTO/20, 10, 0, 0, 0, 1",
            "RAPID",
        )
    )
    assert path.passes == ((0, 2), (2, 5))
    assert path.lines.tolist() == [4, 5, 10, 11, 12]
    assert not np.any(path.positions[:, 2])  # no rapid target among the waypoints
    np.testing.assert_array_equal(path.pass_starts, [True, False, True, False, False])


@pytest.mark.parametrize("word", sorted(IGNORED - {"FINI"}))  # FINI ends the program
def test_ignored_records(word: str) -> None:
    plain = read_cl_data(multax(*TWO_CUTS))
    for record in (word, f"{word}/1, ABC, 2.5", f"{word} some free text"):
        path = read_cl_data(multax(record, TWO_CUTS[0], record, TWO_CUTS[1]))
        np.testing.assert_array_equal(path.positions, plain.positions)


def test_comments_and_continuations() -> None:
    path = read_cl_data(
        program(
            "$$ a comment line",
            "MULTAX/ON  $$ an inline comment",
            "GOTO/0, 0, $",
            "  0, 0, $  $$ a comment after a continuation",
            "  0, 1",
            "",
            "GOTO/10, 0, 0, 0, 0, 1 $$ GOTO/99, 99, 99",
        )
    )
    np.testing.assert_allclose(path.positions, [[0, 0, 0], [0.01, 0, 0]])
    assert path.lines.tolist() == [3, 7]


def test_a_nearly_unit_axis_is_normalised_and_the_correction_reported() -> None:
    path = read_cl_data(multax("GOTO/0, 0, 0, 0, 0, 1.0005", "GOTO/10, 0, 0, 0, 0.6, 0.7998"))
    np.testing.assert_allclose(np.linalg.norm(path.axes, axis=1), 1.0, atol=1e-15)
    assert path.axis_correction == pytest.approx(5e-4, rel=1e-9)


# --- errors naming the line ---------------------------------------------------------------


@pytest.mark.parametrize(
    ("record", "words"),
    [
        ("CIRCLE/0, 0, 0, 0, 0, 1, 5, 0.01, 0.5, 6, 0", ["arc starts on its axis"]),
        ("GODLTA/0, 0, 1", ["GODLTA", "not applied"]),
        ("123, 4", ["not a record"]),
        ("GOTO 1, 2, 3", ["'/'"]),
        ("RAPID/ON", ["RAPID takes no"]),
        ("UNITS/FEET", ["UNITS needs"]),
        ("MULTAX/MAYBE", ["MULTAX takes"]),
        ("TLAXIS/0, 1", ["TLAXIS needs"]),
        ("FEDRAT/IPR, 0.1", ["FEDRAT needs"]),
        ("FEDRAT/0", ["must be > 0"]),
        ("FEDRAT/-100", ["must be > 0"]),
        ("FEDRAT/MMPM, 1e-310", ["is 1.67e-315 m/s", "taken from 1e-06 to 100 m/s"]),
        ("FEDRAT/1e-320", ["is 0 m/s", "taken from 1e-06 to 100 m/s"]),
        ("FEDRAT/IPM, 1e308", ["is 4.23e+304 m/s", "(0.06 to 6e+06 mm/min)"]),
        ("FEDRAT/MMPM, 6.1e6", ["is 102 m/s"]),
        ("GOTO/0, 0, 0, 0", ["x, y, z, i, j, k", "got 4"]),
        ("GOTO/0, 0, 0, 0, 0", ["got 5"]),
        ("GOTO/1.2.3, 0, 0, 0, 0, 1", ["'1.2.3' is not a number"]),
        ("GOTO/abc, 0, 0, 0, 0, 1", ["'abc' is not a number"]),
        ("GOTO/, 0, 0, 0, 0, 1", ["'' is not a number"]),
        ("GOTO/1e999, 0, 0, 0, 0, 1", ["not a finite number"]),
        ("GOTO/nan, 0, 0, 0, 0, 1", ["not a finite number"]),
        ("GOTO/-inf, 0, 0, 0, 0, 1", ["not a finite number"]),
        ("GOTO/2e6, 0, 0, 0, 0, 1", ["beyond"]),
        ("GOTO/0, 0, 0, 0, 0, 1.002", ["tool axis", "length 1.002"]),
        ("GOTO/0, 0, 0, 0, 0, 0", ["tool axis", "length 0"]),
    ],
)
def test_bad_record_names_its_line(record: str, words: list[str]) -> None:
    error = line_error(multax("$$ line 2", TWO_CUTS[0], record, TWO_CUTS[1]))
    assert error.line == 4
    assert error.text == record
    assert error.field == "path.cl_data"
    assert str(error).startswith("path.cl_data: line 4: ")
    for word in words:
        assert word in error.message


def test_the_feeds_at_the_ends_of_the_range_are_read() -> None:
    """6e6 mm/min is 100 m/s, 0.1 mm/min 1.67e-6 m/s: both taken (the request's feed range)."""
    for record, feed in (("FEDRAT/MMPM, 6e6", 100.0), ("FEDRAT/MMPM, 0.1", 0.1e-3 / 60)):
        path = read_cl_data(multax(record, *TWO_CUTS))
        assert path.feed == pytest.approx(feed, rel=1e-12)


def test_units_may_not_change_after_a_goto() -> None:
    error = line_error(multax("UNITS/MM", TWO_CUTS[0], "UNITS/INCHES", TWO_CUTS[1]))
    assert error.line == 4 and "units change" in error.message
    read_cl_data(multax("UNITS/MM", TWO_CUTS[0], "UNITS/MM", TWO_CUTS[1]))  # no change: fine


def test_a_refused_record_is_echoed_at_most_100_characters() -> None:
    record = "TRACUT/" + ", ".join(["1.234567"] * 100)
    error = line_error(multax(record))
    assert error.line == 2
    assert len(error.message) < 200
    assert "..." in error.message


def test_a_continuation_past_the_end() -> None:
    error = line_error(multax(*TWO_CUTS, "GOTO/0, 0, $"))
    assert error.line == 4 and "continued" in error.message


@pytest.mark.parametrize(
    "text",
    ["", "$$ nothing\n", multax("RAPID", "GOTO/0, 0, 0, 0, 0, 1"), program("PARTNO X", "FINI")],
)
def test_no_cutting_move(text: str) -> None:
    with pytest.raises(InvalidInputError, match="no cutting move"):
        read_cl_data(text)


def test_a_pass_of_one_point_is_dropped_and_counted() -> None:
    path = read_cl_data(
        multax(*TWO_CUTS, "RAPID", "GOTO/0, 0, 50, 0, 0, 1", "GOTO/20, 0, 0, 0, 0, 1", "RAPID")
    )
    assert path.passes == ((0, 2),)
    assert path.one_point_passes == 1
    assert path.lines.tolist() == [2, 3]


def test_a_repeated_point_within_a_pass_is_dropped_and_counted() -> None:
    path = read_cl_data(multax(*TWO_CUTS, "GOTO/10.0000000, 0, 0, 0, 0, 1", "GOTO/20, 0, 0"))
    assert path.lines.tolist() == [2, 3, 5]
    assert path.report is not None and path.report.repeated_points == 1


def test_repeats_across_a_rapid_and_reorientations_in_place_are_fine() -> None:
    path = read_cl_data(
        multax(*TWO_CUTS, "GOTO/10, 0, 0, 0, 0.6, 0.8", "RAPID", "GOTO/10, 0, 50, 0, 0, 1",
               "GOTO/10, 0, 0, 0, 0.6, 0.8", "GOTO/20, 0, 0, 0, 0, 1")
    )  # fmt: skip
    assert path.passes == ((0, 3), (3, 5))


def test_a_right_angle_turn_names_its_line() -> None:
    path = read_cl_data(multax("GOTO/0, 0, 0, 0, 0, 1", "GOTO/10, 0, 0, 1, 0, 0"))
    with pytest.raises(InvalidLineError) as caught:
        path.waypoints_in_workpiece(field="path.cl_data")
    assert caught.value.line == 3
    assert caught.value.waypoint == 1


def test_the_cl_examples_are_what_their_script_writes() -> None:
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "make_cam_examples", CAM_EXAMPLES / "make_cam_examples.py"
    )
    assert spec is not None and spec.loader is not None
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    assert script.cl_program(inch=False) == (CAM_EXAMPLES / "sweep_mm.cl").read_text()
    assert script.cl_program(inch=True) == (CAM_EXAMPLES / "sweep_inch.cl").read_text()
    assert script.three_axis_program() == (CAM_EXAMPLES / "sweep_3axis_mm.cl").read_text()
