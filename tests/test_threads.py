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
