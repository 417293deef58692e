"""Dependencies of the routes, as ``Annotated`` aliases."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends

from service.config import Settings, get_settings
from solver.families import catalogue
from solver.robots import Robot

SettingsDep = Annotated[Settings, Depends(get_settings)]
CatalogueDep = Annotated[dict[str, Robot], Depends(catalogue)]
