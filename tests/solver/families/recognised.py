"""Helpers of the recognition tests: a frame added to a URDF, two robots' answers compared."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np
import pytest

from solver.core.robots import Robot
from solver.core.spatial import Placement
from tests.cases import MAP_EVALUATE_RTOL
from tests.problems import evaluate_path, evaluate_placements, prepare_path


def with_fixed_frame(
    text: str, name: str, parent: str, xyz: Iterable[float], rpy: Iterable[float]
) -> str:
    """URDF text with a frame ``name`` fixed to ``parent`` at (xyz, rpy)."""
    xyz_text, rpy_text = (" ".join(repr(float(v)) for v in values) for values in (xyz, rpy))
    return text.replace(
        "</robot>",
        f'<link name="{name}"/><joint name="{name}_joint" type="fixed"><parent link="{parent}"/>'
        f'<child link="{name}"/><origin xyz="{xyz_text}" rpy="{rpy_text}"/></joint></robot>',
    )


def bent_elbow(ur5_text: str) -> str:
    """The UR5's URDF text with its elbow's axis turned by a mrad: no UR or OPW arm (numeric IK)."""
    elbow = '<origin rpy="0.0 0.0 0.0" xyz="0.0 -0.1197 0.425"/>'
    assert ur5_text.count(elbow) == 1
    return ur5_text.replace(elbow, elbow.replace('rpy="0.0 0.0 0.0"', 'rpy="0.001 0 0"'))


def answers_alike(
    robot: Robot, path: np.ndarray, placement: Placement, expected: object, **options: Any
) -> bool:
    """Whether ``robot``'s answer at ``placement`` is feasible, after asserting it is ``expected``.

    The same feasibility and reason; where feasible, mu_path and the joint path, and the map
    kernel's mu_path at the placement; ``options`` as the problem's (``spin_mode``).
    """
    answer = evaluate_path(robot, path, placement, **options)
    assert isinstance(expected, type(answer))
    assert answer.feasible == expected.feasible and answer.reason == expected.reason
    if not expected.feasible:
        return False
    assert answer.mu_path == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
    assert answer.q is not None and expected.q is not None
    np.testing.assert_allclose(answer.q, expected.q, atol=1e-9)
    cells = placement.as_row()[None]
    kernel = evaluate_placements(robot, prepare_path(robot, path), cells, **options)
    assert kernel.mu_path[0] == pytest.approx(expected.mu_path, rel=MAP_EVALUATE_RTOL)
    return True
