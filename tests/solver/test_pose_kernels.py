"""The compiled pose kernels (:mod:`solver.families.kernels`) on any span of waypoints.

The UR kernel works LANES waypoints at a time in a work space of fixed-length rows
(:mod:`solver.families.lanes`: the compiler runs four waypoints in one vector instruction).
Its answers must not depend on where a span starts or ends: a span of one waypoint (the map's
probes), spans that cross a LANES boundary, and the whole path give the same bits. And they
are the numpy IK's and Jacobian's (:mod:`solver.families.ur.ik`,
:mod:`solver.families.ur.jacobian`): the same statuses, the same angles and joint speeds to
rounding.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.core.codes import OK, SINGULAR, UNREACHABLE
from solver.families.kernels import OPW_KERNEL, UR_KERNEL, pose_block
from solver.families.lanes import LANES
from solver.families.opw.kernel import kernel_parameters as opw_parameters
from solver.families.ur.dh import UR_DH
from solver.families.ur.ik import forward_kinematics_dh, solve_batch
from solver.families.ur.jacobian import joint_speeds_per_unit_twist
from solver.families.ur.kernel import kernel_parameters as ur_parameters
from solver.kernels.cell import pose_work
from tests.solver.families.test_opw import build

N = 3 * LANES + 7  # three whole passes and a part


def flange_poses(seed: int) -> np.ndarray:
    """N flange poses of a UR5 (N, 4, 4): most reachable, a few out of reach, one singular."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (N, 6))
    q[5, 4] = 0.0  # wrist singular (q5 = 0)
    q[6, 2] = 0.0  # elbow stretched (q3 = 0)
    poses = forward_kinematics_dh(UR_DH["ur5"], q)
    poses[[10, 40, 80], :3, 3] *= 5.0  # out of reach
    return poses


def kernel_rows(transforms: np.ndarray, twist: np.ndarray, tool: np.ndarray) -> np.ndarray:
    """The kernels' pose rows (21, N): R_B_F row by row, p_B_F, the twist, the tool point."""
    rows = np.empty((21, len(transforms)))
    rows[:9] = transforms[:, :3, :3].reshape(-1, 9).T
    rows[9:12] = transforms[:, :3, 3].T
    rows[12:18] = twist.T
    rows[18:21] = tool.T
    return rows


def solve(code: int, par: np.ndarray, poses: np.ndarray, spans: list[tuple[int, int]]) -> tuple:
    """cq, sq, status, qd of every branch, filled span by span."""
    cq, sq, qd, status, _, scratch, need = pose_work(poses.shape[1])
    for array in (cq, sq, qd):
        array[:] = np.nan
    status[:] = -1
    need[:] = True
    for w0, w1 in spans:
        pose_block(code, par, poses, w0, w1, need, scratch, cq, sq, status, qd)
    return cq, sq, status, qd


def pieces(cuts: list[int]) -> list[tuple[int, int]]:
    """The spans between consecutive cuts."""
    return list(zip(cuts[:-1], cuts[1:], strict=True))


SPANS = [
    pieces([0, N]),
    pieces(list(range(N + 1))),  # one waypoint at a time, as the map's probes
    pieces([0, 1, LANES + 2, LANES + 3, 2 * LANES - 1, 3 * LANES + 1, N]),
]


def assert_same_bits(a: tuple, b: tuple) -> None:
    """Every array equal, NaN where NaN."""
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("seed", [0, 1])
def test_ur_kernel_is_the_numpy_ik_and_jacobian_on_any_span(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    transforms = flange_poses(seed)
    twist, tool = rng.normal(size=(N, 6)), transforms[:, :3, 3] + rng.normal(0, 0.1, (N, 3))
    poses = kernel_rows(transforms, twist, tool)
    par = ur_parameters(UR_DH["ur5"])
    answers = [solve(UR_KERNEL, par, poses, spans) for spans in SPANS]
    for other in answers[1:]:
        assert_same_bits(answers[0], other)
    cq, sq, status, qd = answers[0]
    q_ref, status_ref = solve_batch(UR_DH["ur5"], transforms)  # (N, 8, 6), (N, 8)
    np.testing.assert_array_equal(status, status_ref.T)
    assert {OK, SINGULAR, UNREACHABLE} <= set(np.unique(status))
    # Compared where well conditioned: the kernel takes sin q3 and sin q5 as sqrt(1 - cos^2),
    # the numpy IK as the sine of an acos, and both lose digits as 1 / sin near the singularity.
    conditioned = (np.abs(np.sin(q_ref[..., 2])) > 0.01) & (np.abs(np.sin(q_ref[..., 4])) > 0.01)
    ok = (status.T == OK) & conditioned  # (N, 8)
    assert ok.sum() > N
    q_ok = q_ref[ok]  # (M, 6)
    np.testing.assert_allclose(np.moveaxis(cq, 2, 0)[ok], np.cos(q_ok), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.moveaxis(sq, 2, 0)[ok], np.sin(q_ok), rtol=0, atol=1e-12)
    where = np.nonzero(ok)[0]
    speeds = joint_speeds_per_unit_twist(UR_DH["ur5"], q_ok.T, twist[where].T, tool[where].T)
    np.testing.assert_allclose(np.moveaxis(qd, 2, 0)[ok], speeds.T, rtol=1e-9, atol=1e-9)


def test_opw_kernel_on_any_span() -> None:
    """The OPW kernel, in its share of the same work space, gives the same bits on any span."""
    rng = np.random.default_rng(7)
    transforms = flange_poses(3)
    poses = kernel_rows(transforms, rng.normal(size=(N, 6)), transforms[:, :3, 3])
    par = opw_parameters(build("offsets_everywhere").family.parameters)  # type: ignore[union-attr]
    answers = [solve(OPW_KERNEL, par, poses, spans) for spans in SPANS]
    for other in answers[1:]:
        assert_same_bits(answers[0], other)
    assert (answers[0][2] == OK).any()
