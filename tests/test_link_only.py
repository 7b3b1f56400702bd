"""Link-only kernels (mbdsim._jit, issue 32): a wrapperless kernel is finalised without machine code of its
own, its cache entry holds the module its callers link, and a caller compiled later in a fresh process links
it from that cache entry and computes the same as numpy."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import mbdsim

# fastdyn.qdot_into called from Python: its twin (with the CPython wrapper) links the wrapperless qdot_kernel
CHILD = """
import numpy as np
from mbdsim import _jit
from mbdsim._slots import Slots
from mbdsim.solvers import fastdyn
i = lambda *x: np.array([x], np.int64)
cm = Slots((i(0, 1, 2), i(3, 4, 5, 6), i(0, 1, 2), i(3, 4, 5)))   # one body: r, p in q; r', omega in v
e = np.array([0.5, -0.1, 0.7, 0.3])
q, v, qd = np.concatenate([[1.0, 2.0, 3.0], e / np.linalg.norm(e)]), np.array([0.4, -0.2, 0.9, 1.5, -0.7, 2.0]), np.zeros(7)
fastdyn.qdot_into(cm, q, v, qd)
p, w = q[3:], v[3:]
assert np.allclose(qd, np.concatenate([v[:3], [-0.5 * p[1:] @ w], 0.5 * (p[0] * w + np.cross(p[1:], w))]), rtol=0, atol=1e-15)
libs = [cres.library for cres in fastdyn.qdot_kernel.overloads.values()]
print(_jit.LINKED_ONLY, len(libs), all(getattr(lib, "mbdsim_link_only", False) for lib in libs))
"""


def _child(cache: Path) -> list[str]:
    src = Path(mbdsim.__file__).resolve().parent.parent
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_CACHE_DIR=str(cache), MBDSIM_QUIET_COMPILE="1")
    out = subprocess.run([sys.executable, "-X", "faulthandler", "-c", CHILD], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout.split()


def test_link_only_kernel_cached_and_linked_by_a_later_caller(tmp_path):
    assert _child(tmp_path) == ["True", "1", "True"]   # qdot_kernel compiled link-only
    twins = [p for p in tmp_path.rglob("*") if ".python." in p.name]
    assert twins and any(p.suffix == ".nbc" and ".python." not in p.name for p in tmp_path.rglob("*"))
    for p in twins:   # the caller (the twin) compiles again and links qdot_kernel from its link-only cache entry
        p.unlink()
    assert _child(tmp_path) == ["True", "1", "True"]
