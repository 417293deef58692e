"""The blend stencil (motion.md section 2) against D_i written with np.interp, on random paths."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from solver.path.blend_stencil import BlendStencil
from tests.cases import SECOND_DIFFERENCE_RTOL
from tests.solver.test_acceleration import independent_second_difference


@settings(max_examples=200, deadline=None)
@given(
    n=st.integers(2, 40),
    cut=st.integers(0, 40),
    log_b=st.floats(-4, -1),
    seed=st.integers(0, 2**32 - 1),
)
def test_stencil_is_the_second_difference(n: int, cut: int, log_b: float, seed: int) -> None:
    """Random polylines of uneven steps, one or two passes, any blend length."""
    rng = np.random.default_rng(seed)
    steps = rng.uniform(1e-4, 1e-2, size=(n - 1, 1)) * rng.normal(size=(n - 1, 3))
    positions = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    q = rng.normal(size=(n, 4))
    passes = [(0, n)] if not 2 <= cut <= n - 2 else [(0, cut), (cut, n)]
    segment_in_pass = np.ones(n - 1, dtype=bool)
    if len(passes) == 2:
        segment_in_pass[cut - 1] = False
    b = 10.0**log_b
    stencil = BlendStencil.of_path(positions, segment_in_pass, b)
    expected = independent_second_difference(q, positions, passes, b)
    constrained = np.flatnonzero(~np.isnan(expected[:, 0]))
    np.testing.assert_array_equal(np.sort(stencil.waypoints), constrained)
    if not constrained.size:
        return
    got = stencil.second_difference(q.T).T  # (K, 4)
    order = np.argsort(stencil.waypoints)
    scale = np.abs(expected[constrained]).max()
    np.testing.assert_allclose(
        got[order],
        expected[constrained],
        rtol=SECOND_DIFFERENCE_RTOL,
        atol=SECOND_DIFFERENCE_RTOL * scale,
    )
    np.testing.assert_allclose(stencil.weight.sum(axis=1), 0.0, atol=1e-9 / b**2)
