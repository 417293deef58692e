"""CSV paths (cam.md section 5): tool-axis and pose forms, units, header, bad lines."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from solver.cam.cl_data import read_cl_data
from solver.cam.csv_path import read_csv_path
from solver.core.exceptions import InvalidInputError, InvalidLineError
from tests.cases import CAM_EXAMPLES, INCH_MM_ATOL

# The pose CSV prints 9 decimals of metres and of the quaternion.
PRINTED_POSE_ATOL = 1e-8


def line_error(text: str, units: str = "m") -> InvalidLineError:
    with pytest.raises(InvalidLineError) as caught:
        read_csv_path(text, units=units)
    return caught.value


def test_csv_example_is_the_first_pass_of_the_cl_example() -> None:
    csv = read_csv_path((CAM_EXAMPLES / "sweep_pass1.csv").read_text(), units="mm")
    cl = read_cl_data((CAM_EXAMPLES / "sweep_mm.cl").read_text())
    assert csv.passes == ((0, 13),) and csv.units == "mm" and csv.feed is None
    assert csv.lines.tolist() == list(range(2, 15))  # line 1 is the header
    np.testing.assert_allclose(csv.positions, cl.positions[:13], rtol=0, atol=INCH_MM_ATOL)
    np.testing.assert_array_equal(csv.axes, cl.axes[:13])
    assert csv.default_spin_mode == "free"


def test_pose_csv_example_gives_the_parallel_transport_poses() -> None:
    axes = read_csv_path((CAM_EXAMPLES / "sweep_pass1.csv").read_text(), units="mm")
    poses = read_csv_path((CAM_EXAMPLES / "sweep_pass1_pose.csv").read_text(), units="m")
    assert poses.axes is None and poses.rotations is not None
    assert poses.default_spin_mode == "fixed"
    np.testing.assert_allclose(
        poses.waypoints_in_workpiece(), axes.waypoints_in_workpiece(), atol=PRINTED_POSE_ATOL
    )


@pytest.mark.parametrize(
    ("units", "scale", "name"), [("mm", 1e-3, "mm"), ("m", 1.0, "m"), ("inch", 0.0254, "inches")]
)
def test_units(units: str, scale: float, name: str) -> None:
    path = read_csv_path("1,2,3,0,0,1\n4,5,6,0,0,1\n", units=units)
    np.testing.assert_allclose(path.positions, np.array([[1, 2, 3], [4, 5, 6]]) * scale)
    assert path.units == name


def test_quaternion_form_against_scipy() -> None:
    rng = np.random.default_rng(11)
    quaternions = Rotation.random(5, random_state=rng).as_quat()  # x, y, z, w
    text = "X, Y, Z, qx, qy, qz, qw\n" + "".join(
        f"{i * 0.01},0,0,{','.join(repr(float(v)) for v in q)}\n" for i, q in enumerate(quaternions)
    )
    path = read_csv_path(text, units="m")
    np.testing.assert_allclose(
        path.rotations, Rotation.from_quat(quaternions).as_matrix(), atol=1e-15
    )


def test_blank_lines_and_spaces_are_fine() -> None:
    text = "\n x , y, z, i, j, k \n\n0, 0, 0, 0, 0, 1\n\n1, 0, 0, 0, 0, 1\n"
    path = read_csv_path(text, units="m")
    assert path.lines.tolist() == [4, 6]


def test_near_unit_vectors_are_normalised_and_reported() -> None:
    path = read_csv_path("0,0,0,0,0,0.9993\n1,0,0,0,0,1\n", units="m")
    assert path.axis_correction == pytest.approx(7e-4, rel=1e-9)
    path = read_csv_path("0,0,0,0,0,0,1.0002\n1,0,0,0,0,0,1\n", units="m")
    assert path.axis_correction == pytest.approx(2e-4, rel=1e-9)


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ("x,y,z,i,j,k\n0,0,0,0,0,1\n1,0,0,0,0\n", 3, ["5 values", "x, y, z, i, j, k"]),
        ("0,0,0,0,0,1\n1,0,0,0,0,0,1\n", 2, ["7 values"]),
        ("0,0,0,0,0\n1,0,0,0,0\n", 1, ["5 values", " or "]),
        ("x,y,z,qw,qx,qy,qz\n0,0,0,1,0,0,0\n", 1, ["header", "qx, qy, qz, qw"]),
        ("0,0,0,0,0,1\nx,y,z,i,j,k\n", 2, ["'x' is not a number"]),
        ("0,0,0,0,0,1\n1,0,nan,0,0,1\n", 2, ["not a finite number"]),
        ("0,0,0,0,0,1\n1,0,1e400,0,0,1\n", 2, ["not a finite number"]),
        ("0,0,0,0,0,1\n1;0;0;0;0;1\n", 2, ["1 values"]),
        ("0,0,0,0,0,1\n1,0,0,0,0,1.01\n", 2, ["tool axis", "length 1.01"]),
        ("0,0,0,0,0,0,1\n1,0,0,0,0,0,0.99\n", 2, ["quaternion", "length 0.99"]),
        ("0,0,0,0,0,1\n0,0,0,0,0,1\n", 2, ["repeats", "line 1"]),
        ("0,0,0,0,0,0,1\n0,0,0,0,0,0,-1\n", 2, ["repeats"]),  # -q is the same pose
        ("0,0,0,0,0,1\n2000,0,0,0,0,1\n", 2, ["beyond"]),
        ("x,y,z,i,j,k\n0,0,0,0,0,1\n", 2, ["at least 2 waypoints"]),
    ],
)
def test_bad_line_names_its_line(text: str, line: int, words: list[str]) -> None:
    error = line_error(text)
    assert error.line == line
    assert error.field == "path.csv"
    for word in words:
        assert word in error.message


@pytest.mark.parametrize("text", ["", "x,y,z,i,j,k\n", "\n\n"])
def test_no_waypoint(text: str) -> None:
    with pytest.raises(InvalidInputError, match="no cutting move"):
        read_csv_path(text, units="m")


@pytest.mark.parametrize("units", ["cm", "feet", "MM"])
def test_units_other_than_mm_inch_or_m(units: str) -> None:
    """(``inches``, as answers name the unit, is read as ``inch``: the service's audit 24.)"""
    with pytest.raises(InvalidInputError, match="mm or m") as caught:
        read_csv_path("0,0,0,0,0,1\n1,0,0,0,0,1\n", units=units)
    assert caught.value.field == "units"


def test_a_csv_saved_by_excel_with_its_byte_order_mark_reads_as_without() -> None:
    """Excel's "CSV UTF-8" starts with U+FEFF: the header then named no column it knew."""
    text = (CAM_EXAMPLES / "sweep_pass1.csv").read_text()
    marked, plain = (read_csv_path(t, units="mm") for t in ("\ufeff" + text, text))
    np.testing.assert_array_equal(marked.positions, plain.positions)
    np.testing.assert_array_equal(marked.axes, plain.axes)
    assert marked.lines.tolist() == plain.lines.tolist()
