"""Every compiled module's cache is dropped when any source its machine code takes in changes.

numba keys a function's disk cache (``cache=True``) by its own file, but the machine code takes
in the compiled callees of other modules and the module constants compiled code reads. The
kernel groups hash those sources in a marker (solver.core.compiled_cache.drop_stale_caches);
a source left out is an edit that loads old machine code: the upgrade audit of stop 62 changed
``solver.core.codes.TAKES_OVER`` alone and got the old code's map (59 of 126 cells with another
bottleneck waypoint), as none of the markers hashed codes.py.

The sources a compiled module takes in are read here from the files, not from the markers: the
module itself, every solver module it imports, and, through each of those that compiles
functions of its own, what that one imports, and so on. The markers' sources are recorded by
importing every compiled module in a fresh interpreter with drop_stale_caches replaced.
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from pathlib import Path

from tests.cases import ROOT

SOLVER = ROOT / "solver"
_COMPILES = re.compile(r"@njit\b|\bnjit\(")
_NOT_KERNELS = {"compiled_cache.py", "cache_home.py"}  # they name cache=True, compile nothing
_MARKERS = {
    (SOLVER / name).resolve()
    for name in ("core/compiled_cache.py", "kernels/cache.py", "path/cell/kernel_cache.py")
}
"""The markers' own code, which the kernel modules import to check their caches, not to compile."""

RECORD = """
import importlib, json, sys
from pathlib import Path
import solver.core.compiled_cache as compiled_cache
recorded = {}
def record(marker, sources, cached):
    for path in cached:
        recorded.setdefault(str(Path(path).resolve()), set()).update(
            str(Path(source).resolve()) for source in sources
        )
compiled_cache.drop_stale_caches = record
for name in sys.argv[1:]:
    importlib.import_module(name)
print(json.dumps({path: sorted(sources) for path, sources in recorded.items()}))
"""


def _module_file(name: str) -> Path | None:
    base = ROOT.joinpath(*name.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.exists():
            return candidate.resolve()
    return None


def _imports(path: Path) -> set[Path]:
    """The solver modules ``path`` imports (``from solver.x import y``: y's file if a module)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("solver"):
            for alias in node.names:
                file = _module_file(f"{node.module}.{alias.name}") or _module_file(str(node.module))
                found |= {file} if file is not None else set()
        elif isinstance(node, ast.Import):
            for alias in node.names:
                file = _module_file(alias.name) if alias.name.startswith("solver") else None
                found |= {file} if file is not None else set()
    return found


def _compiles(path: Path) -> bool:
    return _COMPILES.search(path.read_text()) is not None


def taken_in(path: Path) -> set[Path]:
    """The files whose source may be in ``path``'s machine code (see the module's docstring)."""
    seen, todo = set(), [path.resolve()]
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        seen.add(module)
        for imported in _imports(module) - _MARKERS:
            if _compiles(imported):
                todo.append(imported)
            else:
                seen.add(imported)
    return {file for file in seen if file.name != "__init__.py"}


def test_every_marker_hashes_every_source_its_kernels_take_in() -> None:
    cached = sorted(
        path.resolve()
        for path in SOLVER.rglob("*.py")
        if "cache=True" in path.read_text()
        and path.name not in _NOT_KERNELS
        and path.resolve() not in _MARKERS
    )
    names = [".".join(path.relative_to(ROOT).with_suffix("").parts) for path in cached]
    done = subprocess.run(
        [sys.executable, "-c", RECORD, *names],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    hashed = {
        Path(path): {Path(s) for s in sources} for path, sources in json.loads(done.stdout).items()
    }
    unguarded = {}
    for path in cached:
        sources = taken_in(path)
        if sources == {path}:  # numba's own key, the file, is all it takes in
            continue
        missing = sources - hashed.get(path, set())
        if missing:
            unguarded[str(path.relative_to(ROOT))] = sorted(
                str(file.relative_to(ROOT)) for file in missing
            )
    assert unguarded == {}
    assert len(cached) > 30  # the compiled modules were found
