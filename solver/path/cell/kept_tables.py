"""Self pairs' tables kept across checkers (:mod:`solver.path.cell.pair_tables`).

A pair's table depends on its two robot parts and the joints between them only, not on the
obstacles or the clearance: a new cell for the same arm (a box moved in the page's editor,
another clearance, another workpiece) reuses the tables made for the last one. They are kept
by their parts' content keys (:class:`solver.path.cell.robot_geometry.RobotGeometry`), the least
recently used dropped first, read-only (threads share them).
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np

Row = tuple[list[int], list[int], list[float], np.ndarray]
"""A pair's table: the q indices of its joints, the grid counts, the weights, coal's distances."""

MAX_KEPT = 64
"""Tables kept (a UR5's five are 0.65 MB)."""

_kept: OrderedDict[tuple[str, str], Row] = OrderedDict()
_lock = threading.Lock()


def kept_row(key: tuple[str, str] | None) -> Row | None:
    """The kept table of ``key``'s parts, if any (it becomes the most recently used)."""
    if key is None:
        return None
    with _lock:
        made = _kept.get(key)
        if made is not None:
            _kept.move_to_end(key)
        return made


def keep_row(key: tuple[str, str] | None, made: Row) -> None:
    """Keep ``made`` under ``key`` (None: not kept); the least recently used over MAX_KEPT go."""
    if key is None:
        return
    made[3].flags.writeable = False
    with _lock:
        _kept[key] = made
        _kept.move_to_end(key)
        while len(_kept) > MAX_KEPT:
            _kept.popitem(last=False)


def forget() -> None:
    """Drop every kept table (tests that count the tables made)."""
    with _lock:
        _kept.clear()
