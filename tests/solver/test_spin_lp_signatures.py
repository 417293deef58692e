"""The spin LP's kernels get one argument type whatever arrays their callers hold.

numba compiles a kernel once per argument type, and a read-only array (a broadcast view, a
robot's frozen limits) is another type than a writable one: ``spin_speeds`` had two compiled
signatures and ``spin_rates_at_feed`` four, each compiled once per installation. Read-only and
writable inputs give the same answers to the bit and leave one signature per kernel.
"""

from __future__ import annotations

import numpy as np

from solver.kernels import spin_lp


def _read_only(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view


def test_read_only_and_writable_inputs_share_one_signature() -> None:
    rng = np.random.default_rng(3)
    a, c, b = (rng.normal(size=(6, 4, 5)) for _ in range(3))
    qdot_max = rng.uniform(1.0, 3.0, 6)
    answers = []
    for view in (_read_only, np.array):  # read-only views first, then writable copies
        speed, limiting = spin_lp.spin_speed(view(a), view(c), view(b), view(qdot_max))
        feed = np.broadcast_to(0.99 * speed, (4, 5))  # near each optimum: rates not 0
        sigma, lam = spin_lp.spin_rate_at_feed(
            view(a), view(c), view(b), view(qdot_max), feed if view is _read_only else feed.copy()
        )
        answers.append((speed, limiting, sigma, lam))
    assert np.isfinite(answers[0][0]).all() and (answers[0][2] != 0).sum() >= 10
    for read_only, writable in zip(*answers, strict=True):
        np.testing.assert_array_equal(read_only, writable)
    assert len(spin_lp.spin_speeds.signatures) == 1
    assert len(spin_lp.spin_rates_at_feed.signatures) == 1
