"""The optimiser's decision vector: named placement variables, each with its bounds.

One type for every part of the search (the coarse map, differential evolution, SLSQP, the NLP,
the symmetry and the answer): a decision vector is an array over ``VARIABLES`` = (x, y, yaw,
spin, z), and :class:`PlacementBounds` gives each its range. A variable whose range is a single
value is fixed (the spin and the height z, by default: a table); the others are free.

This module is the one place that knows the order: everything else makes vectors with
:func:`decision_vector` or :func:`vector_of`, reads them with :func:`variables_of` (numpy or
casadi alike) and turns them into placement rows with :func:`placement_rows`. Adding a variable
(a table tilt, a track position) touches this module and the pose transform.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.core.spatial import MAX_COORDINATE, Placement

VARIABLES = ("x", "y", "yaw", "spin", "z")  # m, m, rad, rad, m
N_VARIABLES = len(VARIABLES)
# A decision vector's entries in the order of a placement row [x, y, z, yaw, spin]
# (solver.core.spatial.Placement.as_row, the batched layout of the path pipeline).
_ROW_ORDER = [VARIABLES.index(name) for name in ("x", "y", "z", "yaw", "spin")]
_TWO_PI = 2 * math.pi


class Variables(NamedTuple):
    """A decision vector's entries by name (floats, or casadi expressions in the NLP)."""

    x: Any
    y: Any
    yaw: Any
    spin: Any
    z: Any


def decision_vector(*, x: float, y: float, yaw: float, spin: float, z: float) -> np.ndarray:
    """The decision vector of named values, shape (N_VARIABLES,)."""
    named = {"x": x, "y": y, "yaw": yaw, "spin": spin, "z": z}
    return np.array([named[name] for name in VARIABLES], dtype=float)


def variables_of(vector: Any) -> Variables:
    """The named entries of a decision vector (a numpy array or a casadi symbol of N_VARIABLES)."""
    return Variables(**{name: vector[k] for k, name in enumerate(VARIABLES)})


def placement_rows(vectors: np.ndarray) -> np.ndarray:
    """Decision vectors (P, N_VARIABLES) as placement rows (P, 5) [x, y, z, yaw, spin]."""
    v = np.asarray(vectors, dtype=float).reshape(-1, N_VARIABLES)
    return v[:, _ROW_ORDER]


@dataclass(frozen=True)
class PlacementBounds:
    """A box of placements: x, y (m), yaw and tool spin (rad) ranges at height z (m).

    Attributes:
        x: (min, max), m. y: (min, max), m. yaw: (min, max), rad.
        z: m, the height of every placement; or (min, max), m, to search it too.
        spin: (min, max), rad, the constant tool spin (cam.md section 3); (0, 0) fixes it.
    """

    x: tuple[float, float]
    y: tuple[float, float]
    yaw: tuple[float, float]
    z: float | tuple[float, float]
    spin: tuple[float, float] = (0.0, 0.0)

    @property
    def z_range(self) -> tuple[float, float]:
        """(min, max) of the height, m; one value twice when it is fixed."""
        if isinstance(self.z, tuple):
            return (float(self.z[0]), float(self.z[1]))
        return (float(self.z), float(self.z))

    def _range(self, name: str) -> tuple[float, float]:
        """(min, max) of a variable."""
        return self.z_range if name == "z" else getattr(self, name)

    def check(self) -> None:
        """Raise InvalidInputError naming the range that is not finite, reversed or too wide."""
        for name in VARIABLES:
            low, high = self._range(name)
            field = "z" if name == "z" and not isinstance(self.z, tuple) else f"bounds.{name}"
            if not (math.isfinite(low) and math.isfinite(high) and low <= high):
                raise InvalidInputError(field, f"needs finite [min, max], got {[low, high]}")
            if name in ("x", "y", "z") and max(abs(low), abs(high)) > MAX_COORDINATE:
                raise InvalidInputError(field, f"beyond +-{MAX_COORDINATE:g} m")
        if self.spin[1] - self.spin[0] > _TWO_PI + 1e-12:
            raise InvalidInputError(
                "bounds.spin",
                f"{self.spin[1] - self.spin[0]:.6g} rad is wider than a turn (2 pi rad)",
            )

    def within_a_turn(self) -> PlacementBounds:
        """The box, a yaw range over a turn cut to the turn centred on its middle.

        The same placements (yaw is periodic) and the same reported copy (the one nearest the
        middle of the range), with the work of one turn: a range of +-1000 rad made the coarse
        map's yaw axis, the box's edges and the local searches a thousand times longer, 37 s
        and more of one synchronous request (the contract audit, stop 54).
        """
        low, high = self.yaw
        if high - low <= _TWO_PI:
            return self
        middle = (low + high) / 2.0
        return dataclasses.replace(self, yaw=(middle - math.pi, middle + math.pi))

    def wrapped_yaw(self, yaw: float) -> float:
        """The copy of ``yaw`` (rad, up to whole turns) nearest the yaw range's middle."""
        middle = (self.yaw[0] + self.yaw[1]) / 2.0
        return middle + math.remainder(yaw - middle, _TWO_PI)

    @property
    def lower(self) -> np.ndarray:
        """Shape (N_VARIABLES,), the lower bound of each variable."""
        return np.array([self._range(name)[0] for name in VARIABLES])

    @property
    def upper(self) -> np.ndarray:
        """Shape (N_VARIABLES,), the upper bound of each variable."""
        return np.array([self._range(name)[1] for name in VARIABLES])

    @property
    def free(self) -> np.ndarray:
        """Shape (N_VARIABLES,), bool: the variables with a range (the others are fixed)."""
        return self.upper > self.lower

    def contains(self, vector: np.ndarray, *, slack: float = 1e-12) -> bool:
        """Whether a decision vector (N_VARIABLES,) is inside the box (to ``slack``)."""
        v = np.asarray(vector, dtype=float)
        return bool(np.all(v >= self.lower - slack) and np.all(v <= self.upper + slack))

    def clamp(self, vector: np.ndarray) -> np.ndarray:
        """The decision vector moved into the box."""
        clamped: np.ndarray = np.clip(np.asarray(vector, dtype=float), self.lower, self.upper)
        return clamped

    def centre(self) -> np.ndarray:
        """The middle of the box, a decision vector."""
        middle: np.ndarray = (self.lower + self.upper) / 2
        return middle

    def placement(self, vector: np.ndarray) -> Placement:
        """The placement of a decision vector."""
        v = variables_of([float(value) for value in vector])
        return Placement(v.x, v.y, v.z, v.yaw, spin=v.spin)

    def rows(self, vectors: np.ndarray) -> np.ndarray:
        """Decision vectors (P, N_VARIABLES) as placement rows (P, 5) [x, y, z, yaw, spin]."""
        return placement_rows(vectors)


def vector_of(placement: Placement) -> np.ndarray:
    """The decision vector of a placement."""
    return decision_vector(
        x=placement.x, y=placement.y, yaw=placement.yaw, spin=placement.spin, z=placement.z
    )
