"""Self pairs' tables kept across checkers (:mod:`solver.path.cell.pair_tables`).

A pair's table depends on its two robot parts and the joints between them only, not on the
obstacles or the clearance: a new cell for the same arm (a box moved in the page's editor,
another clearance, another workpiece) reuses the tables made for the last one. They are kept
by their parts' content keys (:class:`solver.path.cell.robot_geometry.RobotGeometry`), the least
recently used dropped first, read-only (threads share them).
"""

from __future__ import annotations

import numpy as np

from solver.path.cell.kept import Kept

Row = tuple[list[int], list[int], list[float], np.ndarray]
"""A pair's table: the q indices of its joints, the grid counts, the weights, coal's distances."""

MAX_KEPT = 64
"""Tables kept (a UR5's five are 0.65 MB)."""

_kept: Kept[tuple[str, str], Row] = Kept(MAX_KEPT)


def kept_row(key: tuple[str, str] | None) -> Row | None:
    """The kept table of ``key``'s parts, if any (it becomes the most recently used)."""
    return None if key is None else _kept.get(key)


def keep_row(key: tuple[str, str] | None, made: Row) -> None:
    """Keep ``made`` under ``key`` (None: not kept); the least recently used over MAX_KEPT go."""
    if key is None:
        return
    made[3].flags.writeable = False
    _kept.keep(key, made)


def forget() -> None:
    """Drop every kept table (tests that count the tables made)."""
    _kept.clear()
