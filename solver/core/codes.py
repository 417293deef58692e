"""Codes shared by the numpy pipeline and its compiled twins (one place for both).

An IK solution's status (what a family's ``solve`` gives per pose and branch), and why a branch
or a placement fails along a path (dtf.md section 4): an index into :data:`REASONS`, or
:data:`FEASIBLE`. The compiled kernels use the same integers, so a kernel cell equals a numpy
cell code for code.
"""

from __future__ import annotations

from typing import Literal

# Status of a (pose, branch) IK solution.
OK = 0
UNREACHABLE = 1
SINGULAR = 2
# A regular solution on the other side of the singular set: det J < 0 (a six-joint numeric
# family's solutions carry the sign of det J, J (6, 6) at the flange or any point, as OK and
# OK_MIRRORED; an analytic family gives OK only, its branch labels fix that sign). Tracking
# calls a change between OK and OK_MIRRORED from one waypoint of a pass to the next a
# discontinuity: the branch crossed a singularity (q5 = 0, the elbow, the shoulder) between
# the samples, where the analytic branch jumps (robots.md: a wrist never passes q5 = 0).
OK_MIRRORED = 3

Reason = Literal["unreachable", "joint_limits", "singular", "discontinuous", "collision"]
REASONS: tuple[Reason, ...] = (
    "unreachable",
    "joint_limits",
    "singular",
    "discontinuous",
    "collision",
)
FEASIBLE = -1  # reason code of a feasible branch
# The index of each reason in REASONS. The kernels give the first four; ``collision`` (cell.md
# section 3) is given after them, by the path checks of :mod:`solver.path.limits`.
REASON_UNREACHABLE, REASON_JOINT_LIMITS, REASON_SINGULAR, REASON_DISCONTINUOUS = range(4)
REASON_COLLISION = 4
# Branches whose mu_path is within this relative tolerance of the best tie; the first in the
# family's order is chosen (dtf.md section 4).
TIE_RTOL = 1e-12
# Along a path, a waypoint takes the bottleneck over only where its V_max is below this
# fraction of every earlier waypoint's: a tie in the last bits stays with the earlier waypoint,
# as a branch tie with the first branch. Repeated geometry ties: the same corner cut on
# several levels binds joint 1 at the same V_max on each, which a map's kernel and the
# evaluator round apart in the last bit (14 of 117 cells of a 2,500-move pocket program named
# two waypoints). :func:`solver.path.bottleneck.bottleneck_waypoint` and the kernels' running
# minimum (solver/kernels/fixed_follow.py, free_follow.py) apply it alike.
TAKES_OVER = 1.0 - TIE_RTOL
# The same for mu_acc (motion.md section 2): D_i divides the joint angles' last bits by b^2, so
# mu_acc is known to a few 1e-12 only (at b = 2 mm, 10 rad/s^2 and 0.24 m/s a bit of q moves it
# by up to 2.6e-12), and the wrist-flip branches, whose q6 differ by pi, tie to that rounding.
ACC_TIE_RTOL = 1e-9
# Slack (rad) when fitting a joint's 2 pi copy inside its limits.
EDGE = 1e-12
