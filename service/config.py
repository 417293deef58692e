"""Service settings, read from the environment (prefix ``DTF_``) through :func:`get_settings`."""

from __future__ import annotations

import functools

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    """Settings of the service; each one can be set as ``DTF_<NAME>`` in the environment."""

    model_config = SettingsConfigDict(env_prefix="DTF_")

    max_body_bytes: int = Field(
        default=2_000_000,
        gt=0,
        description="Largest request body accepted (bytes); a larger one is answered 413.",
    )
    max_map_cells: int = Field(
        default=50_000,
        gt=0,
        description="Most placements (x * y * yaw values) one /v1/map request may ask for.",
    )
    max_map_poses: int = Field(
        default=20_000_000,
        gt=0,
        description="Most placement-waypoint pairs one /v1/map request may ask for (each is 8 IK "
        "solutions; about 2 million take a second).",
    )


@functools.cache
def get_settings() -> Settings:
    """The settings, read from the environment on first use and kept."""
    return Settings()
