"""Known answers shared by the tests, each with where it comes from and its tolerance."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

UR_MODELS = ("ur3", "ur5", "ur10", "ur3e", "ur5e", "ur10e", "ur16e")
E_SERIES = ("ur3e", "ur5e", "ur10e", "ur16e")
# Arms with no analytic IK: example-robot-data URDFs with the numeric family (robots.md 4).
NUMERIC_MODELS = ("panda", "xarm7", "kinova_jaco2")
OPW_MODELS = (
    "kuka_kr6_r700_sixx",
    "kuka_kr16_2",
    "abb_irb2400",
    "abb_irb4600_60_205",
    "fanuc_m20ia",
    "fanuc_r2000ic_165f",
)

# Sensors 2022 Table 3 (task requirements of three UR5e path segments): u_T, u_R, h (m).
SENSORS_TABLE_3 = {
    "i": ([0.9999, 0.0, 0.0117], [0.6209, 0.7625, -0.1820], 4.4632),
    "ii": ([-0.9893, 0.0, 0.1459], [0.0865, -0.9761, -0.1994], 0.0360),
    "iii": ([0.9992, 0.0, 0.0411], [0.9997, -0.0249, 0.0011], 0.7454),
}


def unit(vector: list[float]) -> np.ndarray:
    """The table's 4-digit directions, renormalised (they are unit only to ~1e-4)."""
    arr = np.asarray(vector, dtype=float)
    return arr / np.linalg.norm(arr)


# Relative agreement between the closed-form DTF and the LP optimum (issue 2).
DTF_LP_RTOL = 1e-9
# FK(IK(T)) = T (issue 2), on every matrix entry (metres for the position column).
FK_IK_ATOL = 1e-9
# The CB-series URDFs round pi/2 (1.57079632679); the catalogue restores it, so their chain
# matches the DH chain to rounding.
CB_URDF_VS_DH_ATOL = 1e-12
TWO_PI = 2 * math.pi
# A capability-map cell against /v1/evaluate at that placement (issue 3): relative.
MAP_EVALUATE_RTOL = 1e-9
# An optimum against /v1/evaluate at the reported placement, and the two methods (issue 4).
OPTIMUM_EVALUATE_RTOL = 1e-6
OPTIMUM_METHODS_RTOL = 1e-5

# The free-spin two-variable LP against HiGHS with the spin rate free (issue 8): relative.
FREE_SPIN_LP_RTOL = 1e-9
# Fixed mode with the free mode's spins against the free mode's mu_path (cam.md section 2: the
# discretisation error of the schedule, under 1 % on a 133-waypoint path).
SPIN_SCHEDULE_RTOL = 0.01

# CAM files (cam.md sections 5, 6 and 8).
CAM_EXAMPLES = EXAMPLES / "cam"
# The same program in inches and in millimetres (coordinates exact in both): metres agree to this.
INCH_MM_ATOL = 1e-12
# A controller's frame back to the matrix (cam.md section 8): every entry, m for the position.
FRAME_ROUND_TRIP_ATOL = 1e-9

# UR5 as a plain URDF through the numeric family against the analytic UR family (issue 11):
# the share of cells where feasibility and, on analytic-feasible cells, mu_path agree, and the
# relative tolerance of "agree" (numeric never above the analytic value by more).
NUMERIC_VS_ANALYTIC_AGREEMENT = 0.98
NUMERIC_VS_ANALYTIC_RTOL = 1e-6

# Joint accelerations at a constant feed (issue 24, motion.md section 2). The README example
# (UR5, examples/evaluate_request.json at x 0, y 0.45, z 0.1, yaw 0, blend 2 mm): mu_acc at
# every joint limited to a (rad/s^2), as motion.md gives it (6 digits), wrist_3 at waypoint 57.
README_MU_ACC = {10.0: 0.238835, 3.0: 0.130816}
README_MU_ACC_ATOL = 5e-7
README_MU_ACC_WAYPOINT, README_MU_ACC_JOINT = 57, 5
# The compiled kernels' mu_acc and V_acc against the numpy pipeline's. Their joint angles come
# from different IK formulas (the kernel's atan2 of its (cos, sin) pairs) and differ in the last
# bits; D_i sums them with weights of 4 / b^2 in all, so 1 / V_acc^2 = max_j |D_ij| / a_j can
# agree only to a few ulp of 2 pi times 4 / (b^2 a_j) (at b = 2 mm and 10 rad/s^2, one such
# ulp moves a V_acc of 0.24 m/s by 2.6e-12 relative). Measured: up to 1.7 of them on the UR5,
# 7.5 on the OPW arms; on top of mu_path's 1e-12 relative.
KERNEL_ACC_ULPS = 16
# D_i written in the test from the answer's joint path and arc lengths (motion.md section 5).
SECOND_DIFFERENCE_RTOL = 1e-9
# A smooth analytic path at 2,000 points: mu_acc against toppra's largest constant feed (its
# cubic spline of q(s)), and the time-optimal cycle time against toppra's on that spline.
TOPPRA_FEED_RTOL = 0.01
TOPPRA_TIME_RTOL = 0.02
# The README example at 10 rad/s^2: L / mu_acc (motion.md section 4 gives 1.338 s).
README_CONSTANT_FEED_TIME_10 = 1.338
README_CONSTANT_FEED_TIME_ATOL = 5e-4
# The pass at mu_acc with its ramps against toppra with the feed capped at mu_acc (a virtual
# joint q = s limited to mu_acc m/s), on toppra's spline: relative.
TOPPRA_RAMP_RTOL = 0.01
