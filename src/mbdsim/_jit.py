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

Link-only kernels (issue 32). numba finalises every compiled function on its own: it links the modules of
everything the function calls into the function's module, runs LLVM's full module optimisation over the
lot and generates its machine code (kept in the cache). A wrapperless kernel is never run on its own:
its callers link its module and optimise and generate code for it again, with theirs. So every kernel
paid the optimisation and code generation of its whole call tree, once per level of the tree: most of a
cold compile. `_link_only` finalises the wrapperless kernels (mbdsim's functions compiled without the
CPython wrapper) link-only: their callees' modules linked in, each function already optimised on its own
(numba's function passes, run as every module is added), no module optimisation and no machine code;
their cache entries hold that module (kind "mbdsim-link-only"), which is all a caller needs. The entries
(`entry`, and the Python-callable twins) are finalised by numba as before: LLVM optimises their whole
call tree once, as it did at the top level before, so the machine code of a run is the same optimisation
of the same functions. Relies on `CPUContext.get_executable`, `CPUCodeLibrary`'s `_linking_libraries`,
`_get_module_for_linking`, `serialize_using_object_code` and `_unserialize`; MBDSIM_LINK_ONLY=0 or a numba
without them keeps numba's finalisation (the cache directory's key records which, `_jitcache`).
"""
from __future__ import annotations

from numba import njit
from numba.core import caching
from numba.core.registry import CPUDispatcher

from ._jitcache import ENTRY_FLAGS, KERNEL_FLAGS, LINK_ONLY   # (numba's cache directory and locator set on import)

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
        # numba's dispatch calls what this returns with the arguments: the twin itself, whose own dispatch
        # (in C) finds its compiled entry (compiling it the first time). The twin's _compile_for_args
        # would type and look up every argument in Python at every call (~0.15 ms a call)
        return self.python_twin()


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


def _link_only() -> bool:
    """Install the link-only finalisation of the wrapperless kernels (module docstring, "Link-only");
    False (numba's own finalisation kept) when disabled or when this numba lacks the internals used."""
    if not LINK_ONLY:
        return False
    try:
        from llvmlite import binding as ll
        from numba import _dynfunc
        from numba.core.codegen import CPUCodeLibrary, JITCPUCodegen
        from numba.core.cpu import CPUContext
        CPUCodeLibrary._finalize_dynamic_globals, CPUCodeLibrary._get_module_for_linking   # noqa: B018
    except (ImportError, AttributeError):
        return False
    if getattr(CPUContext.get_executable, "mbdsim", False):
        return True
    get_executable = CPUContext.get_executable
    serialize = CPUCodeLibrary.serialize_using_object_code
    unserialize = CPUCodeLibrary._unserialize.__func__

    def wrapperless(library, fndesc) -> bool:
        """An mbdsim kernel compiled without the CPython wrapper (no entry point to generate)."""
        if not (fndesc.modname or "").startswith("mbdsim.") or getattr(library, "_finalized", True):
            return False
        names = {f.name for f in library._final_module.functions if not f.is_declaration}
        return fndesc.llvm_func_name in names and fndesc.llvm_cpython_wrapper_name not in names

    def finalize_link_only(library):
        """numba's finalize without its module optimisation and machine code: the callee modules linked
        in (so that a caller links this module alone), nothing added to the JIT engine."""
        seen = set()
        for lib in library._linking_libraries:
            if lib not in seen:
                library._reload_init.update(lib._reload_init)
                seen.add(lib)
                library._final_module.link_in(lib._get_module_for_linking(), preserve=True)
        library._finalize_dynamic_globals()
        library._finalized = True
        library.mbdsim_link_only = True

    def patched_get_executable(self, library, fndesc, env):
        if getattr(library, "mbdsim_link_only", False) or wrapperless(library, fndesc):
            if not library._finalized:
                finalize_link_only(library)
            return _dynfunc.make_function(fndesc.lookup_module(), fndesc.qualname.split(".")[-1],
                                          f"compiled wrapperless kernel {fndesc.qualname!r}", 0, env, (library,))
        return get_executable(self, library, fndesc, env)

    def patched_serialize(self):
        if getattr(self, "mbdsim_link_only", False):
            return (self.name, "mbdsim-link-only", self._get_module_for_linking().as_bitcode())
        if _SAVING_MBDSIM[0]:   # an entry of mbdsim's: numba's object format, plus the defined symbols' names
            self._ensure_finalized()
            mod = self._get_module_for_linking()
            names = tuple(g.name for gs in (mod.functions, mod.global_variables) for g in gs if not g.is_declaration)
            return (self.name, "mbdsim-object", (self._get_compiled_object(), mod.as_bitcode(), names))
        return serialize(self)

    def patched_unserialize(cls, codegen, state):
        name, kind, data = state
        if kind == "mbdsim-object":
            object_code, bitcode, names = data
            library = codegen.create_library(name)
            library.__class__ = _lazy_class(type(library))
            library.enable_object_caching()
            library._set_compiled_object(object_code)
            library.__dict__["_mbdsim_bitcode"] = bitcode
            library._finalize_final_module()
            library._codegen._engine._defined_symbols |= set(names)
            return library
        if kind != "mbdsim-link-only":
            return unserialize(cls, codegen, state)
        library = codegen.create_library(name)
        library._final_module = library._shared_module = ll.parse_bitcode(data)
        library._finalized = True
        library.mbdsim_link_only = True
        return library

    set_env = JITCPUCodegen.set_env

    def patched_set_env(self, env_name, env):
        """numba's set_env, skipped for an environment that no module in the JIT engine defines (that of a
        link-only kernel loaded from the cache: its callers' code holds its own copy)."""
        if self._engine.get_global_value_address(env_name):
            set_env(self, env_name, env)

    patched_get_executable.mbdsim = True
    JITCPUCodegen.set_env = patched_set_env
    CPUContext.get_executable = patched_get_executable
    CPUCodeLibrary.serialize_using_object_code = patched_serialize
    CPUCodeLibrary._unserialize = classmethod(patched_unserialize)
    return True


# Loading an entry from the cache (issue 32, "every later process quick"). numba's object format stores the
# machine code and the LLVM bitcode of the module (for linking into later compilations) and parses the bitcode
# on every load, to list the symbols the module defines: ~0.09 s of a fresh process's first simulate for the
# README pendulum's four entries. mbdsim's entries are saved as "mbdsim-object" (the same two plus the defined
# symbols' names) and loaded without parsing: the bitcode is parsed only if something links it
# (`_lazy_class`). Saving is told apart by `_SAVING_MBDSIM`, set while numba saves a function of mbdsim's
# (`_jitcache`'s save hook), so a user's own numba functions keep numba's format.
_SAVING_MBDSIM = [False]
_LAZY: dict = {}


def _lazy_class(base):
    """`base` (numba's CPUCodeLibrary class) with its shared module parsed from the kept bitcode on first use."""
    cls = _LAZY.get(base)
    if cls is None:
        from llvmlite import binding as ll

        def get(self):
            d = self.__dict__
            if d.get("_mbdsim_shared") is None and d.get("_mbdsim_bitcode") is not None:
                d["_mbdsim_shared"] = ll.parse_bitcode(d.pop("_mbdsim_bitcode"))
            return d.get("_mbdsim_shared")

        def put(self, mod):
            self.__dict__["_mbdsim_shared"] = mod
            self.__dict__.pop("_mbdsim_bitcode", None)

        cls = _LAZY[base] = type(base.__name__, (base,), {"_shared_module": property(get, put),
                                                           "__module__": base.__module__})
    return cls


def _saving_hook() -> None:
    """Mark numba's saves of mbdsim's functions (see `_SAVING_MBDSIM`)."""
    save = caching.Cache.save_overload
    if getattr(save, "mbdsim", False):
        return

    def save_overload(self, sig, data):
        module = getattr(getattr(self, "_py_func", None), "__module__", None) or ""
        _SAVING_MBDSIM[0] = module.startswith("mbdsim.")
        try:
            return save(self, sig, data)
        finally:
            _SAVING_MBDSIM[0] = False

    save_overload.mbdsim = True
    caching.Cache.save_overload = save_overload


LINKED_ONLY = _link_only()
if LINKED_ONLY:
    _saving_hook()

from . import _compilenote  # noqa: E402 - after the decorators: the note on long compilations (issue 32)

_compilenote.install()
