"""The blend stencil: a path's second difference over the blend length (motion.md section 2).

Joint accelerations at a constant feed v are D_i v^2, D_i the second difference of the joint
path over the blend length b in the tool point's arc length. The stencil that forms D from
five waypoints' q depends on the path only, not on the placement: made once per problem
(:class:`solver.path.problem.PathProblem`), used by the acceleration limit
(:class:`solver.path.limits.JointAccelerationLimit`), the compiled kernels and the NLP's rows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BlendStencil:
    """The second difference over the blend length as weights of waypoints (motion.md s. 2).

    D_i = (q(s_i + b) - 2 q_i + q(s_i - b)) / b^2, q(s) the piecewise-linear interpolation of
    the q_i in the tool point's arc length s within a pass, at every waypoint with s_i - b >= 0
    and s_i + b <= s_end of its pass: a sum of five waypoints' q with fixed weights. The
    indices and weights depend on the path only (not on the placement): made once per problem,
    used by the pipeline and by the NLP's rows.

    Attributes:
        blend_length: b, m, > 0.
        waypoints: shape (K,), the constrained waypoints i.
        index: shape (K, 5), the waypoints whose q make D_i: around s_i - b, i, around s_i + b.
        weight: shape (K, 5), 1/m^2, their weights (each row sums to 0).
    """

    blend_length: float
    waypoints: np.ndarray
    index: np.ndarray
    weight: np.ndarray

    @classmethod
    def of_path(
        cls, tool_position: np.ndarray, segment_in_pass: np.ndarray, blend_length: float
    ) -> BlendStencil:
        """The stencil of a path.

        Args:
            tool_position: shape (N, 3), m, the tool point p_i (in any fixed frame).
            segment_in_pass: shape (N - 1,), False where a rapid joins two passes.
            blend_length: b, m, > 0.
        """
        b = float(blend_length)
        n = len(tool_position)
        length = np.linalg.norm(np.diff(tool_position, axis=0), axis=1)
        starts = np.concatenate([[0], np.flatnonzero(~segment_in_pass) + 1, [n]])
        rows: list[np.ndarray] = []
        weights: list[np.ndarray] = []
        kept: list[np.ndarray] = []
        for start, stop in zip(starts[:-1], starts[1:], strict=True):
            s = np.concatenate([[0.0], np.cumsum(length[start : stop - 1])])
            inside = np.flatnonzero((s - b >= 0.0) & (s + b <= s[-1]))
            if not inside.size or stop - start < 2:
                continue
            below, w_below = _interpolation(s, s[inside] - b)
            above, w_above = _interpolation(s, s[inside] + b)
            rows.append(start + np.column_stack([below, below + 1, inside, above, above + 1]))
            weights.append(
                np.column_stack(
                    [1.0 - w_below, w_below, np.full(len(inside), -2.0), 1.0 - w_above, w_above]
                )
                / b**2
            )
            kept.append(start + inside)
        if not kept:
            return cls(b, np.zeros(0, dtype=np.int64), np.zeros((0, 5), np.int64), np.zeros((0, 5)))
        return cls(b, np.concatenate(kept), np.concatenate(rows), np.concatenate(weights))

    def second_difference(self, q: np.ndarray) -> np.ndarray:
        """D at the constrained waypoints: q (n, ..., W) -> (n, ..., K), rad/m^2.

        Formed as sum_m weight_m (q_m - q_0) (a row's weights sum to 0): the weights' rounding
        then does not multiply the angles' size.
        """
        around = q[..., self.index]  # (n, ..., K, 5)
        second: np.ndarray = np.einsum(
            "...km,km->...k", around[..., 1:] - around[..., :1], self.weight[:, 1:]
        )
        return second


def _interpolation(s: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The segment k of the arc lengths ``s`` (ascending) holding each target, and its weight.

    q(target) = (1 - w) q_k + w q_{k+1}; k is the last waypoint with s_k <= target (the last
    segment at the end), w in [0, 1].
    """
    k = np.clip(np.searchsorted(s, target, side="right") - 1, 0, len(s) - 2)
    span = s[k + 1] - s[k]
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(span > 0.0, (target - s[k]) / span, 1.0)
    return k, np.clip(w, 0.0, 1.0)
