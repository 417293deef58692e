"""Can a path run at a programmed feed? (cam.md section 7, the ERK 2021 figs. 3-4 check).

At a feed F the joint speeds at waypoint i are those at V_max_i scaled by F / V_max_i: the DTF's
joint speeds are per unit of tool speed (and, in free spin mode, the spin rate scales with
them), so each joint's use of its limit scales the same way, and the largest use along the path
is F / mu_path, at the bottleneck. With joint acceleration limits the path runs at F when
mu_acc >= F (motion.md section 2): the feasibility and the margin are against mu_acc.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.core.exceptions import InvalidInputError
from solver.path.evaluate import PathEvaluation


@dataclass(frozen=True)
class FeedCheck:
    """The path at feed F.

    Attributes:
        feed: F (m/s).
        feasible: whether the path runs at F with every joint within its limit (mu_path >= F;
            mu_acc >= F with acceleration limits).
        margin: mu_path / F, or mu_acc / F (> 1: room to spare); ``None`` when infeasible.
        qdot_at_feed: shape (N, n), rad/s, the joint speeds at F; ``None`` when infeasible. NaN
            rows where the tool only turns (V_max = 0: no feed there).
        use: shape (N, n), |qdot_at_feed| / qdot_max, dimensionless (1: on the limit).
        acceleration_use: shape (N, n), with acceleration limits |D_i| F^2 / qddot_max at a
            constant feed F (motion.md section 2; NaN within the blend length of a pass end);
            ``None`` without them or when infeasible.
    """

    feed: float
    feasible: bool
    margin: float | None
    qdot_at_feed: np.ndarray | None
    use: np.ndarray | None
    acceleration_use: np.ndarray | None = None


def check_feed(
    evaluation: PathEvaluation,
    feed: float,
    qdot_max: np.ndarray,
    *,
    qddot_max: np.ndarray | None = None,
) -> FeedCheck:
    """The joint speeds and limit use of an evaluated path at feed ``feed``.

    Args:
        evaluation: from :func:`solver.path.evaluate.evaluate_path`.
        feed: F, m/s, finite and > 0.
        qdot_max: shape (n,), rad/s, the joint speed limits the evaluation used.
        qddot_max: shape (n,), rad/s^2, its acceleration limits (None: none).

    Raises:
        InvalidInputError: on ``feed``, not finite or not > 0.
    """
    if not (math.isfinite(feed) and feed > 0.0):
        raise InvalidInputError("feed", f"{feed:.6g} m/s must be finite and > 0")
    ev = evaluation
    if ev.mu_path is None or ev.qdot is None or ev.v_max is None:
        return FeedCheck(feed, False, None, None, None)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(ev.v_max > 0.0, feed / ev.v_max, np.nan)
    qdot_at_feed = ev.qdot * scale[:, None]
    index = ev.mu_path if ev.acceleration is None else ev.acceleration.mu_acc
    acceleration_use = None
    acc = ev.acceleration
    if acc is not None and qddot_max is not None and acc.mu_acc > 0.0:
        acceleration_use = np.abs(acc.qdd) * (feed / acc.mu_acc) ** 2 / qddot_max
    return FeedCheck(
        feed=feed,
        feasible=index >= feed,
        margin=index / feed,
        qdot_at_feed=qdot_at_feed,
        use=np.abs(qdot_at_feed) / qdot_max,
        acceleration_use=acceleration_use,
    )
