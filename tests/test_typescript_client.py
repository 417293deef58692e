"""TypeScript types generated from the committed spec accept every request example (issue 26).

openapi-typescript writes the types of ``openapi/openapi.json`` as a TypeScript client's author
would (its default options); every example of every schema a request body reaches, and every
request body in ``examples/``, is then typed with its schema and compiled by ``tsc --strict``.
A field the service defaults must be optional there, or a request that leaves it out does not
compile.

Both tools come from the npm registry, at pinned versions, into a cache folder
(``DTF_NPM_CACHE``, default ``~/.cache/dtf-place/npm``) on the first run; node and npm must be
on the PATH (Node 20 or later). Nothing is skipped: without them the test fails and says so.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from service.spec import request_components
from tests.cases import EXAMPLES, ROOT

TOOLS = {"openapi-typescript": "7.13.0", "typescript": "5.9.3"}
CACHE = Path(os.environ.get("DTF_NPM_CACHE", Path.home() / ".cache" / "dtf-place" / "npm"))
REQUEST_FILES = {  # examples/ files that are request bodies, and their schemas
    "evaluate_request.json": "EvaluateRequest",
}


def _npm_tools() -> Path:
    """The folder whose node_modules/.bin holds openapi-typescript and tsc (installed once)."""
    npm = shutil.which("npm")
    assert npm is not None and shutil.which("node"), "node and npm are needed (Node 20 or later)"
    folder = CACHE / "-".join(f"{name}@{version}" for name, version in TOOLS.items())
    if not (folder / "node_modules" / ".bin" / "tsc").exists():
        folder.mkdir(parents=True, exist_ok=True)
        command = [npm, "install", "--prefix", str(folder), "--no-audit", "--no-fund"]
        command += [f"{name}@{version}" for name, version in TOOLS.items()]
        done = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
        assert done.returncode == 0, done.stdout + done.stderr
    return folder / "node_modules" / ".bin"


def test_request_examples_compile_with_tsc_strict(tmp_path: Path) -> None:
    tools = _npm_tools()
    spec = json.loads((ROOT / "openapi" / "openapi.json").read_text())
    types = tmp_path / "api.d.ts"
    generated = subprocess.run(
        [str(tools / "openapi-typescript"), str(ROOT / "openapi" / "openapi.json"), "-o", types],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert generated.returncode == 0, generated.stdout + generated.stderr
    lines = ['import type { components } from "./api";', ""]
    typed = 0
    for name in sorted(request_components(spec)):
        for k, example in enumerate(spec["components"]["schemas"][name].get("examples", [])):
            lines.append(
                f'export const {name}_{k}: components["schemas"]["{name}"] = {json.dumps(example)};'
            )
            typed += 1
    for file, name in REQUEST_FILES.items():
        body = json.loads((EXAMPLES / file).read_text())
        lines.append(
            f'export const file_{typed}: components["schemas"]["{name}"] = {json.dumps(body)};'
        )
        typed += 1
    assert typed >= 20  # every request component of the spec has an example
    (tmp_path / "examples.ts").write_text("\n".join(lines) + "\n")
    compiled = subprocess.run(
        [str(tools / "tsc"), "--strict", "--noEmit", "--target", "es2020", "examples.ts"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert compiled.returncode == 0, compiled.stdout[:5000] + compiled.stderr[:2000]


@pytest.mark.parametrize("name", ["EvaluateRequest", "MapJob", "Pose"])
def test_request_components_are_found(name: str) -> None:
    spec = json.loads((ROOT / "openapi" / "openapi.json").read_text())
    assert name in request_components(spec)
