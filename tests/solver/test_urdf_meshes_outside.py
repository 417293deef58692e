"""A URDF's collision meshes are read from example-robot-data's share folder only (cell.md s. 2).

The contract audit (stop 54): the filter was a pattern over the text, ``<collision ...
</collision>``; an element starting with a comment holding ``</collision>`` ended there for
the pattern, and the mesh after it was read from any file of the server (its hull changed the
answer), or was a 500 where the name was a folder or a FIFO. Read as XML, the element is the
element, and a mesh outside the share folder leaves its link to a capsule, as the answer says.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from solver.core.exceptions import InvalidInputError
from solver.core.robots import example_robot_data_dir
from solver.families import robot_from_urdf
from solver.path.cell.checker import CellChecker
from solver.path.cell.shapes import Cell
from tests.solver.test_cell import ascii_stl, cube_triangles

SHARED = "package://example-robot-data/robots/ur_description/meshes/ur5/collision/wrist3.stl"


def _ur5_urdf() -> str:
    return (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()


@pytest.mark.parametrize("hide", ["<!-- </collision> -->", "<![CDATA[</collision>]]>", ""])
@pytest.mark.parametrize("target", ["file", "folder", "fifo", "file://"])
def test_a_mesh_outside_the_share_is_never_read(tmp_path: Path, hide: str, target: str) -> None:
    outside = tmp_path / "secret.stl"
    outside.write_bytes(ascii_stl(cube_triangles(0.6)))
    names = {"file": str(outside), "folder": str(tmp_path), "file://": f"file://{outside}"}
    if target == "fifo":
        os.mkfifo(tmp_path / "pipe")
        names["fifo"] = str(tmp_path / "pipe")
    urdf = _ur5_urdf()
    assert urdf.count(f'<mesh filename="{SHARED}"/>') == 1
    urdf = urdf.replace(f'<mesh filename="{SHARED}"/>', f'{hide}<mesh filename="{names[target]}"/>')
    arm = robot_from_urdf(urdf, base_frame="base", tool_frame="tool0", name="ur5-outside")
    checker = CellChecker(arm, Cell())
    assert "wrist_3_joint" in checker.approximated  # its only element was left out
    assert not any(obj.name.startswith("wrist_3_link") for obj in checker.geometry.geometryObjects)


def test_the_meshes_a_urdf_has_read_are_bounded() -> None:
    """Each collision mesh is read and made a hull per request: fifteen copies of a 28 MB mesh
    (scaled differently, so no cache holds) took 41 s. The UR5's own reads 0.27 MB."""
    share = example_robot_data_dir()
    big = max(share.rglob("*.stl"), key=lambda path: path.stat().st_size)
    name = "package://example-robot-data/robots/" + str(big.relative_to(share))
    copies = 20_000_000 // big.stat().st_size + 1
    elements = "".join(
        f'<collision><geometry><mesh filename="{name}" scale="1 1 {1 + k / 100}"/></geometry>'
        "</collision>"
        for k in range(copies)
    )
    urdf = _ur5_urdf()
    at = urdf.index("</link>", urdf.index('<link name="wrist_3_link">'))
    arm = robot_from_urdf(
        urdf[:at] + elements + urdf[at:], base_frame="base", tool_frame="tool0", name="ur5-heavy"
    )
    with pytest.raises(InvalidInputError, match="at most 20 MB") as refused:
        CellChecker(arm, Cell())
    assert refused.value.field == "robot.urdf"
