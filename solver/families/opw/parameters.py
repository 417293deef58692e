"""The seven lengths, offsets and sign corrections of an OPW arm (robots.md section 3).

Brandstotter, Angerer, Hofbaur (2014): an industrial arm with an ortho-parallel basis and a
spherical wrist is described by a1, a2, b, c1, c2, c3, c4 (m). ``offsets`` (rad) and
``sign_corrections`` (+-1) map the paper's joint zero and direction to the maker's, the
convention of the ROS-Industrial support packages and of ``opw_kinematics``:
q_paper = sign_correction * q_maker - offset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from solver.core.exceptions import InvalidInputError

MAX_LENGTH = 100.0  # m: no arm is bigger; beyond it a request is a typo


@dataclass(frozen=True)
class OpwParameters:
    """Geometry of an OPW arm (metres, radians).

    Attributes:
        a1, a2, b, c1, c2, c3, c4: the paper's lengths (m); c2 > 0 and c3 > 0.
        offsets: shape (6,), rad: the paper's angle is sign_correction * maker's - offset, so
            the maker's is sign_correction * (paper's + offset) (opw_kinematics' forward and
            inverse).
        sign_corrections: shape (6,), each +1 or -1 (py-opw-kinematics' ``flip_axes`` is -1).
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets: tuple[float, ...] = (0.0,) * 6
    sign_corrections: tuple[int, ...] = (1,) * 6

    def __post_init__(self) -> None:
        """Check the values; raise InvalidInputError naming the field (``robot.opw.<name>``)."""
        for name in ("a1", "a2", "b", "c1", "c2", "c3", "c4"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value)):
                raise InvalidInputError(f"robot.opw.{name}", f"{value} m is not a finite length")
            if abs(value) > MAX_LENGTH:
                raise InvalidInputError(
                    f"robot.opw.{name}", f"{value} m is beyond +-{MAX_LENGTH:g} m"
                )
        for name in ("c2", "c3"):
            if getattr(self, name) <= 0.0:
                raise InvalidInputError(
                    f"robot.opw.{name}", f"{getattr(self, name)} m must be > 0 (a link length)"
                )
        if len(self.offsets) != 6 or not all(math.isfinite(v) for v in self.offsets):
            raise InvalidInputError(
                "robot.opw.offsets", f"needs 6 finite angles (rad), got {len(self.offsets)} values"
            )
        if len(self.sign_corrections) != 6 or any(s not in (1, -1) for s in self.sign_corrections):
            raise InvalidInputError(
                "robot.opw.sign_corrections",
                f"needs 6 values, each +1 or -1, got {list(self.sign_corrections)}",
            )
