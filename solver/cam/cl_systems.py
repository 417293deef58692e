"""The coordinate systems CL points are written in: NX ``MSYS`` and SolidWorks ``CSYS`` (cam.md 9).

- ``MSYS/x, y, z, xi, xj, xk, yi, yj, yk``: the machine coordinate system's origin and its x
  and y axes, in the part's frame; z = x cross y.
- ``CSYS/r11, r12, r13, t1, r21, r22, r23, t2, r31, r32, r33, t3``: the 3 x 4 matrix [R | t],
  row by row, that takes a point written in the system to the part's frame; SolidWorks writes it
  after ``TRNTYP/WORLD, 0, 0, 0`` (the system given in the world frame).

Either way a point p as written is o + R p in the part frame, a tool axis R a. Axes within 1e-3
of unit length and of orthogonality are made orthonormal (cam.md section 6); a mirror is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidLineError
from solver.core.spatial import MAX_COORDINATE
from solver.core.tool_axis import NEAR_UNIT_TOLERANCE


@dataclass(frozen=True)
class CoordinateSystem:
    """Where a CL file's points are written, in the part frame.

    Attributes:
        rotation: shape (3, 3), R, its columns the system's axes in the part frame.
        origin: shape (3,), in the file's length unit, the system's origin in the part frame.
    """

    rotation: np.ndarray
    origin: np.ndarray

    def same_as(self, other: CoordinateSystem) -> bool:
        """Whether both systems are the same (to 1e-12)."""
        return bool(
            np.allclose(self.rotation, other.rotation, rtol=0, atol=1e-12)
            and np.allclose(self.origin, other.origin, rtol=0, atol=1e-12)
        )


PART = CoordinateSystem(rotation=np.eye(3), origin=np.zeros(3))
"""The part frame itself, in force until a file states a system."""


def msys(values: np.ndarray, *, field: str, line: int, text: str) -> CoordinateSystem:
    """The system of ``MSYS/x, y, z, xi, xj, xk, yi, yj, yk`` (9 numbers).

    Raises:
        InvalidLineError: another count, axes that are not orthonormal within 1e-3, or an
            origin beyond MAX_ORIGIN.
    """
    if values.shape != (9,):
        raise InvalidLineError(
            field,
            f"MSYS needs x, y, z, xi, xj, xk, yi, yj, yk; got {values.size}",
            line=line,
            text=text,
        )
    x_axis, y_axis = values[3:6], values[6:9]
    rotation = _orthonormal(
        np.column_stack([x_axis, y_axis, np.cross(x_axis, y_axis)]),
        field=field,
        line=line,
        text=text,
    )
    return CoordinateSystem(
        rotation=rotation, origin=_origin(values[:3], field=field, line=line, text=text)
    )


def csys(values: np.ndarray, *, field: str, line: int, text: str) -> CoordinateSystem:
    """The system of ``CSYS/`` and its 3 x 4 matrix, row by row (12 numbers).

    Raises:
        InvalidLineError: another count, a matrix whose R is not a rotation within 1e-3, or an
            origin beyond MAX_ORIGIN.
    """
    if values.shape != (12,):
        raise InvalidLineError(
            field,
            f"CSYS needs a 3 x 4 matrix (12 numbers); got {values.size}",
            line=line,
            text=text,
        )
    matrix = values.reshape(3, 4)
    rotation = _orthonormal(matrix[:, :3], field=field, line=line, text=text)
    return CoordinateSystem(
        rotation=rotation, origin=_origin(matrix[:, 3], field=field, line=line, text=text)
    )


MAX_ORIGIN = MAX_COORDINATE / 1e-3
"""The largest coordinate of a system's origin, in the file's unit: MAX_COORDINATE in mm, the
smallest unit a program states (its unit may be stated after the system). An origin beyond it
was refused at the next GOTO, as that point's position (the hostile-input audit: MSYS/1e308)."""


def _origin(origin: np.ndarray, *, field: str, line: int, text: str) -> np.ndarray:
    """The system's origin, refused where it is not finite or beyond MAX_ORIGIN.

    Raises:
        InvalidLineError: on the system's own line.
    """
    if not np.all(np.abs(origin) <= MAX_ORIGIN):  # NaN too
        raise InvalidLineError(
            field,
            f"the coordinate system's origin {origin.tolist()} is beyond +-{MAX_COORDINATE:g} m "
            "in any length unit",
            line=line,
            text=text,
        )
    return origin.copy()


def _orthonormal(rotation: np.ndarray, *, field: str, line: int, text: str) -> np.ndarray:
    """The nearest rotation to ``rotation`` (SVD), refused when it is off by more than 1e-3."""
    u, _, vt = np.linalg.svd(rotation)
    nearest: np.ndarray = u @ vt
    off = float(np.max(np.abs(rotation - nearest)))
    if not off <= NEAR_UNIT_TOLERANCE or np.linalg.det(nearest) < 0.0:
        raise InvalidLineError(
            field,
            f"the coordinate system's axes are not orthonormal and right-handed (off by "
            f"{off:.3g}; within {NEAR_UNIT_TOLERANCE:g} they are made so)",
            line=line,
            text=text,
        )
    return nearest
