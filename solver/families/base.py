"""The closed-form families' common base: a six-joint arm whose IK and J^-1 t are functions.

The seam itself (:class:`solver.core.family.KinematicsFamily`) is in :mod:`solver.core.family`.

"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from solver.core.family import Branch, KinematicsFamily
from solver.core.progress import Progress
from solver.families.kernels import TILTED


class ClosedFormFamily(KinematicsFamily):
    """A six-joint family whose IK and J^-1 t are closed-form functions of its parameters.

    A subclass names the family and gives its branches and its two functions, each taking the
    parameters first (``solve(parameters, rotation, position)``,
    ``speeds(parameters, q, twist, tool_point)``), as :mod:`solver.families.ur` and
    :mod:`solver.families.opw` do; and, for the compiled map, its pose kernel's code in
    :mod:`solver.families.kernels` and the function that makes the kernel's parameters.
    """

    branch_labels: tuple[Branch, ...]
    solve_function: Callable[..., tuple[np.ndarray, np.ndarray]]
    speeds_function: Callable[..., np.ndarray]
    kernel_code: int | None = None
    kernel_parameters_function: Callable[..., np.ndarray] | None = None

    def __init__(self, parameters: object) -> None:
        """Hold the arm's parameters (the geometry the two functions take)."""
        self.parameters = parameters

    @property
    def dof(self) -> int:
        """Six joints."""
        return 6

    @property
    def branches(self) -> tuple[Branch, ...]:
        """The family's branch labels."""
        return self.branch_labels

    def solve(self, rotation: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All branches in closed form (see :meth:`KinematicsFamily.solve`), in its base turn.

        The chain's flange poses are the family's own flange's first, where they differ
        (:attr:`KinematicsFamily.flange_offset`).
        """
        if self.flange_offset is not None:
            rotation, position = self.flange_offset.family_flange(rotation, position)
        if self.base_turn is not None:
            rotation = self.base_turn.vectors_in(rotation)
            position = self.base_turn.points_in(position)
        return type(self).solve_function(self.parameters, rotation, position)

    @property
    def tilted(self) -> bool:
        """Whether the family solves in a frame whose z is not {B}'s (its base turn's tilt)."""
        return self.base_turn is not None and self.base_turn.tilt is not None

    def map_kernel(self) -> tuple[int, np.ndarray] | None:
        """The family's pose kernel code and this arm's kernel parameters (see the base).

        Where the family's frame {A} is tilted from {B}, the code plus
        :data:`solver.families.kernels.TILTED`, and R_A_B and {A}'s origin before the
        parameters: the kernels place a path in {B} (a turn about its z) and write each block's
        poses in {A} (:func:`solver.families.kernels.pose_block`).
        """
        make = type(self).kernel_parameters_function
        if self.kernel_code is None or make is None:
            return None
        if not self.tilted:
            return self.kernel_code, make(self.parameters)
        assert self.base_turn is not None  # tilted
        frame = np.concatenate(
            [self.base_turn.vectors_in(np.eye(3)).ravel(), np.asarray(self.base_turn.shift)]
        )
        return self.kernel_code + TILTED, np.concatenate([frame, make(self.parameters)])

    def path_cost(self, n_waypoints: int, *, free_spin: bool = False) -> float:
        """A pose a waypoint (the unit): the compiled kernel's, tilted or not."""
        return float(n_waypoints)

    def joint_speeds_per_unit_twist(
        self,
        q: np.ndarray,
        twist: np.ndarray,
        tool_point: np.ndarray,
        *,
        qdot_max: np.ndarray | None = None,
        progress: Progress | None = None,
    ) -> np.ndarray:
        """J^-1 t in closed form (see :meth:`KinematicsFamily.joint_speeds_per_unit_twist`).

        It takes milliseconds for a whole path: ``progress`` is not called. In a base turn the
        twist's two parts and the point are turned into it (joint speeds do not depend on the
        frame they are written in).
        """
        if self.base_turn is not None:
            turn = self.base_turn
            twist = np.concatenate([turn.vectors_in(twist[:3]), turn.vectors_in(twist[3:])])
            tool_point = turn.points_in(tool_point)
        return type(self).speeds_function(self.parameters, q, twist, tool_point)
