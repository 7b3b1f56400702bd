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
