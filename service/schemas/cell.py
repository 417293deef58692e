"""The cell of a request (cell.md section 1): obstacles, the tool, the clearance; and a contact.

``fixed`` objects are in the robot base frame {B}, ``workpiece`` objects in the workpiece frame
{O} (they move with the placement). Each object is a ``shape`` with its sizes (m) and pose
(:mod:`service.schemas.cell_objects`). An answer reports the closest pair as a :class:`Contact`.
"""

from __future__ import annotations

import math

from pydantic import ConfigDict, Field

from service.config import MAX_CELL_OBJECTS
from service.schemas.cell_objects import CellObject, Size
from service.schemas.common import RequestModel, ResponseModel
from solver.core.exceptions import InvalidInputError
from solver.path.cell.shapes import (
    DEFAULT_CLEARANCE,
    DEFAULT_COLLISION_STEP,
    DEFAULT_CUTTING_LENGTH,
    MIN_COLLISION_STEP,
    Cell,
    Mesh,
    Tool,
)
from solver.path.cell.verdict import Contact as SolverContact
from solver.path.cell.verdict import Unchecked as SolverUnchecked

MAX_LINK_RADII = 64


class ToolSpec(RequestModel):
    """The spindle and holder: a cylinder along tool z ending at the tool point."""

    model_config = ConfigDict(
        json_schema_extra={"examples": [{"radius": 0.03, "length": 0.12, "cutting_length": 0.02}]}
    )

    radius: Size = Field(description="m.")
    length: Size = Field(
        description="m, from its start to the tool point, along tool z from the flange: the "
        "robot's tcp puts the tool point at the tool's tip. A tool that would start behind the "
        "flange (the tcp left at the flange) is refused, naming the length that fits."
    )
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
        ge=MIN_COLLISION_STEP,
        le=math.pi,
        description="rad, the largest joint move between two checks; a finer step weighs "
        "proportionally more against the size limits (50 times the default's at the least).",
    )
    link_radii: list[Size] | None = Field(
        default=None,
        min_length=1,
        max_length=MAX_LINK_RADII,
        description="m, capsule radii of an arm without collision geometry: the base's, then one "
        "per joint, each capsule along its link's kinematic segment (a UR e-series shoulder, "
        "upper arm and forearm along the links, beside the DH line by Universal Robots' "
        "shoulder and elbow offsets). Default: the arm's "
        "published collision capsules (UR5e, UR10e: MuJoCo Menagerie's, where the links are) or "
        "its URDF's geometry; given for a UR5e or UR10e, they replace the published capsules. "
        "They size the capsules of the links the answer's cell_approximated names: an arm whose "
        "links all carry collision geometry (the UR5's URDF meshes, the Panda's) uses none, and "
        "radii given for one are a 422 (they would size nothing).",
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
                item.to_solver(f"cell.{group}.{k}.{item.shape}", max_triangles)
                for k, item in enumerate(getattr(self, group))
            )
            for group in ("fixed", "workpiece")
        }
        pieces = sum(
            shape.part_count() if isinstance(shape, Mesh) else 1
            for group in shapes.values()
            for shape in group
        )
        if pieces > max_objects:
            raise InvalidInputError(
                "cell",
                f"{pieces} objects, each separate part of a mesh one (its convex hull); at most "
                f"{max_objects} (DTF_MAX_CELL_OBJECTS): join a mesh's parts, or send the ones "
                "near the robot",
            )
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


CELL_APPROXIMATED = (
    "With a cell: the robot's links given capsules along their kinematic segments, having no "
    "collision geometry the service can read (an arm built from DH or OPW parameters, a URDF "
    "whose meshes are elsewhere)."
)
CELL_UNCHECKED = (
    "With a cell: the robot parts not checked against a fixed object because no joint moves "
    "them relative to it, with their distance (the same at every configuration and placement): "
    "the base, which stands on the fixed objects, and a link only joint 1 turns about a fixed "
    "halfspace's normal, joint 1 on or above the halfspace's boundary (joint 1's link of an arm "
    "on its table, which a capsule from joint 1's origin at the foot would otherwise cut at "
    "every placement; a table top above joint 1 is checked, and collides)."
)


class UncheckedPair(ResponseModel):
    """A robot part not checked against a fixed object: no joint moves it relative to it."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "robot_part": "joint_1_capsule",
                    "obstacle": 0,
                    "obstacle_name": "table",
                    "distance": -0.05,
                }
            ]
        }
    )

    robot_part: str = Field(
        description="The robot's geometry object: the base's, or a link only joint 1 turns "
        "about the normal of a fixed halfspace (joint 1's link of an arm on its table)."
    )
    obstacle: int = Field(description="The fixed object's index.")
    obstacle_name: str = Field(description="Its name, or its place (fixed[0]).")
    distance: float = Field(
        description="m, coal's distance at the zero configuration, the same at every "
        "configuration and placement (negative: they overlap, as a base stands on its table)."
    )

    @classmethod
    def from_solver(cls, pair: SolverUnchecked) -> UncheckedPair:
        """The schema of a solver record."""
        return cls(
            robot_part=pair.robot_part,
            obstacle=pair.obstacle,
            obstacle_name=pair.obstacle_name,
            distance=pair.distance,
        )
