"""The two decorators of mbdsim's compiled kernels: `kernel` (called from other kernels) and `entry`
(also called from Python).

Why not plain ``numba.njit(cache=True)``: numba compiles, for every function, a CPython wrapper (unboxing
each argument from Python objects) and a C wrapper beside the function itself, even for a function that
only other compiled functions call. The kernels take the compiled model and its work arrays as two
tuples of about a hundred arrays (`system.compiled`), and the wrappers that unbox them are costly: 8-9 s
of LLVM for a kernel that reads one number, against 0.5 s without them. Dropping them from the inner
kernels cut the README example's cold compilation by about a quarter (250 s -> 185 s of CPU, issue 32);
the rest is numba re-optimising every callee inside each caller (bench/RESULTS.md, Start-up).

* ``@kernel(...)``: ``njit(cache=True, ...)`` without either wrapper. Other kernels call it as usual. A
  call from Python (a test, a debugging session) goes to a twin compiled with the CPython wrapper and
  cached beside it under its own file names, so such a call works and never touches the wrapperless code.
* ``@entry(...)``: ``njit(cache=True, ...)`` with the CPython wrapper only (no C wrapper, which nothing
  of mbdsim uses): the kernels that Python calls (the step loop, the output and Python-path kernels).

Both take numba's ``njit`` options (``_nrt``, ``inline``, ``error_model``, ``fastmath``, ...). Which numba
internals this relies on: `Dispatcher.add_overload` and `_compile_for_args`, the flags
``no_cpython_wrapper`` / ``no_cfunc_wrapper`` and `caching.FunctionCache` (present since numba 0.49).
"""
from __future__ import annotations

from numba import njit
from numba.core import caching
from numba.core.registry import CPUDispatcher

from ._jitcache import ENTRY_FLAGS, KERNEL_FLAGS   # (numba's cache directory and locator set on import)

_WRAPPERLESS = KERNEL_FLAGS


class _TwinCache(caching.FunctionCache):
    """The on-disk cache of a kernel's Python-callable twin: the kernel's files with ``.python`` added to
    their names (numba's index does not tell a wrapperless compilation from a wrapped one)."""

    def __init__(self, py_func):
        super().__init__(py_func)
        self._cache_file = caching.IndexDataCacheFile(
            cache_path=self._cache_path, filename_base=self._impl.filename_base + ".python",
            source_stamp=self._impl.locator.get_source_stamp())


class KernelDispatcher(CPUDispatcher):
    """A numba dispatcher whose compilations have no CPython wrapper (see the module docstring): they
    are not entered in the table that Python calls look up, so a Python call always reaches
    `_compile_for_args`, which hands it to the twin (`python_twin`)."""

    _twin = None

    def add_overload(self, cres):
        self.overloads[tuple(cres.signature.args)] = cres

    @property
    def signatures(self) -> list:
        """The argument types compiled for, by kernels or (Python calls) for the twin, each once."""
        sigs = list(self.overloads)
        if self._twin is not None:
            sigs += [s for s in self._twin.signatures if s not in sigs]
        return sigs

    def python_twin(self) -> CPUDispatcher:
        """The same function compiled with the CPython wrapper (cached under its own file names)."""
        if self._twin is None:
            options = {k: v for k, v in self.targetoptions.items() if k not in _WRAPPERLESS}
            twin = CPUDispatcher(self.py_func, locals=self.locals, targetoptions=options)
            try:
                twin._cache = _TwinCache(self.py_func)
            except Exception:  # noqa: BLE001 - a numba without these internals: compiled, not cached
                pass
            self._twin = twin
        return self._twin

    def _compile_for_args(self, *args, **kws):
        return self.python_twin()._compile_for_args(*args, **kws)


def _disabled() -> bool:
    from numba.core import config
    return bool(config.DISABLE_JIT)


def _options(options: dict) -> dict:
    out = {"nopython": True, "cache": True}
    out.update(options)
    return out


def kernel(fn=None, **options):
    """Decorator of a kernel called from other kernels: compiled without wrappers, cached on disk; a
    Python call goes to a wrapped twin (module docstring). ``@kernel`` or ``@kernel(_nrt=False, ...)``
    with numba's ``njit`` options."""
    def wrap(f):
        if _disabled():   # NUMBA_DISABLE_JIT=1: the plain Python function (debugging kernels without compiling)
            return f
        opts = _options(options)
        cache = opts.pop("cache")
        opts.pop("nopython")
        disp = KernelDispatcher(f, targetoptions={"nopython": True, **_WRAPPERLESS, **opts})
        if cache:
            disp.enable_caching()
        return disp
    return wrap if fn is None else wrap(fn)


def entry(fn=None, **options):
    """Decorator of a kernel that Python calls: ``njit(cache=True, no_cfunc_wrapper=True, ...)``.
    ``@entry`` or ``@entry(_nrt=False, ...)`` with numba's ``njit`` options."""
    def wrap(f):
        opts = _options(options)
        opts.pop("nopython")
        return njit(**ENTRY_FLAGS, **opts)(f)
    return wrap if fn is None else wrap(fn)


from . import _compilenote  # noqa: E402 - after the decorators: the note on long compilations (issue 32)

_compilenote.install()
