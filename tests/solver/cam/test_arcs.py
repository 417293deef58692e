"""Arcs of CL data (cam.md section 9): on the circle, within the tolerance, the right way round.

Each circle is placed by geometry here (a centre, a plane, a radius, start and end angles), so
the expected points come from the construction, not from the reader.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solver.cam.arcs import arc_points
from solver.core.exceptions import InvalidLineError

WHERE = {"field": "path.cl_data", "line": 7, "text": "CIRCLE/..."}


def plane(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A random centre (m) and an orthonormal frame e1, e2, axis."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    e1 = np.cross(axis, rng.normal(size=3))
    e1 /= np.linalg.norm(e1)
    return rng.uniform(-0.5, 0.5, size=3), e1, np.cross(axis, e1), axis


def on_circle(centre, e1, e2, radius: float, angle: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    return centre + radius * (math.cos(angle) * e1 + math.sin(angle) * e2)


def angles_of(points: np.ndarray, centre, e1, e2) -> np.ndarray:  # type: ignore[no-untyped-def]
    offsets = points - centre
    return np.unwrap(np.arctan2(offsets @ e2, offsets @ e1))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("tolerance", [1e-5, 1e-6, 2e-4])
def test_points_lie_on_the_circle_and_no_chord_strays_beyond_the_tolerance(
    seed: int, tolerance: float
) -> None:
    centre, e1, e2, axis = plane(seed)
    radius, begin, finish = 0.02 + 0.01 * seed, 0.3 * seed, 0.3 * seed + 2.5
    start, end = on_circle(centre, e1, e2, radius, begin), on_circle(centre, e1, e2, radius, finish)
    points = arc_points(
        start, end, centre, axis, radius=radius, tolerance=tolerance,
        clockwise_about_axis=None, **WHERE,
    )  # fmt: skip
    np.testing.assert_array_equal(points[-1], end)
    np.testing.assert_allclose(np.linalg.norm(points - centre, axis=1), radius, atol=1e-12)
    np.testing.assert_allclose((points - centre) @ axis, 0.0, atol=1e-12)
    chain = np.vstack([start, points])
    sagitta = radius - np.linalg.norm((chain[1:] + chain[:-1]) / 2 - centre, axis=1)
    assert np.max(sagitta) <= tolerance
    assert np.max(sagitta) > tolerance / 4  # not needlessly dense either
    swept = angles_of(chain, centre, e1, e2)
    assert swept[-1] - swept[0] == pytest.approx(2.5, abs=1e-12)  # the shorter way: +2.5 rad


def test_the_shorter_way_may_be_clockwise_about_the_axis() -> None:
    centre, e1, e2, axis = plane(11)
    start, end = on_circle(centre, e1, e2, 0.01, 0.0), on_circle(centre, e1, e2, 0.01, -1.0)
    points = arc_points(
        start, end, centre, axis, radius=None, tolerance=1e-5, clockwise_about_axis=None, **WHERE
    )
    swept = angles_of(np.vstack([start, points]), centre, e1, e2)
    assert swept[-1] == pytest.approx(-1.0, abs=1e-12)
    assert np.all(np.diff(swept) < 0)


@pytest.mark.parametrize(("clockwise", "sweep"), [(True, -(2 * math.pi - 1.0)), (False, 1.0)])
def test_a_stated_sense_may_take_the_long_way(clockwise: bool, sweep: float) -> None:
    centre, e1, e2, axis = plane(3)
    start, end = on_circle(centre, e1, e2, 0.01, 0.0), on_circle(centre, e1, e2, 0.01, 1.0)
    points = arc_points(
        start, end, centre, axis, radius=0.01, tolerance=1e-5,
        clockwise_about_axis=clockwise, **WHERE,
    )  # fmt: skip
    swept = angles_of(np.vstack([start, points]), centre, e1, e2)
    assert swept[-1] == pytest.approx(sweep, abs=1e-12)


@pytest.mark.parametrize("clockwise", [None, False, True])
def test_a_full_circle_is_an_end_equal_to_its_start(clockwise: bool | None) -> None:
    centre, e1, e2, axis = plane(5)
    start = on_circle(centre, e1, e2, 0.03, 0.7)
    points = arc_points(
        start, start.copy(), centre, axis, radius=0.03, tolerance=1e-5,
        clockwise_about_axis=clockwise, **WHERE,
    )  # fmt: skip
    swept = angles_of(np.vstack([start, points]), centre, e1, e2)
    turn = -2 * math.pi if clockwise else 2 * math.pi
    assert swept[-1] - swept[0] == pytest.approx(turn, abs=1e-12)
    np.testing.assert_array_equal(points[-1], start)


def test_a_helix_descends_linearly_and_counts_its_extra_turns() -> None:
    centre, e1, e2, axis = plane(8)
    start = on_circle(centre, e1, e2, 0.005, 0.0) + 0.004 * axis
    end = on_circle(centre, e1, e2, 0.005, -2.0)  # NX: clockwise about the axis, 2 rad
    points = arc_points(
        start, end, centre, axis, radius=0.005, tolerance=1e-5,
        clockwise_about_axis=True, extra_turns=2, **WHERE,
    )  # fmt: skip
    chain = np.vstack([start, points])
    swept = angles_of(chain, centre, e1, e2)
    total = -(2.0 + 4 * math.pi)
    assert swept[-1] == pytest.approx(total, abs=1e-12)
    heights = (chain - centre) @ axis
    np.testing.assert_allclose(heights, 0.004 * (1 - swept / total), atol=1e-15)


@pytest.mark.parametrize(
    ("end_radius", "stated", "words"),
    [(0.0101, None, "agree"), (0.01, 0.011, "stated radius")],
)
def test_radii_that_disagree_are_refused_with_the_line(
    end_radius: float, stated: float | None, words: str
) -> None:
    centre, e1, e2, axis = plane(2)
    start, end = on_circle(centre, e1, e2, 0.01, 0.0), on_circle(centre, e1, e2, end_radius, 1.0)
    with pytest.raises(InvalidLineError, match=words) as caught:
        arc_points(
            start, end, centre, axis, radius=stated, tolerance=1e-5,
            clockwise_about_axis=None, **WHERE,
        )  # fmt: skip
    assert caught.value.line == 7


def test_rounded_radii_within_the_mismatch_are_read() -> None:
    centre, e1, e2, axis = plane(4)
    start, end = on_circle(centre, e1, e2, 0.01, 0.0), on_circle(centre, e1, e2, 0.010005, 1.0)
    points = arc_points(
        start, end, centre, axis, radius=0.01, tolerance=1e-6, clockwise_about_axis=None, **WHERE
    )
    np.testing.assert_array_equal(points[-1], end)
    radii = np.linalg.norm(points - centre, axis=1)
    assert np.all(np.diff(radii) > 0)  # the radius changes steadily from start to end
