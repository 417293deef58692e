"""The six-joint map's kernels compiled without reference counting keep their answers.

:func:`solver.families.numeric.bounded_kernel.follow_bounded`, ``seed_kernel.seed_paths`` and
``chain_kernel.speeds_per_twist`` run their loops compiled with ``_nrt=False``; the maps they
give are held to the numpy reference and to following every slot elsewhere
(test_numeric_kernel.py, test_numeric_pruned_map.py). Here: the branches of that code those
maps rarely reach, the wrap of a joint value (against Python's float modulo) and the singular
test's eigenvalue fallback (against numpy's :func:`ik.is_singular`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from solver.core.codes import SINGULAR, TIE_RTOL
from solver.families.numeric import bounded_kernel, chain_kernel, ik
from solver.families.numeric.family import NumericFamily
from solver.path import bounded
from tests.solver.families.numeric_maps import ur5_from_urdf


@njit(cache=False)
def _wrap_all(values: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    out = np.empty_like(values)
    for i in range(len(values)):
        out[i] = bounded_kernel.wrapped(values[i])
    return out


def test_wrapped_is_python_modulo_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    edges = [math.pi, -math.pi, 0.0, -0.0, 2 * math.pi, -2 * math.pi, 3 * math.pi, 1e300]
    edges += [float(np.nextafter(math.pi, s)) for s in (0.0, 4.0)]
    edges += [float(np.nextafter(-math.pi, s)) for s in (0.0, -4.0)]
    edges += [math.pi - 2 * math.pi + 1e-16, 1e-300, -1e-300]
    values = np.array([*edges, *rng.uniform(-20.0, 20.0, 20_000)])
    expected = np.array([(v + math.pi) % (2 * math.pi) - math.pi for v in values.tolist()])
    got = _wrap_all(values)
    np.testing.assert_array_equal(got.view(np.int64), expected.view(np.int64))


def test_a_singular_waypoint_is_singular_as_numpy_says() -> None:
    """A slot followed through the UR5's wrist singularity (q5 = 0): each status as numpy's."""
    robot = ur5_from_urdf()
    family = robot.family
    assert isinstance(family, NumericFamily)
    q5 = np.array([0.2, 0.1, 0.0, 0.0, 0.0, 0.0, -0.1, -0.2])  # exactly 0 twice: rank lost
    path_q = np.column_stack(
        [
            np.linspace(0.3, 0.4, 8),
            np.full(8, -1.2),
            np.full(8, 1.4),
            np.linspace(-0.6, -0.5, 8),
            q5,
            np.full(8, 0.7),
        ]
    )
    rotations, positions = chain_kernel.forward(family.chain.packed(), path_q)
    rng = np.random.default_rng(4)
    twists, tools = rng.normal(size=(1, 8, 6)), positions[None] + 0.05
    settings, constants = family._settings()
    rules = (TIE_RTOL, bounded.MARGIN, bounded.ROUGH, bounded.SLACK, bounded.STRIDE)
    q, status, _, dropped = family.follow_bounded(
        path_q[None, :1].copy(),
        (rotations[None], positions[None]),
        (twists, tools, robot.qdot_max, np.zeros(8, dtype=bool), 0.35),
        (*rules, bounded.RESIDUAL, bounded.MOTION),
    )
    assert not dropped.any()
    assert settings[3] == ik.SINGULAR_RCOND and constants[0] == ik.TOLERANCE
    followed = q[:, 0, 0].T  # (8, 6), wrapped
    assert np.isfinite(followed).all()
    expected = ik.is_singular(family.chain, followed)
    assert expected[2] and expected[3] and not expected[0]  # the case reaches both answers
    np.testing.assert_array_equal(status[0, 0] == SINGULAR, expected)
