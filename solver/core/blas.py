"""One BLAS thread for the optimisers, so that an optimum does not depend on the host's cores.

numpy and scipy each bundle an OpenBLAS that runs on as many threads as the machine has cores,
and its sums are ordered by the thread count: scipy's SLSQP took other steps on one thread than
on two (the ERK optimisation by the scipy method: 89 iterations against 94, its answer's last
digits; with acceleration limits the waypoint where they bind moved from 16 to 81; the
determinism audit of stop 59). The same request then answered differently on a one-core host,
or under OPENBLAS_NUM_THREADS=1. :func:`one_blas_thread` sets every loaded BLAS to one thread
(threadpoolctl, which knows the bundled libraries' symbols), process-wide and left so (a limit
restored at the end of one search could undo another's running beside it); the optimisers'
matrices are a few dozen rows, where more threads bought nothing.
"""

from __future__ import annotations

import threading

try:
    from threadpoolctl import ThreadpoolController
except ModuleNotFoundError as missing:  # an installation upgraded by its code alone (README)
    raise ModuleNotFoundError(
        f"{missing.name} is not installed, and this release needs it (pyproject.toml): after "
        "updating the code, install again: pip install -e .",
        name=missing.name,
    ) from missing

_controller: ThreadpoolController | None = None
_lock = threading.Lock()


def one_blas_thread() -> None:
    """Set numpy's and scipy's BLAS (and any other loaded) to one thread, from now on."""
    global _controller
    with _lock:
        if _controller is None:
            import scipy.optimize  # noqa: F401 - scipy's OpenBLAS loaded before it is looked for

            _controller = ThreadpoolController()
        _controller.limit(limits=1, user_api="blas")
