"""Dependencies of the routes, as ``Annotated`` aliases."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends

from service.config import Settings, get_settings
from solver.core.robots import Robot
from solver.families import catalogue


async def _settings() -> Settings:
    """The settings, given on the event loop.

    FastAPI runs a plain function dependency in its thread pool: a hop to a worker thread and
    back on every request.
    """
    return get_settings()


SettingsDep = Annotated[Settings, Depends(_settings)]


async def _catalogue() -> dict[str, Robot]:
    """The robot catalogue, on the event loop (read at startup, by the lifespan's warm-up)."""
    return catalogue()


CatalogueDep = Annotated[dict[str, Robot], Depends(_catalogue)]
