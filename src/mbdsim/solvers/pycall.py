"""Calling back into Python from the compiled kernels: `call_address(address, t)`.

A load written as a Python callable (t, state) cannot be compiled, but it need not send the whole run to
the Python path: `solvers.pyloads` wraps the model's callables in one ctypes callback `int64 f(double t)`
and stores its address in the work arrays (`Work.arrays()[48][1][0]`). The kernels' `loads_into` calls
it through this intrinsic (an indirect call: about 1 us plus the Python work), after the frames of the
current state are in the work arrays; the callback writes the generalized loads into the work array
`[48][0]` (six slots per frame) and returns 0, or a non-zero status when the callable failed. Address 0
means no callback (nothing is called). The intrinsic is inlined into its caller, so the cached kernels
keep working: only the address is run-time data.
"""
from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic


@intrinsic
def call_address(typingctx, address, t):
    """int64 status of the C function `int64 f(double t)` at `address` (an int64)."""
    sig = types.int64(types.int64, types.float64)

    def codegen(context, builder, signature, args):
        addr, tt = args
        fnty = ir.FunctionType(ir.IntType(64), [ir.DoubleType()])
        return builder.call(builder.inttoptr(addr, fnty.as_pointer()), [tt])
    return sig, codegen



def _codegen(nargs):
    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.DoubleType(), [ir.DoubleType()] * nargs)
        return builder.call(builder.inttoptr(args[0], fnty.as_pointer()), list(args[1:]))
    return codegen


def _sig(nargs):
    return types.float64(types.int64, *([types.float64] * nargs))


# the user functions of expressions (system.exprvm's USER op, mbdsim.userfunctions): float64 f(float64 x0, ...)
# of 1 to MAX_ARGS arguments at `address` (an int64: a numba.cfunc's address), an indirect call inlined into
# the interpreter (the cached kernels stay valid: only the address is run-time data)
MAX_ARGS = 6


@intrinsic
def call_double_1(typingctx, address, x0):
    """float64 f(x0) of the C function at `address`."""
    return _sig(1), _codegen(1)


@intrinsic
def call_double_2(typingctx, address, x0, x1):
    """float64 f(x0, x1) of the C function at `address`."""
    return _sig(2), _codegen(2)


@intrinsic
def call_double_3(typingctx, address, x0, x1, x2):
    """float64 f(x0, x1, x2) of the C function at `address`."""
    return _sig(3), _codegen(3)


@intrinsic
def call_double_4(typingctx, address, x0, x1, x2, x3):
    """float64 f(x0, ..., x3) of the C function at `address`."""
    return _sig(4), _codegen(4)


@intrinsic
def call_double_5(typingctx, address, x0, x1, x2, x3, x4):
    """float64 f(x0, ..., x4) of the C function at `address`."""
    return _sig(5), _codegen(5)


@intrinsic
def call_double_6(typingctx, address, x0, x1, x2, x3, x4, x5):
    """float64 f(x0, ..., x5) of the C function at `address`."""
    return _sig(6), _codegen(6)
