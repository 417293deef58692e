"""scripts/run_tests.py's latency run collects only LATENCY_MODULES: they must be every module
that marks a test ``latency``, or a test marked elsewhere would run in neither run."""

from __future__ import annotations

import importlib.util
import re

from tests.cases import ROOT


def _latency_modules() -> tuple[str, ...]:
    spec = importlib.util.spec_from_file_location("run_tests", ROOT / "scripts" / "run_tests.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return tuple(module.LATENCY_MODULES)


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
