"""A mesh of separate parts is checked as one convex hull per part (Mesh.parts).

The cell audit (stop 53): a fixture of two clamp blocks 0.5 m apart sent as one STL was one
hull filling the space between them where the tool works, and every placement of a 60-cell map
collided; the same blocks sent as two boxes left 56 feasible. The known answer here is that
map with two boxes: a box's mesh hull is the box.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import Placement
from solver.families import get_robot
from solver.path.capability_map import capability_map, grid_axis
from solver.path.cell.checker import CellChecker
from solver.path.cell.shapes import Box, Cell, Halfspace, Mesh
from solver.path.cell.stl import read_stl
from solver.path.evaluate import evaluate_path
from solver.path.problem import PathOptions, PathProblem
from tests.solver.test_cell import ascii_stl, binary_stl, cube_triangles
from tests.solver.test_evaluate import load_path

SIDE = 0.05
CLAMPS = ((-0.25, 0.06, 0.0), (0.25, 0.06, 0.0))  # in {O}, either side of the ERK path


def _at(position: tuple[float, float, float]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = position
    return pose


def _blocks(centres: tuple[tuple[float, float, float], ...]) -> np.ndarray:
    return np.concatenate([cube_triangles(SIDE) + np.array(centre) for centre in centres])


def test_the_parts_of_a_mesh_are_its_separate_solids() -> None:
    two = _blocks(CLAMPS)
    shuffled = two[np.random.default_rng(3).permutation(len(two))]
    parts = Mesh(shuffled).parts()
    assert len(parts) == 2
    for part in parts:  # each part is one block's 12 triangles, whichever block comes first
        centre = part.reshape(-1, 3).mean(axis=0)
        assert len(part) == 12
        assert min(np.linalg.norm(centre - np.array(c)) for c in CLAMPS) < 1e-12
    assert len(Mesh(cube_triangles(0.1)).parts()) == 1
    # a binary STL keeps float32 corners: shared corners stay equal, the parts stay two
    read = read_stl(binary_stl(two), max_triangles=24, units="m")
    assert len(Mesh(read).parts()) == 2
    # blocks touching along an edge share its corners: one part
    touching = _blocks(((0.0, 0.0, 0.0), (SIDE, 0.0, 0.0)))
    assert len(Mesh(touching).parts()) == 1


def test_a_clamp_pair_mesh_maps_as_two_boxes() -> None:
    robot, path = get_robot("ur5"), load_path("curved_line")
    as_mesh = Cell(workpiece=(Mesh(_blocks(CLAMPS), name="clamps"),))
    as_boxes = Cell(workpiece=tuple(Box((SIDE,) * 3, _at(c), name="clamps") for c in CLAMPS))
    axes = {
        "xs": grid_axis(-0.2, 0.2, 0.1, field="x"),
        "ys": grid_axis(0.3, 0.6, 0.1, field="y"),
        "z": 0.1,
        "yaws": np.array([-1.0, 0.0, 1.0]),
    }
    maps = [
        capability_map(PathProblem.of(robot, path, PathOptions(cell=cell)), **axes)  # type: ignore[arg-type]
        for cell in (as_mesh, as_boxes)
    ]
    np.testing.assert_array_equal(maps[0].reason, maps[1].reason)
    np.testing.assert_array_equal(maps[0].mu_path, maps[1].mu_path)
    assert (maps[0].reason == -1).sum() >= 50  # one hull of both: 0 of 60


def test_a_contact_names_the_mesh_whichever_part() -> None:
    """The second block, around the tool point at waypoint 0: obstacle 1 (the mesh), its name;
    the contact's pair found again by the quick refusal test (CellChecker.collides_at)."""
    robot, path = get_robot("ur5"), load_path("curved_line")
    placement = Placement(0.0, 0.45, 0.1, 0.0)
    tool_point = (placement.transform_workpiece_to_base() @ path[0])[:3, 3]
    far = (1.5, 1.5, 1.5)
    mesh = Mesh(_blocks((far, tuple(tool_point))), name="clamps")
    cell = Cell(fixed=(Halfspace((0.0, 0.0, 1.0), -0.5, name="floor"), mesh))
    evaluation = evaluate_path(PathProblem.of(robot, path, PathOptions(cell=cell)), placement)
    contact = evaluation.collision
    assert evaluation.reason == "collision" and contact is not None
    assert (contact.waypoint, contact.obstacle, contact.obstacle_name) == (0, 1, "clamps")
    assert contact.obstacle_slot == 2  # the floor, the far block, the block at the tool
    checker = CellChecker(robot, cell)
    q0 = evaluate_path(PathProblem.of(robot, path), placement).q
    assert q0 is not None
    transform = placement.transform_workpiece_to_base()
    assert checker.collides_at(q0[0], transform, contact)


def test_an_ascii_stl_with_a_long_solid_line_is_ascii() -> None:
    """Its facets past the first 4 kB: it was refused as a binary STL of 2 billion triangles."""
    text = ascii_stl(cube_triangles(0.1)).replace(b"solid cube", b"solid " + b"x" * 5000, 1)
    np.testing.assert_allclose(read_stl(text, max_triangles=12), cube_triangles(0.1), atol=1e-12)


def test_a_vertex_of_four_numbers_is_refused() -> None:
    text = ascii_stl(cube_triangles(0.1)).replace(b"vertex -0.05 -0.05 -0.05", b"vertex 1 2 3 4", 1)
    assert b"vertex 1 2 3 4" in text
    with pytest.raises(InvalidInputError, match="a vertex is not three numbers"):
        read_stl(text, max_triangles=12)


def test_an_ascii_stl_cut_after_a_whole_facet_is_refused_naming_its_last_vertex() -> None:
    """It was read as the part of the solid it held: a fixture with fewer triangles than it has,
    placements that hit the rest answered free of it. Every cut after a facet's end is refused;
    the whole file is read."""
    text = ascii_stl(cube_triangles(0.1))
    lines = text.decode().splitlines()
    ends = [n for n, line in enumerate(lines, 1) if line == "endfacet"]
    for end in ends:
        cut = ("\n".join(lines[:end]) + "\n").encode()
        last_vertex = max(n for n, line in enumerate(lines[:end], 1) if line.startswith("vertex"))
        with pytest.raises(InvalidInputError, match="no endsolid after its last vertex") as refused:
            read_stl(cut, max_triangles=12, field="cell.fixed.0.stl")
        assert f"(line {last_vertex})" in str(refused.value)
        assert refused.value.field == "cell.fixed.0.stl"
    np.testing.assert_allclose(read_stl(text, max_triangles=12), cube_triangles(0.1), atol=1e-12)
    assert len(ends) == 12
