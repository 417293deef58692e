"""Service settings, read from the environment (prefix ``DTF_``) through :func:`get_settings`."""

from __future__ import annotations

import functools
import importlib.util
import os
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

from pydantic import Field, PrivateAttr, ValidationError, field_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict

MAX_PATH_WAYPOINTS = 20_000
"""The most waypoints any route's schema takes: DTF_MAX_PATH_WAYPOINTS and
DTF_MAX_OPTIMIZE_WAYPOINTS may lower it, and a start that sets either higher stops, naming it
(it was capped without a word)."""
MAX_CELL_OBJECTS = 1_000
"""The most objects a cell's schema takes: DTF_MAX_CELL_OBJECTS may lower it, not raise it."""

_WEB_ORIGIN = re.compile(r"[a-z][a-z0-9+.-]*://([a-z0-9.-]+|\[[0-9a-f:.]+\])(:[0-9]{1,5})?")
"""An origin as a browser's Origin header gives it (RFC 6454): scheme, host, the port if any."""

_ROUTE_LIMIT_NAMES = (
    "DTF_MAX_MAP_CELLS",
    "DTF_MAX_MAP_POSES",
    "DTF_MAX_SEARCH_POSES",
    "; POST /v1/jobs runs bigger maps",
)
"""The synchronous routes' limits as their settings (cells, poses, the scipy search), and the
hint a refusal ends with."""
_JOB_LIMIT_NAMES = ("DTF_MAX_JOB_CELLS", "DTF_MAX_JOB_POSES", "DTF_MAX_JOB_POSES", "")
"""A job's."""


class Settings(BaseSettings):
    """Settings of the service; each one can be set as ``DTF_<NAME>`` in the environment."""

    model_config = SettingsConfigDict(env_prefix="DTF_")

    max_body_bytes: int = Field(
        default=2_000_000,
        gt=0,
        description="Largest request body accepted (bytes); a larger one is answered 413.",
    )
    body_read_seconds: float = Field(
        default=10.0,
        gt=0.0,
        description="Longest wait (s) for a request body to arrive; a body that stops short of "
        "its Content-Length is answered 408 then, and its connection closed.",
    )
    max_map_cells: int = Field(
        default=50_000,
        gt=0,
        description="Most placements (x * y * yaw * spin values) one /v1/map request may ask for.",
    )
    max_map_poses: int = Field(
        default=5_000_000,
        gt=0,
        description="Most placement-waypoint pairs one /v1/map request, or the coarse map of one "
        "/v1/optimize request, may ask for (each is 8 IK solutions; on one thread of the "
        "2-core development machine the default, 5 million, takes about 0.4 s for a UR arm "
        "and 1.4 to 3.6 s for the catalogue's OPW arms in fixed spin by the compiled kernel "
        "(2026-12-04; the speed varies from day to day), and about 3.5 times as long in free "
        "spin, by its own; /v1/map computes on DTF_THREADS threads). A pair of a numeric-IK "
        "arm counts as the work of many (its family's path_cost: about 50 a waypoint for 6 "
        "joints, 200 for 7, plus 800 to 1,000 or 2,600 a placement for the seeds), so its "
        "limit is about 0.5 to 1.2 s; a cell adds 50 a pair for its collision check (more, "
        "in proportion, where it computes more than 250 distances a configuration: robot "
        "part against object or part); joint acceleration limits add 0.5 plus 0.04 a step of "
        "the blend's span in waypoints (2 ik.blend_length over their spacing). "
        "/v1/evaluate weighs its one placement the same way against this limit.",
    )
    max_search_poses: int = Field(
        default=6_100_000,
        gt=0,
        description="Most placement-waypoint pairs, weighed as for DTF_MAX_MAP_POSES, that the "
        "scipy method's search of one /v1/optimize request (DTF_MAX_JOB_POSES in a job) may "
        "evaluate: its differential evolution (61 populations of 20 placements per free "
        "variable, rounded up to a power of two, for a closed-form arm; a costlier IK family "
        "gets a smaller search, down to 11 of 5 per free variable), its refinement, "
        "Nelder-Mead climbs and whole-path checks. The default admits every search of a "
        "closed-form arm over x, y and yaw on a path of 1,000 waypoints (about 5 million: 61 "
        "* 64 * 1000 of them the differential evolution's), and with the spin or z free too "
        "up to about 600 waypoints; a program over 1,000 waypoints is searched on a set of "
        "the waypoints that bind (three evolutions on at most 300, their best placements "
        "checked on the whole path), which admits a closed-form arm over x, y and yaw up to "
        "about 18,000 waypoints; with numeric IK it admits a short path (the Panda on 10 "
        "waypoints: about 20 s) and refuses a search that would take much longer. Where the "
        "search also starts from the coarse map (where the map at most doubles its work), the "
        "work the map adds is weighed against DTF_MAX_MAP_POSES, as the casadi method's map is.",
    )
    max_path_waypoints: int = Field(
        default=20_000,
        gt=0,
        le=MAX_PATH_WAYPOINTS,
        description="Most waypoints a path of /v1/evaluate or /v1/map may have (at most 20,000, "
        "the schemas' bound: a start with more stops, naming it). Validating a body "
        "holds the GIL for about 10 us a waypoint (one pydantic-core call), so a body at this "
        "limit delays other requests once by up to 0.3 s on a 2-core machine; lower it where "
        "that matters.",
    )
    max_optimize_waypoints: int = Field(
        default=20_000,
        gt=0,
        le=MAX_PATH_WAYPOINTS,
        description="Most waypoints a path of /v1/optimize may have (at most 20,000). The local "
        "solves work on the "
        "waypoints that bind (an active set, checked on the whole path), and a program over "
        "2,000 waypoints is mapped on such a set too, so the work grows slowly with the path: "
        "a 10,487-move program on a UR5e takes seconds. The scipy method's differential "
        "evolution of a program over 1,000 waypoints runs on such a set too "
        "(DTF_MAX_SEARCH_POSES bounds it).",
    )
    max_cell_objects: int = Field(
        default=100,
        gt=0,
        le=MAX_CELL_OBJECTS,
        description="Most objects (fixed and workpiece) a request's cell may hold, and most "
        "collision elements a URDF robot checked against a cell may have (at most 1,000, the "
        "schema's bound).",
    )
    max_mesh_triangles: int = Field(
        default=50_000,
        gt=0,
        description="Most triangles one STL mesh of a cell may have.",
    )
    max_detail_waypoints: int = Field(
        default=2_000,
        gt=0,
        description="Up to this many waypoints /v1/evaluate answers every waypoint's detail by "
        "default; beyond it, the summary unless the request asks for detail: waypoints.",
    )
    threads: int = Field(
        default_factory=lambda: os.cpu_count() or 1,
        gt=0,
        description="Threads one /v1/map request computes its placements on (default: the "
        "number of cores).",
    )
    max_urdf_joints: int = Field(
        default=64,
        gt=0,
        description="Most joints (of any type, counted in the document before it is parsed) a "
        "URDF robot may have. An arm with its gripper has about 10 to 20; a 200-joint chain "
        "took 4 to 14 s to read and seed.",
    )
    max_png_panels: int = Field(
        default=24,
        gt=0,
        description="Most panels (yaw x spin values) a PNG map may have.",
    )
    max_solver_seconds: float = Field(
        default=20.0,
        gt=0.0,
        description="Longest time (s) one IPOPT solve of /v1/optimize may take, by the wall "
        "clock; it then stops and its best point so far is judged by the evaluator like any "
        "other. On a machine busy with other work a "
        "solve does fewer iterations in that time, so an answer it stops can depend on the load "
        "(the process's CPU time, IPOPT's other limit, would count every request's work).",
    )
    data_dir: Path = Field(
        default=Path("var"),
        description="Where jobs and their results are kept (an SQLite file), created on first "
        "start; a relative path is taken from the working directory (the start log names the "
        "file).",
    )

    @field_validator("data_dir", mode="before")
    @classmethod
    def _named_directory(cls, value: object) -> object:
        """Refuse an empty path: it meant the working directory (the operator audit, M6)."""
        if isinstance(value, str) and not value.strip():
            raise ValueError("an empty path; name a directory (the default is ./var)")
        return value

    workers: int = Field(
        default_factory=lambda: os.cpu_count() or 1,
        gt=0,
        description="Processes that run jobs (default: the number of cores).",
    )
    dask_scheduler: str | None = Field(
        default=None,
        description="The address of a Dask scheduler (tcp://host:8786) on whose workers the "
        "jobs' placement tasks run; unset, they run in the local worker processes.",
    )

    @field_validator("dask_scheduler")
    @classmethod
    def _scheduler_address(cls, address: str | None) -> str | None:
        """A scheduler's address, ``[scheme://]host:port``, with the dask extra installed.

        A malformed one was taken at startup, and every map job then failed as internal
        ('missing port number in address').
        """
        if address is None:
            return None
        if not _SCHEDULER_ADDRESS.fullmatch(address):
            raise ValueError(
                f"{address[:100]!r} is not a scheduler address: [scheme://]host:port, as "
                "tcp://host1:8786"
            )
        if importlib.util.find_spec("distributed") is None:
            raise ValueError("jobs on a Dask cluster need the dask extra: pip install -e '.[dask]'")
        return address

    cors_origins: Annotated[tuple[str, ...], NoDecode] = Field(
        default=(),
        description="Web origins whose pages may call the API from a browser (CORS): "
        "scheme://host[:port] each, comma-separated, or * for any; none by default (the "
        "service's own page needs none).",
    )

    @field_validator("cors_origins", mode="before")
    @classmethod
    def _listed_origins(cls, value: object) -> object:
        """A comma-separated list, as the environment gives it; empty entries dropped."""
        if isinstance(value, str):
            return tuple(part.strip() for part in value.split(",") if part.strip())
        return value

    @field_validator("cors_origins")
    @classmethod
    def _web_origins(cls, origins: tuple[str, ...]) -> tuple[str, ...]:
        """Each an origin as a browser sends it: a page's URL without its path is refused.

        A browser's Origin header never ends in a slash nor holds a path, so such an entry
        would let no page in, without a word.
        """
        for origin in origins:
            if origin != "*" and not _WEB_ORIGIN.fullmatch(origin):
                raise ValueError(
                    f"{origin[:100]!r} is not a web origin: scheme://host[:port], lower case, "
                    "no path nor trailing slash (or * for any)"
                )
        return origins

    max_queued_jobs: int = Field(
        default=100,
        gt=0,
        description="Most jobs waiting or running at once; one more is answered 429.",
    )
    job_ttl: float = Field(
        default=7 * 24 * 3600.0,
        gt=0.0,
        description="How long a finished job and its result are kept (s); default a week.",
    )
    job_attempts: int = Field(
        default=3,
        gt=0,
        description="Times a job interrupted by a restart, or whose worker process died (killed "
        "for memory, say), is run before it fails.",
    )
    max_job_cells: int = Field(
        default=2_000_000,
        gt=0,
        description="Most placements one map job may ask for (its max_map_cells).",
    )
    job_page_cells: int = Field(
        default=10_000,
        gt=0,
        description="Most cells of a map job's result that GET /v1/jobs/{id} answers in it (a "
        "larger result is answered without its cells, which GET /v1/jobs/{id}/result gives in "
        "pages), and most cells one such page may hold (about 2.2 MB of JSON).",
    )
    max_job_poses: int = Field(
        default=500_000_000,
        gt=0,
        description="Most placement-waypoint pairs one map or optimize job may ask for (its "
        "max_map_poses, and its max_search_poses with method scipy; about 6 minutes on 2 "
        "cores for a UR or OPW arm in fixed spin, by the compiled kernel, on a slow day; free "
        "spin takes about 2.3 times as long). dtf-place's commands take these limits (the "
        "routes' where larger).",
    )

    _limit_names: tuple[str, str, str, str] = PrivateAttr(default=_ROUTE_LIMIT_NAMES)

    def for_jobs(self) -> Settings:
        """These settings with the job limits in place of the synchronous routes' limits."""
        copy = self.model_copy(
            update={
                "max_map_cells": self.max_job_cells,
                "max_map_poses": self.max_job_poses,
                "max_search_poses": self.max_job_poses,
            }
        )
        copy._limit_names = _JOB_LIMIT_NAMES
        return copy

    def for_commands(self) -> Settings:
        """These settings with a dtf-place command's limits: a job's, or a route's if larger.

        A command runs as a job does (on the caller's machine, for the caller alone, with a
        progress bar and Ctrl-C), and may always do what a synchronous request may: each limit
        is the larger of the two, named as its setting.
        """
        cells = max(self.max_map_cells, self.max_job_cells)
        poses = max(self.max_map_poses, self.max_job_poses)
        search = max(self.max_search_poses, self.max_job_poses)
        copy = self.model_copy(
            update={"max_map_cells": cells, "max_map_poses": poses, "max_search_poses": search}
        )
        copy._limit_names = (
            "DTF_MAX_JOB_CELLS" if cells == self.max_job_cells else "DTF_MAX_MAP_CELLS",
            "DTF_MAX_JOB_POSES" if poses == self.max_job_poses else "DTF_MAX_MAP_POSES",
            "DTF_MAX_JOB_POSES" if search == self.max_job_poses else "DTF_MAX_SEARCH_POSES",
            "",
        )
        return copy

    def map_limits(self) -> MapLimits:
        """The map size limits in force, named as their settings (a route's or a job's)."""
        cells, poses, search, hint = self._limit_names
        return MapLimits(
            self.max_map_cells,
            self.max_map_poses,
            cells,
            poses,
            hint,
            self.max_search_poses,
            search,
        )


@dataclass(frozen=True)
class MapLimits:
    """Map size limits: placements and weighed placement-waypoint pairs, with their names.

    Attributes:
        hint: appended to a refusal (a route's points to /v1/jobs; a job's has none).
        search_poses: the weighed pairs of the scipy method's search; search_setting: its name.
    """

    cells: int
    poses: int
    cells_setting: str
    poses_setting: str
    hint: str
    search_poses: int
    search_setting: str


@functools.cache
def get_settings() -> Settings:
    """The settings, read from the environment on first use and kept."""
    return Settings()


def settings_or_exit(status: int | None = None) -> Settings:
    """:func:`get_settings`, or each bad ``DTF_`` variable named on stderr and exit ``status``.

    ``status``: :data:`INVALID_SETTINGS` (3) by default, the service's; the CLI gives its own
    (:data:`service.cli.SETTINGS`), 3 there being an input refused.

    Called where the service starts, before any warm-up: a bad value was refused only after
    it (30 s on a first start), by a traceback through the lifespan that named the field
    (``workers``), not the variable a deployment sets (``DTF_WORKERS``).
    """
    try:
        settings = get_settings()
    except ValidationError as error:
        for item in error.errors():
            name = "DTF_" + "_".join(str(part) for part in item["loc"]).upper()
            value = os.environ.get(name, "")
            message = item["msg"].removeprefix("Value error, ")
            print(f"error: {name}={value[:100]!r}: {message}", file=sys.stderr)  # noqa: T201
        raise SystemExit(INVALID_SETTINGS if status is None else status) from None
    for name in unknown_names(os.environ):
        print(  # noqa: T201
            f"warning: {name} is not a setting (misspelt?): ignored; the settings are in "
            "README (Settings) and service/config.py",
            file=sys.stderr,
        )
    return settings


def unknown_names(environment: Mapping[str, str]) -> list[str]:
    """The ``DTF_`` names in ``environment`` that are no setting, sorted.

    pydantic-settings ignores them: ``DTF_WORKER=2`` (for DTF_WORKERS) ran one worker per
    core without a word (the operator audit of 2026-12-07, M6).
    """
    known = {"DTF_" + name.upper() for name in Settings.model_fields}
    return sorted(name for name in environment if name.startswith("DTF_") and name not in known)


INVALID_SETTINGS = 3
"""The exit status of a service started with a bad ``DTF_`` variable (dtf-place's is 6)."""
_SCHEDULER_ADDRESS = re.compile(
    r"(?:[a-z][a-z0-9+.-]*://)?(?:\[[0-9A-Fa-f:.]+\]|[^:/\s\[\]]+):\d{1,5}"
)
