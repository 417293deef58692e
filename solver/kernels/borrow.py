"""Arrays passed down a compiled kernel's calls without reference counts (no atomic operations).

numba counts the references to an array's memory with atomic increments and decrements, and a
compiled function takes one on each array argument as it starts and gives it back as it ends.
The map kernels call their helpers (following, probing, the pose kernel) several times a
placement with up to 30 arrays each: those atomic operations took a fifth of the fixed-spin map
kernel's time (``perf``, 2026-12-03), and the threads of a map contended for the counts of the
inputs they share. :func:`borrowed_all` gives views of arrays that carry no count (numba skips
the count of an array without one), so the calls below take none. The caller keeps the owners
alive while the views are used: arguments are its caller's, and work arrays are passed to
:func:`keep` at the end.

A function that allocates nothing, nor anything it calls, is compiled without the counting
instead (``_nrt=False``: the acceleration helpers, the numeric families' kernels). The map
kernels' helpers call functions that allocate (the exact position-limit test), which that
flag refuses, so their arguments are borrowed.
"""

from __future__ import annotations

from numba import types
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


def _view(context, builder, array_type, value):  # type: ignore[no-untyped-def]
    """An array struct with ``value``'s data, shape and strides and no reference count."""
    source = make_array(array_type)(context, builder, value=value)
    view = make_array(array_type)(context, builder)
    populate_array(
        view,
        data=source.data,
        shape=source.shape,
        strides=source.strides,
        itemsize=source.itemsize,
        meminfo=None,
    )
    return view._getvalue()


@intrinsic
def borrowed_all(typingctx, arrays):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """The tuple ``arrays`` as views that count no references (its owners must outlive them)."""
    if not isinstance(arrays, types.BaseTuple) or not all(
        isinstance(t, types.Array) for t in arrays.types
    ):
        return None

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        views = [
            _view(context, builder, t, builder.extract_value(args[0], i))  # type: ignore[no-untyped-call]
            for i, t in enumerate(arrays.types)
        ]
        return context.make_tuple(builder, signature.return_type, views)

    return arrays(arrays), codegen


@intrinsic
def keep(typingctx, owner):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """Nothing, but a use of ``owner``: it lives to here, past the uses of its borrowed views."""

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        return context.get_dummy_value()

    return types.none(owner), codegen
