"""``dtf-place`` installed read-only and run by an account whose home cannot be written.

A service account or a locked-down CAM workstation: numba can cache its compiled functions
neither beside their sources nor in ``~/.cache``, and raised at the first decorated function's
import, so every command ended in a 39-line traceback and exit 1, ``--help`` included (stop
61's CLI audit); matplotlib warned twice on stderr and built its font list again at every run.
Here the repository (with the virtual environment inside it, where it is) is mounted read-only
in a mount namespace of the test's own and HOME is a file, so nothing can be written but the
temporary directory (TMPDIR, the test's folder).
"""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from tests.cases import ROOT

PROGRAM = ROOT / "examples" / "cam" / "nx_slot_plate.cls"
READ_ONLY = f"mount --bind -o ro {shlex.quote(str(ROOT))} {shlex.quote(str(ROOT))}"
"""The shell command that mounts the checkout read-only over itself (quoted: a space in its path
split it, and the probe's failure skipped the tests as if the machine could not run them)."""


def _locked_down(args: list[str], temporary: Path) -> subprocess.CompletedProcess[str]:
    """``python -m service.cli ARGS`` with ROOT read-only, HOME unwritable, TMPDIR given."""
    mounted = f'{READ_ONLY} && exec "$@"'
    command = ["unshare", "-m", "--propagation", "private", "sh", "-c", mounted, "sh"]
    command += [sys.executable, "-m", "service.cli", *args]
    keep = {"PATH", "LANG", "LC_ALL"}
    env = {name: value for name, value in os.environ.items() if name in keep}
    env.update({"HOME": "/proc/version", "PYTHONPATH": str(ROOT), "TMPDIR": str(temporary)})
    probe = subprocess.run(
        [
            "unshare",
            "-m",
            "--propagation",
            "private",
            "sh",
            "-c",
            READ_ONLY,
        ],
        capture_output=True,
        check=False,
    )
    if probe.returncode != 0:
        pytest.skip(f"needs a mount namespace (unshare -m, as root): {probe.stderr!r}")
    return subprocess.run(
        command, capture_output=True, text=True, env=env, cwd=temporary, timeout=300, check=False
    )


def test_a_read_only_install_run_without_a_writable_home_answers(tmp_path: Path) -> None:
    result = _locked_down(["import", str(PROGRAM)], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "\nwaypoints: 89 in 2 passes" in result.stdout
    kernels = tmp_path / f"dtf-placement-kernels-{os.getuid()}"
    pictures = tmp_path / f"dtf-placement-matplotlib-{os.getuid()}"
    assert result.stderr.splitlines() == [
        f"note: the compiled kernels are cached in {kernels}: neither the installation's "
        "folders nor this account's home can be written (NUMBA_CACHE_DIR names another folder)",
        f"note: matplotlib's settings and font list are kept in {pictures}: neither the "
        "installation's folders nor this account's home can be written (MPLCONFIGDIR names "
        "another folder)",
    ]
    assert kernels.is_dir() and (kernels.stat().st_mode & 0o777) == 0o700
    again = _locked_down(["import", str(PROGRAM)], tmp_path)  # the same folders, kept
    assert (again.returncode, again.stdout, again.stderr) == (0, result.stdout, result.stderr)


def test_a_cache_folder_of_another_account_is_not_used(tmp_path: Path) -> None:
    """Its cached machine code would be run as this account's: a private folder instead."""
    planted = tmp_path / f"dtf-placement-kernels-{os.getuid()}"
    planted.mkdir(mode=0o777)
    planted.chmod(0o777)  # anyone may write into it
    result = _locked_down(["import", str(PROGRAM)], tmp_path)
    assert result.returncode == 0, result.stderr
    used = result.stderr.splitlines()[0].split(" in ", 1)[1].split(": ", 1)[0]
    assert Path(used).parent == tmp_path and Path(used) != planted
    assert Path(used).name.startswith("dtf-placement-kernels-")
    assert not any(planted.iterdir())
