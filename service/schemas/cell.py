"""The cell of a request (cell.md section 1): obstacles, the tool, the clearance.

``fixed`` objects are in the robot base frame {B}, ``workpiece`` objects in the workpiece frame
{O} (they move with the placement). Each object is a ``shape`` with its sizes (m) and pose.
"""

from __future__ import annotations

import base64
import binascii
import math
from typing import Annotated, Literal

import numpy as np
from pydantic import ConfigDict, Field

from service.schemas.common import (
    Pose,
    RequestModel,
    ResponseModel,
    UnitComponent,
    pose_matrix_of,
)
from solver.core.exceptions import InvalidInputError
from solver.path.cell.shapes import (
    DEFAULT_CLEARANCE,
    DEFAULT_COLLISION_STEP,
    DEFAULT_CUTTING_LENGTH,
    MAX_SIZE,
    Box,
    Cell,
    Cylinder,
    Halfspace,
    Mesh,
    Shape,
    Sphere,
    Tool,
)
from solver.path.cell.stl import read_stl
from solver.path.cell.verdict import Contact as SolverContact

MAX_CELL_OBJECTS = 1_000  # the schema's bound; the setting DTF_MAX_CELL_OBJECTS is lower
MAX_LINK_RADII = 64
MAX_NAME = 100

Size = Annotated[float, Field(gt=0.0, le=MAX_SIZE)]
"""A length (m), > 0 and at most 100 m."""
Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME)]


class _Object(RequestModel):
    """What every object has: an optional name and a pose (default: the frame itself)."""

    name: Name | None = Field(default=None, description="Named in a collision's report.")
    pose: Pose | None = Field(
        default=None,
        description="Position (m) and unit quaternion [qx, qy, qz, qw] in the object's frame "
        "({B} for fixed, {O} for workpiece); default the frame's origin and axes.",
    )

    def _pose(self, field: str) -> np.ndarray:
        """The 4 x 4 pose (identity by default)."""
        if self.pose is None:
            return np.eye(4)
        return pose_matrix_of(self.pose, field=f"{field}.pose")


class BoxObject(_Object):
    """A box centred on its pose."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "shape": "box",
                    "name": "fixture",
                    "size": [0.1, 0.1, 0.3],
                    "pose": {"position": [-0.3, 0.2, 0.15], "orientation": [0, 0, 0, 1]},
                }
            ]
        }
    )

    shape: Literal["box"] = Field(description="The kind of object.")
    size: list[Size] = Field(min_length=3, max_length=3, description="[lx, ly, lz] (m).")

    def to_solver(self, field: str, max_triangles: int) -> Shape:
        """The solver's box."""
        lx, ly, lz = self.size
        return Box((lx, ly, lz), self._pose(field), self.name)


class CylinderObject(_Object):
    """A cylinder along its pose's z, centred on it."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "shape": "cylinder",
                    "name": "pedestal",
                    "radius": 0.1,
                    "length": 0.5,
                    "pose": {"position": [0.6, 0.0, 0.25], "orientation": [0, 0, 0, 1]},
                }
            ]
        }
    )

    shape: Literal["cylinder"] = Field(description="The kind of object.")
    radius: Size = Field(description="m.")
    length: Size = Field(description="m, along z.")

    def to_solver(self, field: str, max_triangles: int) -> Shape:
        """The solver's cylinder."""
        return Cylinder(self.radius, self.length, self._pose(field), self.name)


class SphereObject(_Object):
    """A sphere at its pose's origin."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "shape": "sphere",
                    "radius": 0.05,
                    "pose": {"position": [0.4, 0.3, 0.4], "orientation": [0, 0, 0, 1]},
                }
            ]
        }
    )

    shape: Literal["sphere"] = Field(description="The kind of object.")
    radius: Size = Field(description="m.")

    def to_solver(self, field: str, max_triangles: int) -> Shape:
        """The solver's sphere."""
        return Sphere(self.radius, self._pose(field), self.name)


class HalfspaceObject(RequestModel):
    """The points p with normal . p <= offset: a floor, a table top (no pose)."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {"shape": "halfspace", "name": "table", "normal": [0, 0, 1], "offset": 0.0}
            ]
        }
    )

    shape: Literal["halfspace"] = Field(description="The kind of object.")
    name: Name | None = Field(default=None, description="Named in a collision's report.")
    normal: list[UnitComponent] = Field(
        min_length=3, max_length=3, description="Outward normal (made unit)."
    )
    offset: float = Field(ge=-MAX_SIZE, le=MAX_SIZE, description="d (m, along the unit normal).")

    def to_solver(self, field: str, max_triangles: int) -> Shape:
        """The solver's halfspace."""
        if math.hypot(*self.normal) < 1e-9:
            raise InvalidInputError(f"{field}.normal", "the normal must not be 0")
        nx, ny, nz = self.normal
        return Halfspace((nx, ny, nz), self.offset, self.name)


class MeshObject(_Object):
    """A triangle mesh from an STL file (taken as its convex hull)."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "shape": "mesh",
                    "name": "part",
                    "units": "mm",
                    "stl": "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                    "vertex 100 0 0\nvertex 0 100 0\nendloop\nendfacet\nendsolid t\n",
                }
            ]
        }
    )

    shape: Literal["mesh"] = Field(description="The kind of object.")
    stl: str = Field(
        min_length=1,
        description="The STL file: ASCII text (starting 'solid'), or a binary STL in base64. "
        "At most DTF_MAX_MESH_TRIANGLES triangles.",
    )
    units: Literal["m", "mm", "cm", "in"] = Field(default="m", description="The file's unit.")

    def to_solver(self, field: str, max_triangles: int) -> Shape:
        """The solver's mesh, its STL read (bounded in triangles)."""
        text = self.stl.lstrip()
        if text[:5].lower() == "solid":
            data = text.encode()
        else:
            try:
                data = base64.b64decode(self.stl, validate=True)
            except (binascii.Error, ValueError) as exc:
                raise InvalidInputError(
                    f"{field}.stl", "not an STL: neither ASCII ('solid ...') nor base64"
                ) from exc
        triangles = read_stl(
            data,
            max_triangles=max_triangles,
            units=self.units,
            field=f"{field}.stl",
            setting="DTF_MAX_MESH_TRIANGLES",
        )
        return Mesh(triangles, self._pose(field), self.name)


CellObject = Annotated[
    BoxObject | CylinderObject | SphereObject | HalfspaceObject | MeshObject,
    Field(discriminator="shape"),
]


class ToolSpec(RequestModel):
    """The spindle and holder: a cylinder along tool z ending at the tool point."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"radius": 0.03, "length": 0.12, "cutting_length": 0.02}]}
    )

    radius: Size = Field(description="m.")
    length: Size = Field(description="m, from its start to the tool point.")
    cutting_length: Size = Field(
        default=DEFAULT_CUTTING_LENGTH,
        description="m, the last part (ending at the tool point) that may touch workpiece objects.",
    )


class CellSpec(RequestModel):
    """The robot's surroundings (cell.md): checked along the tracked path, sub-steps included."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "fixed": [
                        {"shape": "halfspace", "name": "table", "normal": [0, 0, 1], "offset": 0.0}
                    ],
                    "workpiece": [
                        {
                            "shape": "box",
                            "name": "part",
                            "size": [0.3, 0.12, 0.09],
                            "pose": {"position": [0.0, 0.06, -0.045], "orientation": [0, 0, 0, 1]},
                        }
                    ],
                    "tool": {"radius": 0.03, "length": 0.12},
                }
            ]
        }
    )

    fixed: list[CellObject] = Field(
        default_factory=list,
        max_length=MAX_CELL_OBJECTS,
        description="Objects in the base frame {B}: table, walls, pedestal, a second machine.",
    )
    workpiece: list[CellObject] = Field(
        default_factory=list,
        max_length=MAX_CELL_OBJECTS,
        description="Objects in the workpiece frame {O}, moving with the placement: the part, "
        "its fixture.",
    )
    tool: ToolSpec | None = Field(default=None, description="The tool; default none.")
    clearance: float = Field(
        default=DEFAULT_CLEARANCE,
        ge=0.0,
        le=1.0,
        description="m, the least distance any checked pair may come to.",
    )
    collision_step: float = Field(
        default=DEFAULT_COLLISION_STEP,
        gt=0.0,
        le=math.pi,
        description="rad, the largest joint move between two checks.",
    )
    link_radii: list[Size] | None = Field(
        default=None,
        min_length=1,
        max_length=MAX_LINK_RADII,
        description="m, capsule radii of an arm without collision geometry: the base's, then one "
        "per joint. Default: the arm's published radii (UR5e, UR10e) or its URDF's geometry.",
    )

    def to_solver(self, *, max_objects: int, max_triangles: int) -> Cell:
        """The solver's cell, bounded in objects and mesh triangles (the settings).

        Raises:
            InvalidInputError: too many objects, a bad mesh, or a bad size.
        """
        count = len(self.fixed) + len(self.workpiece)
        if count > max_objects:
            raise InvalidInputError(
                "cell", f"{count} objects; at most {max_objects} (DTF_MAX_CELL_OBJECTS)"
            )
        shapes = {
            group: tuple(
                item.to_solver(f"cell.{group}.{k}", max_triangles)
                for k, item in enumerate(getattr(self, group))
            )
            for group in ("fixed", "workpiece")
        }
        tool = None
        if self.tool is not None:
            tool = Tool(self.tool.radius, self.tool.length, self.tool.cutting_length)
        return Cell(
            fixed=shapes["fixed"],
            workpiece=shapes["workpiece"],
            tool=tool,
            clearance=self.clearance,
            collision_step=self.collision_step,
            link_radii=None if self.link_radii is None else tuple(self.link_radii),
        )


class Contact(ResponseModel):
    """The closest pair of robot part and obstacle (or another robot part) on a path."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "waypoint": 128,
                    "robot_part": "wrist_3_link_0",
                    "obstacle": 1,
                    "obstacle_name": "part",
                    "distance": 0.0167,
                }
            ]
        }
    )

    waypoint: int = Field(description="The waypoint, or the one whose sub-steps it is between.")
    robot_part: str = Field(description="The robot's geometry object (link, capsule or tool).")
    obstacle: int | None = Field(
        description="The obstacle's index, fixed first then workpiece; null for a robot part."
    )
    obstacle_name: str = Field(
        description="Its name, its place (fixed[0]), or the other robot part's name."
    )
    distance: float = Field(description="m, coal's distance (negative: penetration).")

    @classmethod
    def from_solver(cls, contact: SolverContact | None) -> Contact | None:
        """The schema of a solver contact (None stays None)."""
        if contact is None:
            return None
        return cls(
            waypoint=contact.waypoint,
            robot_part=contact.robot_part,
            obstacle=contact.obstacle,
            obstacle_name=contact.obstacle_name,
            distance=contact.distance,
        )
