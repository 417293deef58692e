"""Conservative advancement (:func:`solver.path.cell.advance.clear_until`) against a plain scan.

The compiled scan first searches the path's joint travel for the configurations it alone proves
clear, then scans on; its answer must be the plain definition's, written here in numpy: the
last configuration m after i before the first where sum_j w_j |q_mj - q_ij| reaches the slack
(summed in the kernel's order for six joints, three pairs, so that no rounding differs). Paths
that turn back (where travel exceeds displacement and the search stops early), long ones (the
search's exponential steps), and slacks from below zero to beyond the whole path.
"""

from __future__ import annotations

import numpy as np
import pytest

from solver.path.cell.advance import clear_until, travelled


def _plain(q: np.ndarray, weights: np.ndarray, p: int, index: int, slack: float) -> int:
    """The definition: the configuration before the first after ``index`` that moved >= slack."""
    w = weights[p]
    for m in range(index + 1, len(q)):
        d = w * np.abs(q[m] - q[index])
        if len(w) == 6:
            moved = (d[0] + d[1]) + (d[2] + d[3]) + (d[4] + d[5])
        else:
            moved = 0.0
            for term in d:
                moved += term
        if moved >= slack:
            return m - 1
    return len(q) - 1


def _path(rng: np.random.Generator, count: int, n: int, *, turning: bool) -> np.ndarray:
    """A joint path: steady moves, or moves that turn back every few configurations."""
    steps = rng.uniform(-0.02, 0.05, size=(count, n))
    if turning:
        steps *= np.where((np.arange(count) // 7) % 2 == 0, 1.0, -1.0)[:, None]
    return np.cumsum(steps, axis=0)


@pytest.mark.parametrize("n", [6, 7])
@pytest.mark.parametrize("turning", [False, True])
@pytest.mark.parametrize("count", [2, 133, 3000])
def test_the_scan_is_the_plain_definition(n: int, turning: bool, count: int) -> None:
    rng = np.random.default_rng(count * 10 + n + int(turning))
    q = _path(rng, count, n, turning=turning)
    weights = rng.uniform(0.0, 1.2, size=(5, n))
    weights[4] = 0.0  # a pair no joint moves (the shoulder against an upright table)
    travel = travelled(q)
    checked = 0
    for _ in range(120):
        p = int(rng.integers(5))
        index = int(rng.integers(count))
        slack = float(rng.choice([-0.01, 0.0, 1e-12, rng.uniform(0, 0.5), rng.uniform(0, 80)]))
        assert clear_until(q, travel, weights, p, index, slack) == _plain(
            q, weights, p, index, slack
        ), (p, index, slack)
        checked += 1
    assert checked == 120


def test_travel_is_each_joints_running_sum_of_moves() -> None:
    q = np.array([[0.0, 1.0], [0.5, 0.5], [0.25, 1.5], [1.0, 1.5]])
    assert np.array_equal(travelled(q), np.array([[0.0, 0.0], [0.5, 0.5], [0.75, 1.5], [1.5, 1.5]]))


def test_a_slack_exactly_reached_stops_there() -> None:
    """Moved == slack is not clear (the scan's >=): the search must not step over it."""
    q = np.zeros((10, 6))
    q[:, 0] = np.arange(10) * 0.25  # exact binary fractions: no rounding anywhere
    weights = np.zeros((1, 6))
    weights[0, 0] = 1.0
    travel = travelled(q)
    for index in range(10):
        for slack in (0.25, 0.5, 1.0, 2.0):
            assert clear_until(q, travel, weights, 0, index, slack) == _plain(
                q, weights, 0, index, slack
            )
