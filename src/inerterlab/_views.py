"""Array views without reference counts, for calls through numba first-class functions."""

from __future__ import annotations

from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic

__all__ = ["borrow", "readonly"]


@intrinsic
def borrow(typingctx, arr):
    """A view of ``arr`` that carries no reference count (``arr`` must outlive it).

    A call through a first-class function takes and releases a reference to every array
    argument (two atomic operations each): for a right-hand side called four times per
    Runge-Kutta step with five arrays that was half the time of the step. The kernels
    hand the system's functions such views of their own work arrays instead."""

    def codegen(context, builder, sig, args):
        aty = sig.args[0]
        src = cgutils.create_struct_proxy(aty)(context, builder, value=args[0])
        dst = cgutils.create_struct_proxy(aty)(context, builder)
        dst.meminfo = cgutils.get_null_value(dst.meminfo.type)
        dst.parent = cgutils.get_null_value(dst.parent.type)
        dst.nitems = src.nitems
        dst.itemsize = src.itemsize
        dst.data = src.data
        dst.shape = src.shape
        dst.strides = src.strides
        return dst._getvalue()

    return arr(arr), codegen


@intrinsic
def readonly(typingctx, arr):
    """``arr`` typed as read-only (the same array; only its type changes).

    A compiled function is compiled once per signature, and an array's writability is
    part of it: a caller holding writable tables would compile the core's right-hand
    side (:func:`inerterlab.systems._kernel.evaluate`) a second time, about 20 s of CPU,
    for arithmetic it already has. Passing the tables through this
    keeps one signature."""
    if not isinstance(arr, types.Array):
        return None
    rt = arr.copy(readonly=True)

    def codegen(context, builder, sig, args):
        return impl_ret_borrowed(context, builder, sig.return_type, args[0])

    return rt(arr), codegen
