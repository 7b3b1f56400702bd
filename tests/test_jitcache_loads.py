"""Cached kernels load without numba's full target refresh (mbdsim._jitcache._fast_cached_loads), only
mbdsim's own kernels take that path, and a failure of the short path falls back to numba's method.
Each check runs in a fresh process: the refresh happens once per process."""
from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mbdsim as mb
from mbdsim import _jitcache

_PENDULUM = """
import sys
import numpy as np
import mbdsim as mb
{before}
m = mb.Model("p", gravity=(0, -9.81, 0))
b = m.add_body("b", 1.0, inertia=(1e-3, 1 / 12, 1 / 12), position=(0.5, 0, 0))
m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
r = mb.simulate(m, 0.5)
from mbdsim.solvers import fastdop
hits = sum(fastdop.run.stats.cache_hits.values())
misses = sum(fastdop.run.stats.cache_misses.values())
print(hits, misses, int("numba.np.linalg" in sys.modules), int("scipy.linalg" in sys.modules))
print(" ".join(repr(float(x)) for x in r.q[-1]))
"""


@pytest.fixture(scope="module", autouse=True)
def _warm_cache():
    """The pendulum's kernels compiled (or loaded) in this process first, so that the fresh processes
    below load them from the disk cache instead of compiling them a second time (cold cache in CI)."""
    m = mb.Model("p", gravity=(0, -9.81, 0))
    b = m.add_body("b", 1.0, inertia=(1e-3, 1 / 12, 1 / 12), position=(0.5, 0, 0))
    m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
    mb.simulate(m, 0.5)


def _run(code: str, cwd=None) -> list[str]:
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                         timeout=900, cwd=cwd)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.split("\n")


def test_short_path_installed():
    from numba.core import caching
    assert _jitcache.FAST_LOADS
    assert getattr(caching.FunctionCache.load_overload, "mbdsim", False)


def test_a_fresh_process_loads_the_kernels_without_the_refresh():
    first = _run(_PENDULUM.format(before=""))        # compiles the kernels if the cache is cold
    second = _run(_PENDULUM.format(before=""))
    hits, misses, linalg, scipy_linalg = map(int, second[0].split())
    assert hits == 1 and misses == 0                 # loaded from the cache ...
    assert linalg == 0                               # ... without the registries (numba.np.linalg among them)
    assert scipy_linalg == 0                         # and a plain pendulum's run needs no scipy.linalg
    q1, q2 = (np.array([float(x) for x in lines[1].split()]) for lines in (first, second))
    assert np.array_equal(q1, q2)
    # the pendulum is still a pendulum: the CM stays 0.5 m from the pivot
    assert abs(np.hypot(q2[0], q2[1]) - 0.5) < 1e-9


def test_a_failing_short_path_falls_back_to_numbas_method():
    before = """
from numba.core import caching
_orig = caching.FunctionCache._load_overload
_failed = []
def _flaky(self, sig, ctx):
    if not _failed:
        _failed.append(1)
        raise RuntimeError("simulated failure of the short path")
    return _orig(self, sig, ctx)
caching.FunctionCache._load_overload = _flaky
"""
    ref = _run(_PENDULUM.format(before=""))
    out = _run(_PENDULUM.format(before=before))
    assert out[1] == ref[1]                          # the same run, all kernels loaded
    assert int(out[0].split()[2]) == 1               # numba's own method (with its refresh) did the reload


def test_other_numba_functions_keep_numbas_method(tmp_path):
    (tmp_path / "userkernel.py").write_text("from numba import njit\n\n@njit(cache=True)\n"
                                            "def twice(x):\n    return 2.0 * x\n")
    code = """
import sys
import mbdsim.solvers.fastdop   # mbdsim's short path installed
import userkernel
print(userkernel.twice(1.5), sum(userkernel.twice.stats.cache_hits.values()), int("numba.np.linalg" in sys.modules))
"""
    _run(code, cwd=tmp_path)                         # compiles and caches the user's function
    value, hits, linalg = _run(code, cwd=tmp_path)[0].split()
    assert float(value) == 3.0 and int(hits) == 1
    assert int(linalg) == 1                          # loaded by numba's method: the refresh ran


def test_entries_load_without_parsing_their_bitcode():
    """An entry loaded from the cache (kind "mbdsim-object", mbdsim._jit) keeps its LLVM bitcode unparsed until
    something links it; linking then gets the module with the entry's functions, and the run is the same."""
    if not _jitcache.LINK_ONLY:
        pytest.skip("MBDSIM_LINK_ONLY=0: numba's own cache format")
    check = textwrap.dedent("""
        lib = fastdop.run.overloads[fastdop.run.signatures[0]].library
        pending = "_mbdsim_bitcode" in lib.__dict__
        mod = lib._get_module_for_linking()
        names = [f.name for f in mod.functions if not f.is_declaration]
        print(int(pending), int(any("run" in n for n in names)), int("_mbdsim_bitcode" in lib.__dict__))
    """)
    code = _PENDULUM + check
    out = subprocess.run([sys.executable, "-c", code.replace("{before}", "")], capture_output=True, text=True,
                         timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    lines = out.stdout.split("\n")
    hits, misses = map(int, lines[0].split()[:2])
    assert hits >= 1 and misses == 0
    assert lines[2].split() == ["1", "1", "0"]


def test_the_lazy_imports_freeze_what_they_built():
    """`mbdsim._load`: the import objects (numba's ~10^5) go to the collector's permanent generation, so
    that later full collections and the interpreter's exit skip them; MBDSIM_GC_FREEZE=0 turns it off;
    objects made after the import are collected as always."""
    code = ("import gc, mbdsim as mb\nmb.simulate\nn = gc.get_freeze_count()\n"
            "class A: pass\na = A(); a.me = a; import weakref; w = weakref.ref(a); del a\ngc.collect()\n"
            "print(n, int(w() is None), int(gc.isenabled()))")
    frozen, collected, enabled = map(int, _run(code)[0].split())
    assert frozen > 20000 and collected == 1 and enabled == 1
    off = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                         env={**__import__("os").environ, "MBDSIM_GC_FREEZE": "0"})
    assert off.stdout.split()[0] == "0", off.stderr[-2000:]
