"""User functions compiled with numba run inside the kernels (issue 29, mbdsim.userfunctions): a load
calling an njit / cfunc function registered with Model.add_function against the same load written as an
expression, an njit driver of t against its expression, and the bad inputs (each named)."""
import warnings

import numba
import numpy as np
import pytest
from numba import types

import mbdsim as mb
from mbdsim.errors import EvaluationError
from test_driver_integrals import _carousel   # arm turned about z by the motion, pendulum at its tip


@numba.njit
def drag(w):
    return -0.3 * w


@numba.njit
def spin(t):
    return 3 * t + 2 * np.sin(t)


@numba.njit
def spin_d1(t):
    return 3 + 2 * np.cos(t)


@numba.njit
def spin_d2(t):
    return -2 * np.sin(t)


@numba.cfunc(types.float64(types.float64, types.float64))
def spring(x, xd):
    return -5.0 * (x - 0.2) - 0.1 * xd


def _run(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.simulate(model, **{"end_time": 1.5, "output_step": 0.01, **kw})


def _pendulum(torque, **functions):
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 2.0, inertia=(0.01, 2 / 12, 2 / 12), position=(0.5, 0, 0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    for name, fn in functions.items():
        m.add_function(name, fn)
    m.add_torque("drag", rod, (0, 0, torque))
    return m


def test_njit_load_matches_the_expression():
    a = _run(_pendulum("drag(WZ(rod))", drag=drag))
    b = _run(_pendulum("-0.3*WZ(rod)"))
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    assert np.max(np.abs(a.joint_coordinate("pin") - b.joint_coordinate("pin"))) < 1e-10
    assert np.ptp(b.joint_coordinate("pin")) > 0.5   # (it swings)


def test_cfunc_of_two_arguments_in_a_joint_torque():
    def model(value, **fns):
        m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
        rod = m.add_body("rod", 2.0, inertia=(0.01, 2 / 12, 2 / 12), position=(0.5, 0, 0))
        pin = m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
        for name, fn in fns.items():
            m.add_function(name, fn)
        m.add_joint_force("k", pin, value)
        return m
    a = _run(model("spring(pin, pin_dot)", spring=spring))
    b = _run(model("-5.0*(pin - 0.2) - 0.1*pin_dot"))
    assert a.success and "compiled" in a.stats["method"], a.stats["method"]
    assert np.max(np.abs(a.joint_coordinate("pin") - b.joint_coordinate("pin"))) < 1e-10


def test_njit_driver_matches_the_expression_driver():
    b = _run(_carousel(displacement="3*t + 2*sin(t)"))
    exact = _run(_carousel(displacement=mb.expressions.time_function(spin, d1=spin_d1, d2=spin_d2)))
    stencil = _run(_carousel(displacement=spin))   # d1, d2: 8th-order central differences in the kernel
    for a, tol in ((exact, 1e-10), (stencil, 1e-8)):
        assert a.success and "compiled" in a.stats["method"], a.stats["method"]
        assert a.system.derived["compiled"][1].python_drivers == ()   # no driver callback: the cfunc's address
        for j in ("hub", "tip"):
            assert np.max(np.abs(a.joint_coordinate(j) - b.joint_coordinate(j))) < tol, j


def test_user_function_evaluates_in_python_outputs():
    """The reference path and outputs call the same function (its cfunc) from Python, element-wise."""
    m = _pendulum("drag(WZ(rod))", drag=drag)
    uf = m.functions["drag"]
    assert uf(2.0) == pytest.approx(-0.6) and np.allclose(uf(np.array([1.0, 2.0])), [-0.3, -0.6])


def test_bad_user_functions_are_named():
    with pytest.raises(mb.ModelError, match=r"function 'slow'.*numba.njit"):
        _pendulum("slow(WZ(rod))", slow=lambda w: -0.3 * w)
    with pytest.raises(mb.ModelError, match=r"drag.*takes 1 argument"):
        _pendulum("drag(WZ(rod), t)", drag=drag)

    @numba.cfunc(types.int64(types.int64))
    def ints(x):
        return x
    with pytest.raises(mb.ModelError, match=r"function 'ints'.*float64"):
        _pendulum("ints(t)", ints=ints)

    @numba.njit
    def tup(x):
        return (x, x)
    with pytest.raises(mb.ModelError, match=r"function 'tup'.*numba cannot compile"):
        _pendulum("tup(t)", tup=tup)


def test_non_finite_return_ends_the_run_naming_the_function():
    @numba.njit
    def wall(w):
        return -0.3 * w if w > -2.0 else np.nan   # nan once the rod swings fast enough
    res = _run(_pendulum("wall(WZ(rod))", wall=wall))
    assert not res.success and isinstance(res.error, EvaluationError)
    assert "wall" in str(res.error) and "load 'drag'" in str(res.error) and "non-finite" in str(res.error)
    assert res.time[-1] < 1.5


def test_model_file_refuses_a_user_function(tmp_path):
    with pytest.raises(mb.ModelError, match=r"function 'drag'.*Model.add_function"):
        mb.save_model(_pendulum("drag(WZ(rod))", drag=drag), tmp_path / "p.yaml")


def test_non_finite_driver_names_the_function_and_the_motion():
    @numba.njit
    def encoder(t):
        return 3.0 * t if t < 0.3 else np.inf   # (also: no complex step on a numba function's reference path)
    res = _run(_carousel(displacement=encoder))
    assert not res.success and isinstance(res.error, EvaluationError)
    assert "'encoder'" in str(res.error) and "motion 'spin'" in str(res.error)
    assert 0.25 < res.time[-1] <= 0.3
