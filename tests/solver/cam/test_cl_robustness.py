"""Any text is read or refused with an input error, never a crash (no 5xx on any input).

Programs are drawn by Hypothesis (derandomized: the same examples every run) from the records
of every dialect with arbitrary arguments, numbers from tiny to huge included.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solver.cam.cl_data import read_cl_data
from solver.core.exceptions import InvalidLineError, SolverError

WORDS = [
    "GOTO", "CIRCLE", "FEDRAT", "RAPID", "UNITS", "UNIT", "MULTAX", "TLAXIS", "MSYS", "CSYS",
    "TRNTYP", "FROM", "LOADTL", "LOAD", "TOOL PATH", "END-OF-PATH", "PARTNO", "PPRINT", "PAINT",
    "CYCLE", "GODLTA", "CUTCOM", "WIBBLE", "$$", "Date\t",
]  # fmt: skip
NUMBERS = st.one_of(
    st.sampled_from([0.0, 1.0, -1.0, 0.5, 1e-12, 1e300, -1e300]),
    st.floats(min_value=-1e4, max_value=1e4, allow_nan=False),
)
TOKENS = st.one_of(
    NUMBERS.map(lambda v: f"{v:.6g}"),
    st.sampled_from(["MM", "INCH", "IPM", "MMPM", "ON", "OFF", "TOOL", "WORLD", "TIMES", "", "x"]),
)
RECORDS = st.builds(
    lambda word, slash, args, cont: (
        f"{word}{'/' if slash else ' '}{','.join(args)}" + ("$" if cont else "")
    ),
    st.sampled_from(WORDS),
    st.booleans(),
    st.lists(TOKENS, max_size=12),
    st.booleans(),
)


@settings(derandomize=True, max_examples=400, deadline=None)
@given(st.lists(RECORDS, min_size=1, max_size=30), st.sampled_from([None, "mm", "inches"]))
def test_every_program_is_read_or_refused_as_input(records: list[str], units: str | None) -> None:
    try:
        path = read_cl_data("\n".join(records), units=units)  # type: ignore[arg-type]
    except SolverError:
        return
    assert np.all(np.isfinite(path.positions))
    assert np.allclose(np.linalg.norm(path.axes, axis=1), 1.0)
    assert all(stop - start >= 2 for start, stop in path.passes)
    try:
        poses = path.waypoints_in_workpiece()
    except SolverError:
        return
    assert np.all(np.isfinite(poses))


def test_a_huge_arc_at_a_fine_tolerance_is_refused_not_computed() -> None:
    program = "UNITS/MM\nGOTO/900000,0,0\nCIRCLE/0,0,0,0,0,1,900000\nGOTO/-900000,1e-9,0\n"
    try:
        read_cl_data(program, arc_tolerance=1e-300)
    except SolverError as error:
        assert "points within" in str(error)
    else:
        raise AssertionError("a 1e-300 m tolerance on a 900 m arc must be refused")
    assert math.isfinite(read_cl_data(program).positions.max())


@pytest.mark.parametrize(
    ("record", "line"),
    [("MSYS/1e308,0,0,1,0,0,0,1,0", 2), ("CSYS/1,0,0,0,0,1,0,0,0,0,1,2e6", 2)],
)
def test_a_coordinate_system_beyond_reach_is_refused_on_its_own_line(
    record: str, line: int
) -> None:
    """The MSYS origin 1e308 was refused at the next GOTO, as that point's position."""
    with pytest.raises(InvalidLineError) as error:
        read_cl_data(f"UNITS/MM\n{record}\nGOTO/1,2,3\nGOTO/2,2,3\n")
    assert error.value.line == line
    assert "the coordinate system's origin" in error.value.message
    assert "beyond +-1000 m in any length unit" in error.value.message
