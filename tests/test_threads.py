"""Analyses run with one BLAS thread (small dense matrices; shared cores), restored afterwards."""
import numpy as np
import pytest

import mbdsim as mb

threadpoolctl = pytest.importorskip("threadpoolctl")


def _blas_threads():
    return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]


def test_simulate_runs_single_threaded_blas_and_restores():
    before = _blas_threads()
    seen = []

    def force(t, state):
        seen.append(max(_blas_threads() or [1]))
        return (0.0, 0.0, 0.0)

    m = mb.Model("p", gravity=(0, -9.81, 0))
    b = m.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1), position=(1, 0, 0))
    m.add_revolute("pin", m.ground, b, (0, 0, 0), (0, 0, 1))
    m.add_force("f", b, force)
    res = mb.simulate(m, 0.05, output_step=0.01)
    assert res.success
    assert seen and max(seen) == 1
    assert set(_blas_threads()) == set(before)   # libraries loaded during the run keep their default
    assert np.isfinite(res.q).all()


def test_nested_limits_keep_one_thread_and_restore_at_the_outer_exit():
    from mbdsim import _blas as _threads
    before = _blas_threads()
    with _threads._limit():
        assert max(_blas_threads() or [1]) == 1
        with _threads._limit():                   # an analysis inside a study chunk: no second limit
            assert _threads._held.depth == 1
            assert max(_blas_threads() or [1]) == 1
        assert max(_blas_threads() or [1]) == 1   # the inner exit does not restore
    assert _threads._held.depth == 0
    assert _blas_threads() == before


def test_scipy_blas_loaded_inside_an_analysis_is_limited_there(tmp_path):
    """A fresh process: a model whose assembly needs scipy.linalg (a redundant loop: rank decisions),
    imported inside the analysis' limit; its BLAS runs single-threaded during the run and gets its
    default back afterwards."""
    import subprocess
    import sys
    code = '''
import sys, threadpoolctl
import numpy as np
import mbdsim as mb
from mbdsim._blas import _limit, lazy_import
def blas():
    return {i["filepath"]: i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"}
assert "scipy.linalg" not in sys.modules
with _limit():
    lazy_import("scipy.linalg")
    inside = blas()
after = blas()
print(len(inside), max(inside.values()), len(after) == len(inside))
with _limit():
    again = blas()
print(max(again.values()))
'''
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                         env={**__import__("os").environ, "OPENBLAS_NUM_THREADS": "2"})
    assert out.returncode == 0, out.stderr[-2000:]
    first, second = out.stdout.split("\n")[:2]
    n, most, same = first.split()
    assert int(most) == 1 and same == "True"      # every BLAS (scipy's loaded inside) limited to one
    assert int(second) == 1                        # a later analysis limits it too
