"""Drivers written as Python callables of t (and integrals without a closed form) run inside the compiled
step loop through the driver callback of solvers.pyloads: same motion as the expression driver."""
import warnings

import numpy as np

import mbdsim as mb
from mbdsim.errors import EvaluationError
from mbdsim.solvers import dynamic
from test_driver_integrals import _carousel   # arm turned about z by the motion, pendulum at its tip


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.simulate(model, **{"end_time": 1.5, "output_step": 0.01, **kw})


def test_callable_driver_with_exact_derivatives_matches_the_expression():
    tf = mb.expressions.time_function(lambda t: 3 * t + 2 * np.sin(t), d1=lambda t: 3 + 2 * np.cos(t),
                                      d2=lambda t: -2 * np.sin(t))
    a, b = _run(_carousel(displacement=tf)), _run(_carousel(displacement="3*t + 2*sin(t)"))
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    for j in ("hub", "tip"):
        assert np.max(np.abs(a.joint_coordinate(j) - b.joint_coordinate(j))) < 1e-8, j


def test_plain_callable_driver_runs_compiled():
    """Numerical derivatives (the driver callback's 9-point stencil, solvers.pydrive): the motion to 1e-8."""
    a = _run(_carousel(displacement=lambda t: 3 * t + 2 * np.sin(t)))
    b = _run(_carousel(displacement="3*t + 2*sin(t)"))
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    assert np.max(np.abs(a.joint_coordinate("hub") - b.joint_coordinate("hub"))) < 1e-10
    assert np.max(np.abs(a.joint_coordinate("tip") - b.joint_coordinate("tip"))) < 1e-8


def test_stencil_derivatives_against_closed_forms_and_the_tableau_fallback():
    """solvers.pydrive.triple: d1, d2 of a smooth f to 1e-10 relative; sin(300 t) (too fast for the
    stencil's 0.01 s step: the 4th/8th-order check fails) still to 1e-8 through the Ridders tableau; an f
    that raises beyond 1 s keeps its derivatives at 0.98 s (the tableau's finer steps)."""
    from mbdsim.solvers.pydrive import triple
    tf = mb.expressions.time_function
    cases = [(lambda t: 3 * t + 2 * np.sin(t), lambda t: 3 + 2 * np.cos(t), lambda t: -2 * np.sin(t)),
             (lambda t: np.sin(300 * t), lambda t: 300 * np.cos(300 * t), lambda t: -9e4 * np.sin(300 * t)),
             (np.exp, np.exp, np.exp)]
    for f, d1, d2 in cases:
        tri = triple(tf(f))
        for t in (0.0, 0.37, 1.9):
            v, a, b = tri(t)
            assert v == f(t)
            assert abs(a - d1(t)) <= 1e-10 * max(1.0, abs(d1(t))), (f, t)
            assert abs(b - d2(t)) <= 1e-8 * max(1.0, abs(d2(t))), (f, t)

    def lost(t):
        if t > 1.0:
            raise RuntimeError("sensor lost")
        return np.sin(t)
    v, a, b = triple(tf(lost))(0.98)
    assert abs(a - np.cos(0.98)) < 1e-8 and abs(b + np.sin(0.98)) < 1e-6


def test_velocity_driver_without_closed_form_runs_compiled_like_the_reference_path():
    drive = dict(velocity="2 + sin(t**2)", initial_displacement=0.1)
    a = _run(_carousel(**drive), rtol=1e-9)
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    dynamic.USE_COMPILED = False
    try:
        b = _run(_carousel(**drive), method="dop853", rtol=1e-10)
    finally:
        dynamic.USE_COMPILED = True
    for j in ("hub", "tip"):
        assert np.max(np.abs(a.joint_coordinate(j) - b.joint_coordinate(j))) < 1e-7, j


def test_raising_driver_ends_the_run_naming_the_motion():
    def bad(t):
        if t > 0.3:
            raise RuntimeError("encoder lost")
        return 3.0 * t
    res = _run(_carousel(displacement=mb.expressions.time_function(bad, d1=lambda t: 3.0, d2=lambda t: 0.0)))
    assert not res.success and isinstance(res.error, EvaluationError)
    assert "spin" in str(res.error) and "encoder lost" in str(res.error)
    assert res.time[-1] <= 0.3 + 1e-12 and len(res.time) >= 25


def test_callable_driver_in_a_kinematic_sweep():
    """Zero-DOF crank driven by a callable: the crank angle is the callable's value at every output."""
    m = mb.Model("crank")
    crank = m.add_body("crank", 1.0, inertia=(1e-3, 1e-2, 1e-2), position=(0.1, 0, 0))
    pin = m.add_revolute("O", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_motion("drive", pin, displacement=lambda t: 0.5 * t**3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.kinematics(m, end_time=1.0, output_step=0.05)
    assert res.success and "compiled" in res.stats.get("method", ""), res.stats
    assert np.max(np.abs(res.joint_coordinate("O") - 0.5 * res.time**3)) < 1e-10
    assert np.max(np.abs(res.joint_velocity("O") - 1.5 * res.time**2)) < 1e-7


def test_njit_driver_is_fingerprinted_as_its_python_function():
    """A numba.njit dispatcher in a model is walked as the function it compiles (its own fields are numba's
    caches: walking them cost seconds per run); another function gives another digest, and the callable
    is flagged (results computed by calling it are not cached)."""
    import time

    import numba

    from mbdsim.system.fingerprint import fingerprint

    @numba.njit
    def f(t):
        return 3 * t + 2 * np.sin(t)

    @numba.njit
    def g(t):
        return 3 * t

    f(0.5), g(0.5)   # compiled: the dispatchers hold their overloads, types and environments
    mf, mg = _carousel(displacement=f), _carousel(displacement=g)
    t0 = time.perf_counter()
    a, callables = fingerprint(mf)
    assert time.perf_counter() - t0 < 0.2 and callables
    assert a == fingerprint(mf)[0] != fingerprint(mg)[0]
