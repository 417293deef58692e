"""A client generated from the committed spec calls every route through its typed models.

openapi-python-client (a test dependency) writes the client into a temporary folder, from
openapi/openapi.json as a client's author would; it is never committed. Its HTTP client is the
app's TestClient, so no server runs. The one option: PNG answers are read as bytes
(``content_type_overrides``: openapi-python-client knows no image/png).
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import math
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from fastapi.testclient import TestClient

from service.main import app
from tests.cases import EXAMPLES, ROOT

CONFIG = "content_type_overrides:\n  image/png: application/octet-stream\npost_hooks: []\n"


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> ModuleType:
    folder = tmp_path_factory.mktemp("generated")
    (folder / "config.yaml").write_text(CONFIG)
    command = [
        str(Path(sys.executable).with_name("openapi-python-client")),
        "generate",
        "--path",
        str(ROOT / "openapi" / "openapi.json"),
        "--meta",
        "none",
        "--output-path",
        str(folder / "dtf_client"),
        "--config",
        str(folder / "config.yaml"),
    ]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Warning" not in result.stdout, result.stdout
    sys.path.insert(0, str(folder))
    try:
        return importlib.import_module("dtf_client")
    finally:
        sys.path.remove(str(folder))


def _module(package: ModuleType, name: str) -> Any:
    return importlib.import_module(f"{package.__name__}.{name}")


@pytest.fixture(scope="module")
def client(generated: ModuleType) -> Iterator[Any]:
    """The generated client on the app (lifespan run: jobs are worked), raising on any status
    the spec does not declare."""
    with TestClient(app) as test_client:
        yield generated.Client(
            base_url="http://testserver", raise_on_unexpected_status=True
        ).set_httpx_client(test_client)


def _call(package: ModuleType, operation: str, **kwargs: Any) -> Any:
    """Call ``api.<tag>.<operation>`` of the generated client (``sync``: the parsed answer)."""
    tag = next(
        name
        for name in (
            "health",
            "robots",
            "limits",
            "dtf",
            "evaluate",
            "maps",
            "optimize",
            "paths",
            "jobs",
        )
        if importlib.util.find_spec(f"{package.__name__}.api.{name}.{operation}") is not None
    )
    return _module(package, f"api.{tag}.{operation}").sync(**kwargs)


EVALUATE = json.loads((EXAMPLES / "evaluate_request.json").read_text())
GRID = {
    "x": {"min": 0.0, "max": 0.1, "step": 0.1},
    "y": {"min": 0.45, "max": 0.45, "step": 0.1},
    "z": 0.1,
    "yaw": [0.0, 1.0],
}
PNG = b"\x89PNG\r\n\x1a\n"


def test_every_route_through_typed_models(generated: ModuleType, client: Any) -> None:
    models = _module(generated, "models")
    health = _call(generated, "health", client=client)
    assert isinstance(health, models.HealthResponse) and health.status == "ok"
    assert "dtf_jobs" in _call(generated, "metrics", client=client)
    limits = _call(generated, "get_limits", client=client)
    assert isinstance(limits, models.LimitsResponse) and limits.max_path_waypoints == 20_000
    robots = _call(generated, "list_robots", client=client)
    assert isinstance(robots, models.RobotsResponse)
    assert {r.name for r in robots.robots} >= {"ur5", "kuka_kr6_r700_sixx"}

    dtf = _call(
        generated,
        "dtf",
        client=client,
        body=models.DtfRequest.from_dict(
            {"robot": {"model": "ur5e"}, "q": [0.1, -1.2, 1.3, -1.5, -1.4, 0.2], "u_T": [1, 0, 0]}
        ),
    )
    assert isinstance(dtf, models.DtfResponse) and dtf.v_max > 0 and dtf.omega_max == 0

    body = models.EvaluateRequest.from_dict(EVALUATE)
    evaluation = _call(generated, "evaluate", client=client, body=body)
    assert isinstance(evaluation, models.EvaluateResponse)
    assert evaluation.mu_path == pytest.approx(0.293729, abs=1e-6)
    assert evaluation.reason is None or isinstance(evaluation.reason, models.FailureReason)
    assert evaluation.spin_mode == models.SpinMode.FIXED
    picture = _call(generated, "evaluate_png", client=client, body=body)
    assert picture.payload.read().startswith(PNG)

    map_body = models.MapRequest.from_dict(
        {"robot": EVALUATE["robot"], "path": EVALUATE["path"], "grid": GRID}
    )
    cmap = _call(generated, "map_", client=client, body=map_body)
    assert isinstance(cmap, models.MapResponse) and len(cmap.cells) == 4
    picture = _call(generated, "map_png", client=client, body=map_body)
    assert picture.payload.read().startswith(PNG)

    optimum = _call(
        generated,
        "optimize",
        client=client,
        body=models.OptimizeRequest.from_dict(
            {
                "robot": EVALUATE["robot"],
                "path": EVALUATE["path"],
                "bounds": {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3]},
                "z": 0.1,
            }
        ),
    )
    assert isinstance(optimum, models.OptimizeResponse) and optimum.found
    assert optimum.mu_path >= optimum.start.mu_path
    assert math.isfinite(optimum.solver.seconds)

    program = (EXAMPLES / "cam" / "sweep_mm.cl").read_text()
    read = _call(
        generated,
        "import_path",
        client=client,
        body=models.PathImportRequest.from_dict({"path": {"cl_data": program}}),
    )
    assert isinstance(read, models.PathImportResponse)
    assert read.passes == [[0, 13], [13, 26], [26, 39]] and read.units == "mm"


def _finished(generated: ModuleType, client: Any, job: Any) -> Any:
    """The job, read again through the generated client until it is done or failed (2 min)."""
    models = _module(generated, "models")
    deadline = time.monotonic() + 120
    while job.status not in (models.JobStatus.DONE, models.JobStatus.FAILED):
        assert time.monotonic() < deadline, job
        time.sleep(0.2)
        job = _call(generated, "get_job", client=client, job_id=job.id)
    return job


def test_jobs_through_typed_models(generated: ModuleType, client: Any) -> None:
    """The 202 is a JobInfo, and a finished job's result the route's own typed answer."""
    models = _module(generated, "models")
    request = {"robot": EVALUATE["robot"], "path": EVALUATE["path"], "grid": GRID}
    job = _call(
        generated,
        "submit_job",
        client=client,
        body=models.MapJob.from_dict({"kind": "map", "request": request}),
    )
    assert isinstance(job, models.JobInfo)
    job = _finished(generated, client, job)
    assert job.status == models.JobStatus.DONE
    assert isinstance(job.result, models.MapResponse) and len(job.result.cells) == 4
    picture = _call(generated, "get_job_png", client=client, job_id=job.id)
    assert picture.payload.read().startswith(PNG)
    listed = _call(generated, "list_jobs", client=client, status=models.JobStatus.DONE)
    assert isinstance(listed, models.JobList) and job.id in [j.id for j in listed.jobs]
    kept = _call(generated, "cancel_job", client=client, job_id=job.id)
    assert isinstance(kept, models.JobInfo) and kept.status == models.JobStatus.DONE
    assert _call(generated, "delete_job", client=client, job_id=job.id) is None
    gone = _call(generated, "get_job", client=client, job_id=job.id)
    assert (
        isinstance(gone, models.ErrorResponse) and gone.detail[0].to_dict()["type"] == "not_found"
    )


@pytest.mark.parametrize(
    ("branch", "kind"),
    [
        ("auto", str),
        ({"shoulder": "left", "elbow": "up", "wrist": "noflip"}, "Branch"),
        ({"solution": 3}, "NumericBranch"),
    ],
)
def test_every_branch_form_is_read_back(generated: ModuleType, branch: Any, kind: Any) -> None:
    """A named branch was read as the const "auto" (listed first in the oneOf) and refused."""
    models = _module(generated, "models")
    policy = models.IkPolicy.from_dict({"branch": branch})
    expected = kind if kind is str else getattr(models, kind)
    assert isinstance(policy.branch, expected)
    assert policy.to_dict()["branch"] == branch


def test_input_errors_arrive_as_typed_error_responses(generated: ModuleType, client: Any) -> None:
    models = _module(generated, "models")
    request = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    request["placement"]["y"] = 4500.0  # millimetres by mistake
    for operation in ("evaluate", "evaluate_png"):
        answer = _call(
            generated, operation, client=client, body=models.EvaluateRequest.from_dict(request)
        )
        assert isinstance(answer, models.ErrorResponse)
        assert answer.detail[0].loc[:2] == ["body", "placement"]
    too_many = {**GRID, "yaw": [0.01 * k for k in range(100)]}  # panels over DTF_MAX_PNG_PANELS
    body = {"robot": EVALUATE["robot"], "path": EVALUATE["path"], "grid": too_many}
    answer = _call(generated, "map_png", client=client, body=models.MapRequest.from_dict(body))
    assert isinstance(answer, models.ErrorResponse)
    assert answer.detail[0].loc[:2] == ["body", "grid"]


def test_names_read_well(generated: ModuleType) -> None:
    """One class per concept, none named after its position in a union (``...Type0``)."""
    folder = Path(generated.__file__).parent / "models"
    names = sorted(path.stem for path in folder.glob("*.py"))
    assert [name for name in names if re.search(r"type_\d", name)] == []
    assert [name for name in names if "spin_mode" in name] == ["spin_mode"]


def test_fixed_field_names_keep_their_wire_names(generated: ModuleType) -> None:
    """api.md fixes ``min``, ``u_T`` and ``type``; the client spells them ``min_``, ``u_t``,
    ``type_`` and sends the API's names.

    openapi-python-client (0.29) snake-cases every property and suffixes ``_`` to a Python
    keyword or builtin; it has no way to rename one: its config's ``class_overrides`` renames
    classes and modules, ``field_prefix`` applies only to names that are no identifier, and its
    one ``x-`` extension, ``x-enum-varnames``, names enum members. Only a contract change would.
    """
    models = _module(generated, "models")
    axis = models.GridAxis(min_=0.1, max_=0.2, step=0.05)
    assert axis.to_dict() == {"min": 0.1, "max": 0.2, "step": 0.05}
    assert models.GridAxis.from_dict({"min": 0.1, "max": 0.2, "step": 0.05}).min_ == 0.1
    error = models.ErrorDetail.from_dict({"loc": ["body"], "msg": "m", "type": "missing"})
    assert error.type_ == "missing" and error.to_dict()["type"] == "missing"
    request = models.DtfRequest.from_dict({"robot": {"model": "ur5"}, "q": [0.0] * 6})
    assert hasattr(request, "u_t") and not hasattr(request, "u_T")


def test_a_map_job_whose_cells_are_paged_is_read_through_typed_models(
    generated: ModuleType, client: Any, tmp_path: Path
) -> None:
    """Over DTF_JOB_PAGE_CELLS, a map job's result has no ``cells`` (they are read in pages):
    the spec said it was a MapResponse, which requires them."""
    from service.config import Settings
    from tests.service.conftest import served_with

    models = _module(generated, "models")
    request = {"robot": EVALUATE["robot"], "path": EVALUATE["path"], "grid": GRID}
    with served_with(Settings(data_dir=tmp_path, workers=1, job_page_cells=2)):
        job = _call(
            generated,
            "submit_job",
            client=client,
            body=models.MapJob.from_dict({"kind": "map", "request": request}),
        )
        job = _finished(generated, client, job)
    assert job.status == models.JobStatus.DONE
    assert job.result_cells.in_result is False and job.result_cells.total == 4
    assert isinstance(job.result, models.MapResponseWithoutCells)
    assert job.result.feasible_cells == 4 and "cells" not in job.result.to_dict()
