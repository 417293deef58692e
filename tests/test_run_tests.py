"""scripts/run_tests.py's runs: the latency run collects only LATENCY_MODULES, which must be every
module that marks a test ``latency``, or a test marked elsewhere would run in neither run; and a
run leaves nothing in the temporary directory; the modules given out first exist; the sources'
bytecode is written where imports read it."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path
from types import ModuleType

from tests.cases import ROOT


def _run_tests() -> ModuleType:
    spec = importlib.util.spec_from_file_location("run_tests", ROOT / "scripts" / "run_tests.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _latency_modules() -> tuple[str, ...]:
    return tuple(_run_tests().LATENCY_MODULES)


def _on_two_workers(
    arguments: list[str], environment: dict[str, str]
) -> subprocess.CompletedProcess[str]:
    """A pytest run of ``arguments`` on two workers in a child process, from the checkout."""
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-n", "2", "-p", "no:cacheprovider", *arguments],
        cwd=ROOT,
        env=environment,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_the_latency_run_collects_every_module_that_marks_a_latency_test() -> None:
    # read from the files (a regex), not from pytest's collection: a decorator, a module's
    # pytestmark or a mark in a parametrisation all spell the mark out
    marked = {
        path.relative_to(ROOT).as_posix()
        for path in (ROOT / "tests").rglob("test_*.py")
        if re.search(r"\bmark\.latency\b", path.read_text())
    }
    assert marked, "no test is marked latency: the latency run would collect none"
    assert set(_latency_modules()) == marked


def test_a_run_on_two_workers_leaves_no_jobs_directory_behind(tmp_path: Path) -> None:
    # tests/conftest.py's jobs directory: every run on two workers left one in the temporary
    # directory (made by every process, removed only by the workers, not the one they used)
    environment = {k: v for k, v in os.environ.items() if k != "DTF_DATA_DIR"}
    environment["TMPDIR"] = str(tmp_path)
    test = (
        "tests/test_run_tests.py::"
        + test_the_latency_run_collects_every_module_that_marks_a_latency_test.__name__
    )
    run = _on_two_workers([test], environment)
    assert run.returncode == 0, run.stdout + run.stderr
    assert sorted(p.name for p in tmp_path.glob("dtf-test-jobs-*")) == []


def test_the_modules_given_out_first_are_test_modules_once_each() -> None:
    # tests/conftest.py's FIRST orders the workers' modules by name: a module renamed or moved
    # would silently fall back to collection order
    from tests.conftest import FIRST

    assert len(set(FIRST)) == len(FIRST)
    missing = [module for module in FIRST if not (ROOT / module).is_file()]
    assert not missing, missing
    assert all(Path(module).name.startswith("test_") for module in FIRST)


def test_the_sources_bytecode_is_written_where_imports_look_for_it() -> None:
    # where PYTHONDONTWRITEBYTECODE is set every process the tests start compiled the sources
    # again; the runner writes their bytecode first, where the import system reads it
    runner = _run_tests()
    assert runner.compile_sources()
    sources = [path for name in runner.SOURCES for path in (ROOT / name).rglob("*.py")]
    missing = [
        path.relative_to(ROOT).as_posix()
        for path in sources
        if not Path(importlib.util.cache_from_source(str(path))).is_file()
    ]
    assert sources and not missing, missing


CHILD_TEST = """
import os
from pathlib import Path

import pytest

from service.config import Settings, get_settings


@pytest.mark.parametrize("name", ["one", "two"])
def test_settings(name):
    Path(os.environ["SEEN"], name).write_text(os.environ["DTF_DATA_DIR"])
    assert "DTF_MAX_MAP_CELLS" not in os.environ
    assert get_settings().max_map_cells == Settings.model_fields["max_map_cells"].default
"""
"""A test module run by :func:`test_a_shells_dtf_settings_are_left_out_and_named` in a child."""


def test_a_shells_dtf_settings_are_left_out_and_named(tmp_path: Path) -> None:
    # tests/conftest.py's settle_environment: a shell serving the app has its DTF_ settings
    # in the environment; the tests took them (its job store written, its limits applied)
    store, seen = tmp_path / "store", tmp_path / "seen"
    store.mkdir()
    seen.mkdir()
    (tmp_path / "test_child.py").write_text(CHILD_TEST)
    shell = {name: value for name, value in os.environ.items() if not name.startswith("DTF_")}
    environment = shell | {
        "DTF_DATA_DIR": str(store),
        "DTF_MAX_MAP_CELLS": "100",
        "SEEN": str(seen),
        "TMPDIR": str(tmp_path),
    }
    arguments = ["-p", "tests.conftest", "-c", str(ROOT / "pyproject.toml"), str(tmp_path)]
    run = _on_two_workers(arguments, environment)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "left out (the tests set their own): DTF_DATA_DIR, DTF_MAX_MAP_CELLS" in run.stdout
    directories = {path.read_text() for path in seen.iterdir()}
    assert len(list(seen.iterdir())) == 2 and len(directories) == 1  # both workers, one store
    (directory,) = directories
    assert Path(directory).parent == tmp_path and not Path(directory).exists()
    assert list(store.iterdir()) == []
