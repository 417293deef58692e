"""A client generated from the committed spec calls every route through its typed models.

openapi-python-client (a test dependency) writes the client into a temporary folder, from
openapi/openapi.json as a client's author would; it is never committed. Its HTTP client is the
app's TestClient, so no server runs. The one option: PNG answers are read as bytes
(``content_type_overrides``: openapi-python-client knows no image/png).
"""

from __future__ import annotations

import importlib
import json
import math
import subprocess
import sys
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
def client(generated: ModuleType) -> Any:
    return generated.Client(base_url="http://testserver").set_httpx_client(TestClient(app))


def test_every_route_through_typed_models(generated: ModuleType, client: Any) -> None:
    models = _module(generated, "models")
    api = "api"
    health = _module(generated, f"{api}.health.health").sync(client=client)
    assert isinstance(health, models.HealthResponse) and health.status == "ok"
    robots = _module(generated, f"{api}.robots.list_robots").sync(client=client)
    assert isinstance(robots, models.RobotsResponse)
    assert {r.name for r in robots.robots} >= {"ur5", "kuka_kr6_r700_sixx"}

    dtf = _module(generated, f"{api}.dtf.dtf").sync(
        client=client,
        body=models.DtfRequest.from_dict(
            {"robot": {"model": "ur5e"}, "q": [0.1, -1.2, 1.3, -1.5, -1.4, 0.2], "u_T": [1, 0, 0]}
        ),
    )
    assert isinstance(dtf, models.DtfResponse) and dtf.v_max > 0 and dtf.omega_max == 0

    request = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    evaluation = _module(generated, f"{api}.evaluate.evaluate").sync(
        client=client, body=models.EvaluateRequest.from_dict(request)
    )
    assert isinstance(evaluation, models.EvaluateResponse)
    assert evaluation.mu_path == pytest.approx(0.293729, abs=1e-6)
    assert evaluation.reason is None or isinstance(evaluation.reason, models.FailureReason)

    grid = {
        "x": {"min": 0.0, "max": 0.1, "step": 0.1},
        "y": {"min": 0.45, "max": 0.45, "step": 0.1},
        "z": 0.1,
        "yaw": [0.0, 1.0],
    }
    map_body = models.MapRequest.from_dict(
        {"robot": request["robot"], "path": request["path"], "grid": grid}
    )
    cmap = _module(generated, f"{api}.maps.map_").sync(client=client, body=map_body)
    assert isinstance(cmap, models.MapResponse) and len(cmap.cells) == 4
    picture = _module(generated, f"{api}.maps.map_png").sync(client=client, body=map_body)
    assert picture.payload.read().startswith(b"\x89PNG\r\n\x1a\n")

    optimum = _module(generated, f"{api}.optimize.optimize").sync(
        client=client,
        body=models.OptimizeRequest.from_dict(
            {
                "robot": request["robot"],
                "path": request["path"],
                "bounds": {"x": [-0.05, 0.05], "y": [0.4, 0.5], "yaw": [-0.3, 0.3]},
                "z": 0.1,
            }
        ),
    )
    assert isinstance(optimum, models.OptimizeResponse) and optimum.found
    assert optimum.mu_path >= optimum.start.mu_path
    assert math.isfinite(optimum.solver.seconds)

    program = (EXAMPLES / "cam" / "sweep_mm.cl").read_text()
    read = _module(generated, f"{api}.paths.import_path").sync(
        client=client, body=models.PathImportRequest.from_dict({"path": {"cl_data": program}})
    )
    assert isinstance(read, models.PathImportResponse)
    assert read.passes == [[0, 13], [13, 26], [26, 39]] and read.units == "mm"


def test_input_errors_arrive_as_typed_error_responses(generated: ModuleType, client: Any) -> None:
    models = _module(generated, "models")
    request = json.loads((EXAMPLES / "evaluate_request.json").read_text())
    request["placement"]["y"] = 4500.0  # millimetres by mistake
    answer = _module(generated, "api.evaluate.evaluate").sync(
        client=client, body=models.EvaluateRequest.from_dict(request)
    )
    assert isinstance(answer, models.ErrorResponse)
    assert answer.detail[0].loc[:2] == ["body", "placement"]
