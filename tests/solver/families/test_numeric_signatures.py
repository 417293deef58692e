"""The numeric family hands its kernels one array type, whatever views its callers pass.

numba compiles a kernel once per argument type, and a read-only array (a broadcast, or an array
whose ``writeable`` flag is off, as a robot's limits may be) is another type than a writable
one: each such caller compiled the six-joint seeding, following and J^-1 t a second time
(seconds of CPU each on a fresh install). The family makes its arrays alike
(:func:`solver.core.kernel_arrays.kernel_array`); here read-only and writable
inputs give the same answers and leave one signature per kernel.
"""

from __future__ import annotations

import numpy as np

from solver.core.codes import TIE_RTOL
from solver.families.numeric import bounded_kernel, chain_kernel, follow_kernel, seed_kernel
from solver.families.numeric.family import NumericFamily
from solver.path import bounded
from tests.solver.families.numeric_maps import ur5_from_urdf


def _read_only(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view


def test_read_only_and_writable_inputs_share_one_signature() -> None:
    robot = ur5_from_urdf()
    family = robot.family
    assert isinstance(family, NumericFamily)
    path_q = np.column_stack(
        [
            np.linspace(0.3, 0.5, 6),
            np.full(6, -1.2),
            np.full(6, 1.4),
            np.linspace(-0.6, -0.4, 6),
            np.full(6, 0.8),
            np.full(6, 0.7),
        ]
    )
    rotations, positions = chain_kernel.forward(family.chain.packed(), path_q)
    rng = np.random.default_rng(5)
    twists, tools = rng.normal(size=(1, 6, 6)), positions[None] + 0.05
    rules = (TIE_RTOL, bounded.MARGIN, bounded.ROUGH, bounded.SLACK, bounded.STRIDE)
    answers = []
    for view in (_read_only, np.array):  # read-only views first, then writable copies
        current, count = family.seed_first(view(rotations[:1]), view(positions[:1]))
        q, status = family.follow_piece(
            current.copy(), view(rotations[None]), view(positions[None]), False
        )
        followed = family.follow_bounded(
            current,
            (view(rotations[None]), view(positions[None])),
            (view(twists), view(tools), view(robot.qdot_max), view(np.zeros(6, bool)), 0.35),
            (*rules, bounded.RESIDUAL, bounded.MOTION),
        )
        speeds = family.joint_speeds_per_unit_twist(
            view(path_q[:1].T), view(twists[0, :1].T), view(tools[0, :1].T)
        )
        answers.append((current, count, q, status, *followed, speeds))
    assert answers[0][1][0] >= 2  # the pose has several branches
    for read_only, writable in zip(*answers, strict=True):
        np.testing.assert_array_equal(read_only, writable)
    for kernel in (
        seed_kernel.seed_paths,
        follow_kernel.follow_paths,
        bounded_kernel.follow_bounded,
        chain_kernel.speeds_per_twist,
    ):
        assert len(kernel.signatures) == 1, kernel
