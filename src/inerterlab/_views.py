"""Array views without reference counts, for calls through numba first-class functions."""

from __future__ import annotations

from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["borrow"]


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
