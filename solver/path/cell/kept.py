"""Things made once and shared across threads, a bounded number, the least recently used out.

The cell's checkers (:mod:`solver.path.cell.cache`), the self pairs' tables
(:mod:`solver.path.cell.kept_tables`) and the arms' URDF hulls
(:mod:`solver.path.cell.robot_geometry`) are each kept in one.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Generic, TypeVar

K = TypeVar("K")
V = TypeVar("V")


class Kept(Generic[K, V]):
    """At most ``size`` values by key; reading or keeping one makes it the most recently used."""

    def __init__(self, size: int) -> None:
        """An empty store of at most ``size`` values."""
        self.size = size
        self._values: OrderedDict[K, V] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: K) -> V | None:
        """The value kept under ``key``, or None."""
        with self._lock:
            value = self._values.get(key)
            if value is not None:
                self._values.move_to_end(key)
            return value

    def keep(self, key: K, value: V) -> None:
        """Keep ``value`` under ``key``; the least recently used beyond ``size`` go."""
        with self._lock:
            self._values[key] = value
            self._values.move_to_end(key)
            while len(self._values) > self.size:
                self._values.popitem(last=False)

    def clear(self) -> None:
        """Drop every value."""
        with self._lock:
            self._values.clear()
