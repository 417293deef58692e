"""An installation upgraded by its code alone, without the package a release added, is told how.

``threadpoolctl`` came with c40be9c; an editable install updated with ``git pull`` and no second
``pip install`` ended its start in a traceback whose last line named only the module (the
upgrade audit of stop 62, F5). The module is hidden here, as a missing install leaves it.
"""

from __future__ import annotations

import subprocess
import sys

from tests.cases import ROOT


def test_a_missing_threadpoolctl_says_to_install_again() -> None:
    script = "import sys; sys.modules['threadpoolctl'] = None\nimport solver.core.blas\n"
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert done.returncode == 1
    assert done.stderr.splitlines()[-1] == (
        "ModuleNotFoundError: threadpoolctl is not installed, and this release needs it "
        "(pyproject.toml): after updating the code, install again: pip install -e ."
    )
