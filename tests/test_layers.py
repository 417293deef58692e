"""The house's layers (spec/architecture.md section 1): no import cycle anywhere.

``lint-imports`` (in ``.ci/run``, contracts in pyproject.toml) holds the layers' order; this
test holds what a layers contract does not see: a cycle between two modules of one layer, with
imports made inside functions counted too (grimp reads every import statement).
"""

from __future__ import annotations

import pkgutil
import tomllib

import grimp
import pytest

from tests.cases import ROOT


@pytest.fixture(scope="module")
def graph() -> grimp.ImportGraph:
    return grimp.build_graph("solver", "service")


def test_no_module_imports_back_what_imports_it(graph: grimp.ImportGraph) -> None:
    cycles = []
    for importer in sorted(graph.modules):
        for imported in sorted(graph.find_modules_directly_imported_by(importer)):
            back = graph.find_shortest_chain(importer=imported, imported=importer)
            if back is not None:
                cycles.append((importer, *back))
    assert cycles == []


def test_the_graph_sees_imports_inside_functions(graph: grimp.ImportGraph) -> None:
    # solver.families.catalogue() imports its catalogue modules by name (importlib, not seen);
    # the Dask runner is imported inside a function of the job worker (an optional extra).
    assert "service.jobs.dask_runner" in graph.find_modules_directly_imported_by(
        "service.jobs.worker"
    )


@pytest.mark.parametrize("package", ["solver", "service"])
def test_every_module_of_a_package_is_in_its_layers(package: str) -> None:
    """A module in no layer is one the contract cannot see: 14 of the service's were (the seams
    audit), and the use cases reached fastapi through one (service.work)."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    [contract] = [
        c for c in config["contracts"] if c["type"] == "layers" and c["name"].startswith(package)
    ]
    layered = {name.strip() for layer in contract["layers"] for name in layer.split("|")}
    top = {f"{package}.{m.name}" for m in pkgutil.iter_modules([str(ROOT / package)])}
    assert top - layered == set()
