"""The objects of a request's cell (cell.md section 1): one shape a variant, told apart by its key.

``shape`` is box, cylinder, sphere, halfspace or mesh (an STL), with its sizes (m) and a pose in
its group's frame; each object converts itself to the solver's shape (``to_solver``).
"""

from __future__ import annotations

import base64
import binascii
import math
from typing import Annotated, Literal

import numpy as np
from pydantic import ConfigDict, Field

from service.schemas.common import Pose, RequestModel, UnitComponent, pose_matrix_of
from solver.core.exceptions import InvalidInputError
from solver.path.cell.shapes import (
    MAX_SIZE,
    Box,
    Cylinder,
    Halfspace,
    Mesh,
    Shape,
    Sphere,
)
from solver.path.cell.stl import read_stl

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
        min_length=3,
        max_length=3,
        description="n: the outward normal, each component within +-1.001 (a unit vector's).",
    )
    offset: float = Field(
        ge=-MAX_SIZE,
        le=MAX_SIZE,
        description="d (m): the points p with n . p <= d (n as given: with a unit n, d is the "
        "boundary's distance from the origin; n = [0, 0, 0.5] and d = 0.05 is z <= 0.1).",
    )

    def to_solver(self, field: str, max_triangles: int) -> Shape:
        """The solver's halfspace."""
        if math.hypot(*self.normal) < 1e-9:
            raise InvalidInputError(f"{field}.normal", "the normal must not be 0")
        nx, ny, nz = self.normal
        return Halfspace((nx, ny, nz), self.offset, self.name)


class MeshObject(_Object):
    """A triangle mesh from an STL file, each separate part taken as its convex hull."""

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
