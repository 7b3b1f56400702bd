"""The compiled expression interpreter against the Python evaluator of the same parsed trees."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.system import exprvm
from mbdsim.timefunctions import time_function

TS = np.concatenate([np.linspace(-2.5, 3.5, 61), [0.0, 0.25, 0.5, 1.0, 2.0]])

EXPRESSIONS = [
    "pi/6*(1-cos(pi*t/2))", "3*t + 2*t**2 - t**3/7", "sin(t)*exp(-t/3) + cos(2*t)**2", "tan(t/3) - atan(t)",
    "sqrt(1 + t*t) + log(2 + sin(t))", "abs(t - 0.3) * sign(t)", "sinh(t/2) + cosh(t/3) - tanh(t)",
    "asin(t/4) + acos(t/5)", "atan2(t, 1 - t)", "-t**-2 + 1/(1 + t**2)", "(t/3)**2.5",
    "STEP(t, 0, 0, 1, 2)", "STEP5(t, 0.2, -1, 1.5, 3)", "HAVSIN(t, -1, 0, 2, 4)", "POLY(t, 0.5, 1, -2, 3, 0.25)",
    "SHF(t, 0.1, 2, 3, 0.4, -1)", "STEP(t, 0, 0, 1, 1) * SHF(t, 0, 1, 6.283, 0, 0) + POLY(t, 0, 2)",
    "log(t)", "1/t",
]


def _vm(expr, t):
    p = exprvm.pack([exprvm.compile_expr(expr, {"t": 0})])
    stack = np.zeros(p.stack_size)
    return np.array([exprvm.eval_program(p.code, p.consts, p.tables, p.start[0], p.end[0], np.array([x]), stack)
                     for x in np.atleast_1d(t)])


def _close(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    same_nan = np.isnan(a) == np.isnan(b)
    ok = np.isclose(a, b, rtol=1e-13, atol=1e-14) | (np.isinf(a) & (a == b)) | (np.isnan(a) & np.isnan(b))
    return bool(np.all(same_nan & ok))


@pytest.mark.parametrize("text", EXPRESSIONS)
def test_values_and_derivatives_match_the_python_evaluator(text):
    e = mb.parse(text)
    with np.errstate(all="ignore"):
        for f in (e, e.derivative(), e.derivative().derivative()):
            assert _close(_vm(f, TS), [f(x) for x in TS]), f.text


def test_spline_tables():
    xs, ys = [0.0, 0.4, 1.1, 2.0, 3.0], [0.0, 1.0, -0.5, 0.7, 0.2]
    for table in (mb.Akima(xs, ys), mb.CubicSplineTable(xs, ys, bc_type="natural")):
        e = mb.parse("tab(t) + 2*t", tables={"tab": table})
        for f in (e, e.derivative(), e.derivative().derivative()):
            assert _close(_vm(f, TS), [f(x) for x in TS])


def test_time_programs_and_packing():
    fns = [time_function("sin(3*t)"), time_function(2.5), time_function(lambda t: t)]
    progs = [exprvm.time_programs(f) for f in fns]
    assert progs[2] is None                           # a Python callable stays on the Python path
    p = exprvm.pack([q for trio in progs[:2] for q in trio])
    stack = np.zeros(p.stack_size)
    vals = [exprvm.eval_program(p.code, p.consts, p.tables, p.start[k], p.end[k], np.array([0.7]), stack)
            for k in range(6)]
    assert np.allclose(vals, [np.sin(2.1), 3 * np.cos(2.1), -9 * np.sin(2.1), 2.5, 0.0, 0.0], rtol=1e-14)


def test_one_compiled_interpreter_for_every_expression():
    for text in EXPRESSIONS[:6]:
        _vm(mb.parse(text), [0.3])
    assert len(exprvm.eval_program.signatures) == 1


def test_unknown_variable_is_an_expression_error():
    with pytest.raises(mb.ExpressionError):
        exprvm.compile_expr(mb.parse("x*t", variables=("t", "x")), {"t": 0})
