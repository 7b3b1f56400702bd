"""Where numba keeps mbdsim's compiled kernels: one directory per version of the kernel sources.

numba's on-disk cache checks only the source file of each function, not the functions it calls in
other modules, so after an edit or an upgrade a cached kernel could keep a stale copy of a callee.
Keying the cache directory on a hash of every kernel module makes any change start a fresh cache.
Imported (by `mbdsim.system`) before any kernel module is compiled or loaded. A user-set
NUMBA_CACHE_DIR is respected (the hash is appended below it).

The cache does not depend on where mbdsim is installed: numba files each module's kernels under a
hash of the source directory's absolute path, so a second clone, a new virtual environment or a
moved checkout compiled everything again (214 s on a second clone).  `_PackageCacheLocator` files
mbdsim's kernels under their path inside the package instead, and stamps each index with the source
file's content hash instead of numba's (modification time, size), which every clone, copy or install
changes (numba then ignored the whole index and compiled again). numba itself still checks each
function's bytecode hash, its own version and the CPU (its index and data keys), so a changed kernel,
another numba or another machine never loads a stale entry: the cache is keyed on the kernels' content
and the machine, not the path. `mbdsim cache info` / `mbdsim cache clear` (mbdsim._cachedir). A fresh cache directory is first filled from
the compiled kernels shipped with the package (mbdsim._kernelpack: numba's generic CPU).

Loading a cached kernel: numba's `FunctionCache.load_overload` first refreshes the whole CPU target
context (imports and installs every typing and lowering registry, numba.np.linalg's check for scipy's
BLAS included: 0.3-0.8 s in a fresh process), which only a compilation needs: rebuilding a cached
kernel needs the code generator and numba's runtime (NRT), nothing else.  `_fast_cached_loads` makes
the loads of mbdsim's own kernels (functions of mbdsim's modules; any other numba function is loaded
by numba's own method) initialise the runtime only.  A cache miss still compiles through
numba's compiler, which refreshes the context itself; any failure of the short path falls back to
numba's method.
"""
from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

_HERE = Path(__file__).parent
KERNEL_SOURCES = ("system/kernels.py", "system/exprvm.py", "system/_exprvm_ops.py", "system/exprloads_kernel.py",
                  "solvers/kkt_tree.py", "solvers/kkt_square.py", "solvers/fastloads.py", "solvers/fastdyn.py",
                  "solvers/fastdop.py", "solvers/fastdopstep.py", "solvers/fasttree.py", "solvers/minnorm.py", "solvers/fastkin.py",
                  "solvers/pycall.py", "cosim/_stepper.py", "solvers/fastnarrow.py", "solvers/fastcontact.py",
                  "solvers/treecoord.py", "solvers/fastradau.py", "solvers/fastbroad.py", "solvers/fastgjk.py",
                  "solvers/fastmesh.py", "solvers/fasthht.py", "solvers/fastedges.py", "_slots.py",
                  "solvers/loopcoord.py", "solvers/pathcoord.py", "solvers/fastsolve.py",
                  "solvers/fastfriction.py", "solvers/fastridge.py", "solvers/fastmeshpair.py",
                  "solvers/fastswitch.py", "solvers/fastcross.py", "solvers/fastenergy.py",
                  "solvers/fastenergystep.py", "solvers/fastlaw.py", "solvers/faststatic.py")


# numba's flags of mbdsim's two kinds of kernels (mbdsim._jit: @kernel, @entry); numba's index does not record
# them, so they are part of the cache directory's key
KERNEL_FLAGS = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True}
ENTRY_FLAGS = {"no_cfunc_wrapper": True}
# the wrapperless kernels are finalised link-only (mbdsim._jit: no module optimisation or machine code of their
# own; their cache entries hold the module their callers link); MBDSIM_LINK_ONLY=0 restores numba's finalisation
LINK_ONLY = os.environ.get("MBDSIM_LINK_ONLY", "1") != "0"


# the layout of mbdsim's cache entries (mbdsim._jit: "mbdsim-link-only", "mbdsim-object"); a change starts a new
# cache directory
CACHE_FORMAT = 2


def _digest() -> str:
    h = hashlib.sha1(repr((sorted(KERNEL_FLAGS.items()), sorted(ENTRY_FLAGS.items()), LINK_ONLY,
                           CACHE_FORMAT)).encode())
    for rel in KERNEL_SOURCES:
        p = _HERE / rel
        if p.exists():
            h.update(rel.encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:16]


@functools.lru_cache(maxsize=None)
def _file_digest(path: str) -> str:
    return hashlib.sha1(Path(path).read_bytes()).hexdigest()


def base_dir() -> str:
    """The directory holding every kernel version's cache: $NUMBA_CACHE_DIR if set, else
    $XDG_CACHE_HOME/mbdsim/numba (default ~/.cache/mbdsim/numba)."""
    return os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "mbdsim", "numba")


def configure() -> str:
    """Point numba's cache at the directory of this kernel version and, with numba's generic CPU in force,
    unpack the package's compiled kernels there once (mbdsim._kernelpack); returns the directory."""
    import numba
    from . import _kernelpack
    digest = _digest()
    path = os.path.join(base_dir(), digest)
    numba.config.CACHE_DIR = path
    global PORTABLE, UNPACKED
    PORTABLE = _kernelpack.portable_cpu()
    UNPACKED = _kernelpack.install(path, digest) if PORTABLE and not os.environ.get("MBDSIM_NO_PACK") else None
    return path


PORTABLE = False        # numba compiles for its generic CPU (mbdsim._kernelpack.portable_cpu)
UNPACKED = None         # the name of the shipped archive this process unpacked, if it did


def _package_locator() -> bool:
    """Put `_PackageCacheLocator` first in numba's locator list; False when this numba lacks it."""
    try:
        from numba.core import caching
        base = caching.UserProvidedCacheLocator
        impl = caching.CacheImpl
    except (ImportError, AttributeError):
        return False
    if any(getattr(c, "mbdsim", False) for c in impl._locator_classes):
        return True

    class _PackageCacheLocator(base):
        """mbdsim's modules, cached under `CACHE_DIR/<path inside the package>`, whatever the
        checkout's absolute path; any other file falls through to numba's locators."""

        mbdsim = True

        def __init__(self, py_func, py_file):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._cache_path = os.path.join(numba_config().CACHE_DIR, "mbdsim", *_package_parts(py_file))

        def ensure_cache_path(self):
            """numba's check (create the directory, write a temporary file in it), once per directory and
            process: numba makes it for every function (~0.1 s of a fresh process's start for ~240 kernels)."""
            if self._cache_path not in _READY:
                super().ensure_cache_path()
                _READY.add(self._cache_path)

        def get_source_stamp(self):
            """The source file's content hash: numba's (modification time, size) changes with every clone
            or copy of an unchanged file, which made numba ignore the whole index."""
            return _file_digest(self._py_file)

        @classmethod
        def from_function(cls, py_func, py_file):
            if _package_parts(py_file) is None:
                return None
            return super().from_function(py_func, py_file)

    impl._locator_classes.insert(0, _PackageCacheLocator)
    return True


_READY: set = set()   # cache directories checked by this process (_PackageCacheLocator.ensure_cache_path)


@functools.lru_cache(maxsize=None)
def _package_parts(py_file: str) -> tuple | None:
    """The directories from the package's root to `py_file` (a module of mbdsim), else None."""
    try:
        return Path(py_file).resolve().parent.relative_to(_HERE.resolve()).parts
    except (ValueError, OSError):
        return None


def numba_config():
    from numba.core import config
    return config


def _fast_cached_loads() -> bool:
    """Install the short load path for the cached kernels of mbdsim's modules (see the module
    docstring); False (numba's own method kept) when this numba lacks the internals it relies on."""
    try:
        from numba.core import caching
        from numba.core.runtime import nrt
        original = caching.FunctionCache.load_overload
        caching.FunctionCache._load_overload   # noqa: B018 - the internals used below exist
    except (ImportError, AttributeError):
        return False
    if getattr(original, "mbdsim", False):
        return True

    def load_overload(self, sig, target_context):
        module = getattr(getattr(self, "_py_func", None), "__module__", None) or ""
        if not module.startswith("mbdsim."):
            return original(self, sig, target_context)
        try:
            nrt.rtsys.initialize(target_context)
            with self._guard_against_spurious_io_errors():
                return self._load_overload(sig, target_context)
        except Exception:  # noqa: BLE001 - numba's own method decides (and reports) instead
            return original(self, sig, target_context)

    load_overload.mbdsim = True
    load_overload.__doc__ = original.__doc__
    caching.FunctionCache.load_overload = load_overload
    return True


def _cached_nrt() -> bool:
    """Cache numba's runtime module (NRT: its reference counting and allocation helpers), which numba
    compiles with LLVM in every process before the first compiled call (30-40 ms of a fresh process's first
    simulate): the machine code is kept in numba's object format in this kernel version's cache directory,
    keyed on numba's version and the CPU; any failure compiles it as numba does."""
    try:
        import pickle
        from numba.core.runtime import nrtdynmod
        original = nrtdynmod.compile_nrt_functions
        nrtdynmod.create_nrt_module   # noqa: B018 - the internal used below exists
    except (ImportError, AttributeError):
        return False
    if getattr(original, "mbdsim", False):
        return True

    def compile_nrt_functions(ctx):
        codegen = ctx.codegen()
        try:
            import numba
            key = hashlib.sha1(repr((numba.__version__, codegen.magic_tuple())).encode()).hexdigest()[:16]
            path = os.path.join(CACHE_DIR, f"nrt-{key}.pickle")
        except Exception:  # noqa: BLE001
            return original(ctx)
        try:
            with open(path, "rb") as f:
                return codegen.unserialize_library(pickle.load(f))
        except Exception:  # noqa: BLE001 - absent or unreadable: compile it
            pass
        ir_mod, library = nrtdynmod.create_nrt_module(ctx)
        library.enable_object_caching()
        library.add_ir_module(ir_mod)
        library.finalize()
        try:
            os.makedirs(CACHE_DIR, exist_ok=True)
            tmp = f"{path}.{os.getpid()}.tmp"
            with open(tmp, "wb") as f:
                pickle.dump(library.serialize_using_object_code(), f)
            os.replace(tmp, path)
        except Exception:  # noqa: BLE001 - not written: compiled again next time
            pass
        return library

    compile_nrt_functions.mbdsim = True
    nrtdynmod.compile_nrt_functions = compile_nrt_functions
    return True


CACHE_DIR = configure()
PACKAGE_LOCATOR = _package_locator()
FAST_LOADS = _fast_cached_loads()
CACHED_NRT = _cached_nrt()
