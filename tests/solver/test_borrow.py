"""Borrowed views (solver.kernels.borrow): the owner's data, shape and strides, no count."""

from __future__ import annotations

import numpy as np
from numba import njit

from solver.kernels.borrow import borrowed_all, keep


@njit(cache=False)
def _views(a, b, c):  # type: ignore[no-untyped-def]
    x, y, z = borrowed_all((a, b, c))
    x[0, 1] = -1.0  # written through the view
    y[2] = True
    z[1, 0, 1] = 7
    keep((a, b, c))
    return x, y, z


@njit(cache=False)
def _plain(a):  # type: ignore[no-untyped-def]
    return a[::2]


def test_views_write_to_their_owners_with_their_shapes_and_strides() -> None:
    a = np.arange(12.0).reshape(3, 4)
    b = np.zeros(5, dtype=np.bool_)
    c = np.zeros((2, 3, 4), dtype=np.int64)[:, ::2, :]  # not contiguous: strides kept
    x, y, z = _views(a, b, c)
    assert a[0, 1] == -1.0 and b[2] and c[1, 0, 1] == 7
    for view, owner in ((x, a), (y, b), (z, c)):
        assert view.shape == owner.shape and view.strides == owner.strides
        assert view.dtype == owner.dtype
        assert view.__array_interface__["data"][0] == owner.__array_interface__["data"][0]


def test_a_borrowed_view_holds_no_reference_to_its_owner() -> None:
    """numba gives a view with a count a base that keeps the memory; a borrowed one has none."""
    a = np.arange(6.0)
    assert _plain(a).base is not None  # the ordinary view: counted
    x, _, _ = _views(a.reshape(2, 3), np.zeros(3, dtype=np.bool_), np.zeros((2, 1, 2), np.int64))
    assert x.base is None and not x.flags.owndata
