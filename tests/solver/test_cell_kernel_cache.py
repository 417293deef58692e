"""The cell kernels' disk cache is dropped when any source of the package changes.

numba keys a kernel's cache by its own file; the cell's kernels take callees and constants of
other modules in, so an edit there must drop every cell kernel's cached code (a caller would
otherwise run its old machine code). Checked on a copy of the package's sources, with numba's
cache beside them and in the folder NUMBA_CACHE_DIR names.
"""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import numba
import pytest

from solver.path.cell import kernel_cache


def _cached(cache: Path) -> Path:
    """A cached kernel file of the sweep, as numba names them."""
    cached = cache / "sweep.first_due-120.py311.nbi"
    cached.write_bytes(b"machine code")
    return cached


def test_an_edit_of_any_source_drops_every_kernels_cache(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(numba.config, "CACHE_DIR", "")  # numba caches beside the sources
    for source in Path(kernel_cache.__file__).parent.glob("*.py"):
        shutil.copy(source, tmp_path / source.name)
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    other = cache / "shapes.cpython-311.pyc"  # not a kernel's: kept
    other.write_bytes(b"bytecode")
    first = _cached(cache)
    kernel_cache.drop_stale_cell_kernels(tmp_path)
    assert not first.exists() and other.exists()  # no marker yet: what was cached is unknown
    assert len(list(cache.glob("cell_kernels.sources-*"))) == 1
    kept = _cached(cache)
    kernel_cache.drop_stale_cell_kernels(tmp_path)
    assert kept.exists()  # the same sources: the cache stands
    with (tmp_path / "separation.py").open("a") as callee:  # a callee of the sweep's, edited
        callee.write("\n# edited\n")
    kernel_cache.drop_stale_cell_kernels(tmp_path)
    assert not kept.exists()
    assert len(list(cache.glob("cell_kernels.sources-*"))) == 1


def test_the_caches_in_the_folder_numba_cache_dir_names_are_dropped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = tmp_path / "cell"
    package.mkdir()
    for source in Path(kernel_cache.__file__).parent.glob("*.py"):
        shutil.copy(source, package / source.name)
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba"))
    # numba's documented layout under NUMBA_CACHE_DIR: <folder name>_<sha1 of the folder's path>
    cache = tmp_path / "numba" / f"cell_{hashlib.sha1(str(package).encode()).hexdigest()}"
    cache.mkdir(parents=True)
    first = _cached(cache)
    kernel_cache.drop_stale_cell_kernels(package)
    assert not first.exists()
    assert len(list(cache.glob("cell_kernels.sources-*"))) == 1
    assert not (package / "__pycache__").exists()  # nothing written beside the sources
    kept = _cached(cache)
    kernel_cache.drop_stale_cell_kernels(package)
    assert kept.exists()
    with (package / "sweep.py").open("a") as edited:
        edited.write("\n# edited\n")
    kernel_cache.drop_stale_cell_kernels(package)
    assert not kept.exists()
