"""Calling a compiled kernel many times from Python with the same argument types, cheaply.

numba's dispatcher types every argument at every call; for the compiled model's and work arrays' tuples
(about a hundred arrays) that is ~15 us, more than the work of one step of a small model. `Bound` calls
the dispatcher once (loading or compiling the kernel as usual), then the compiled overload's entry point
for those argument types directly (~3x cheaper). The caller must keep the argument types fixed (the
same tuples, float scalars, the same array dtypes); any doubt falls back to the dispatcher.
"""
from __future__ import annotations


class Bound:
    """`Bound(kernel)(*args)`: kernel(*args) through its compiled entry point after the first call."""

    __slots__ = ("kernel", "entry")

    def __init__(self, kernel):
        self.kernel, self.entry = kernel, None

    def __call__(self, *args):
        if self.entry is not None:
            return self.entry(*args)
        out = self.kernel(*args)
        self.entry = _entry(self.kernel, args)
        return out


def _entry(kernel, args):
    """The entry point of `kernel`'s overload for the types of `args` (the kernel itself when unknown).
    A wrapperless kernel (mbdsim._jit.kernel) is entered through its Python-callable twin: its own
    overloads have no CPython wrapper, and calling their entry points from Python crashes."""
    twin = getattr(kernel, "python_twin", None)
    if twin is not None:
        kernel = twin()
    try:
        sigs = kernel.signatures
        if len(sigs) == 1:
            return kernel.overloads[sigs[0]].entry_point
        from numba import typeof
        return kernel.overloads[tuple(typeof(a) for a in args)].entry_point
    except Exception:  # noqa: BLE001 - not a numba dispatcher, or a signature not found: the plain call
        return kernel
