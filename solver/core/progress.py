"""Progress reports of long work, and how a caller stops it.

Long solver calls (maps, the placement engine, the optimisers) take ``progress``, a callable
given the fraction done in (0, 1]. It is called often (after each chunk of placements, each
generation, each IPOPT iteration), so a caller that wants the work to stop (its client gone, the
service shutting down, a job cancelled) raises :class:`Cancelled` from it; the work unwinds and
the exception reaches the caller.
"""

from __future__ import annotations

from collections.abc import Callable

Progress = Callable[[float], None]
"""Called with the fraction of the work done, in (0, 1]; may raise :class:`Cancelled`."""


class Cancelled(Exception):  # noqa: N818 - the name says what happened, as asyncio's does
    """The caller's progress callback stopped the work."""


def span(progress: Progress | None, low: float, high: float) -> Progress | None:
    """The progress callback of one part of the work, the fractions ``low`` to ``high`` of it."""
    if progress is None:
        return None
    outer = progress

    def report(fraction: float) -> None:
        outer(low + (high - low) * min(max(fraction, 0.0), 1.0))

    return report
