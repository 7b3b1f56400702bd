"""Safe expression language, exact derivatives and time functions (closed forms, finite differences)."""
import math

import numpy as np
import pytest

from mbdsim import functions as F
from mbdsim.expressions import (Expr, ExpressionError, double_integrated, integrated, parse, time_function,
                                TimeFunction)

T = np.linspace(0.05, 0.95, 11)

# (text, numpy reference)
CASES = [
    ("1e-3 + 2.5*t", lambda t: 1e-3 + 2.5 * t),
    ("pi/6*(1-cos(pi*t/2))", lambda t: np.pi / 6 * (1 - np.cos(np.pi * t / 2))),
    ("-t**2 + 3*t - 1/(1+t)", lambda t: -t**2 + 3 * t - 1 / (1 + t)),
    ("2**t * t**0.5 - -t", lambda t: 2**t * t**0.5 + t),
    ("t**t", lambda t: t**t),
    ("sin(t)*cos(2*t) + tan(t/3)", lambda t: np.sin(t) * np.cos(2 * t) + np.tan(t / 3)),
    ("asin(t/2) + acos(t/3) + atan(4*t)", lambda t: np.arcsin(t / 2) + np.arccos(t / 3) + np.arctan(4 * t)),
    ("atan2(sin(3*t), cos(t) - 2)", lambda t: np.arctan2(np.sin(3 * t), np.cos(t) - 2)),
    ("sinh(t) - cosh(t/2) * tanh(3*t)", lambda t: np.sinh(t) - np.cosh(t / 2) * np.tanh(3 * t)),
    ("exp(-t)*log(1+t) / sqrt(2+t)", lambda t: np.exp(-t) * np.log(1 + t) / np.sqrt(2 + t)),
    ("abs(t - 0.5)**3 + abs(sin(5*t))", lambda t: np.abs(t - 0.5)**3 + np.abs(np.sin(5 * t))),
    ("STEP(t, 0.2, 0, 0.8, 1.5) + step5(t, 0, 1, 1, 2)", lambda t: F.step(t, 0.2, 0, 0.8, 1.5) + F.step5(t, 0, 1, 1, 2)),
    ("HAVSIN(2*t, 0.2, 0, 1.7, -1)", lambda t: F.havsin(2 * t, 0.2, 0, 1.7, -1)),
    ("POLY(t, 0.5, 1, -2, 3, 0.5)", lambda t: 1 - 2 * (t - 0.5) + 3 * (t - 0.5)**2 + 0.5 * (t - 0.5)**3),
    ("SHF(t, 0.1, 2, 7, 0.3, 1) * shf(t, 0, 1, 2, 0, 0)",
     lambda t: (2 * np.sin(7 * (t - 0.1) - 0.3) + 1) * np.sin(2 * t)),
    ("+t - (((t)))", lambda t: 0 * t),
]


@pytest.mark.parametrize("text,ref", CASES, ids=[c[0] for c in CASES])
def test_parse_and_evaluate(text, ref):
    e = parse(text)
    assert isinstance(e, Expr) and e.text == text and repr(e) == f"Expr({text!r})"
    np.testing.assert_allclose(e.evaluate(T), ref(T), rtol=1e-14, atol=1e-15)
    v = e(0.37)
    assert isinstance(v, float) and v == pytest.approx(float(ref(np.float64(0.37))), rel=1e-14, abs=1e-15)
    out = e(T.reshape(1, -1))
    assert isinstance(out, np.ndarray) and out.shape == (1, T.size)


@pytest.mark.parametrize("text,ref", CASES, ids=[c[0] for c in CASES])
def test_derivatives_against_finite_differences(text, ref):
    e = parse(text)
    d1, d2 = e.derivative(), e.derivative().derivative()
    t = T[np.abs(T - 0.5) > 0.01]                      # away from the kink of abs(t - 0.5)
    h = 1e-5
    np.testing.assert_allclose(d1(t), (ref(t + h) - ref(t - h)) / (2 * h), rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(d2(t), (ref(t + h) - 2 * ref(t) + ref(t - h)) / h**2, rtol=1e-4, atol=1e-4)
    # the derivatives' canonical text parses back to the same function
    for d in (d1, d2):
        np.testing.assert_allclose(parse(d.text)(t), d(t), rtol=1e-13, atol=1e-13)


def test_derivative_closed_form_driver():
    e = parse("pi/6*(1-cos(pi*t/2))")
    t = np.linspace(0, 4, 41)
    np.testing.assert_allclose(e.derivative()(t), np.pi**2 / 12 * np.sin(np.pi * t / 2), rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(e.derivative().derivative()(t), np.pi**3 / 24 * np.cos(np.pi * t / 2),
                               rtol=1e-15, atol=1e-15)
    assert e.derivative().derivative().derivative().derivative().text.count("(") <= 2   # stays small


def test_simplification():
    assert parse("0*sin(t) + t*1 + 0").derivative().text == "1"
    assert parse("3*t**2").derivative().text == "6 * t"
    assert parse("2 + 3*4").text == "2 + 3*4" and parse("2 + 3*4").derivative().text == "0"
    assert parse("2 + 3*4").is_constant and parse("2 + 3*4")(T).shape == T.shape
    assert parse("t - t").derivative().text == "0"
    assert parse("STEP(t, 0, 0, 1, 1)").derivative().derivative().derivative().derivative().text == "0"
    assert len(parse("t**5*exp(-t)").derivative().derivative().text) < 200


def test_library_function_derivatives_are_exact():
    e = parse("STEP(2*t, 0.2, 1, 1.4, -3)")
    t = np.linspace(0, 1, 21)
    np.testing.assert_allclose(e.derivative()(t), 2 * F.STEP_d(2 * t, 0.2, 1, 1.4, -3), rtol=1e-15)
    np.testing.assert_allclose(e.derivative().derivative()(t), 4 * F.step(2 * t, 0.2, 1, 1.4, -3, order=2), rtol=1e-15)
    assert "order=1" in e.derivative().text
    assert parse("STEP(t, 0, 0, 1, 1, order=1)")(0.5) == pytest.approx(1.5)
    with pytest.raises(ExpressionError, match="argument 3"):
        parse("STEP(t, 0, t, 1, 1)").derivative()


def test_tables_in_expressions():
    xs = np.linspace(0, 2, 9)
    road = F.CubicSplineTable(xs, xs**3)
    e = parse("road(2*t) + 1", tables={"road": road})
    np.testing.assert_allclose(e(T), (2 * T)**3 + 1, rtol=1e-12)
    np.testing.assert_allclose(e.derivative()(T), 24 * T**2, rtol=1e-11)
    np.testing.assert_allclose(e.derivative().derivative()(T), 48 * T, rtol=1e-10)


def test_several_variables():
    e = parse("x*sin(t) + x**2", variables=("x", "t"))
    assert e(2.0, 0.5) == pytest.approx(2 * math.sin(0.5) + 4)
    assert e(t=0.5, x=2.0) == e(2.0, 0.5)
    assert e.derivative("x")(2.0, 0.5) == pytest.approx(math.sin(0.5) + 4)
    assert e.depends_on("x") and not parse("t").depends_on("x")
    with pytest.raises(TypeError):
        e(1.0)
    with pytest.raises(ExpressionError, match="'t'"):
        parse("x*t", variables=("x",))


# (text, token named in the message)
REJECTED = [
    ("__import__('os')", "__import__"),
    ("__import__('os').system('echo hacked')", "__import__('os').system"),
    ("t.__class__", "t.__class__"),
    ("(1).real", "(1).real"),
    ("lambda: t", "lambda: t"),
    ("(lambda x: x)(t)", "lambda x: x"),
    ("x + 1", "x"),
    ("e**t", "e"),
    ("open('f')", "open"),
    ("eval('1')", "eval"),
    ("max(t, 1)", "max"),
    ("sin", "sin"),
    ("t[0]", "t[0]"),
    ("'text'", "'text'"),
    ("t if t else 1", "t if t else 1"),
    ("t < 1", "t < 1"),
    ("t ^ 2", "t ^ 2"),
    ("t % 2", "t % 2"),
    ("[t]", "[t]"),
    ("sin(t, 2)", "sin(t, 2)"),
    ("STEP(t, 1, 0, 0, 1)", "STEP(t, 1, 0, 0, 1)"),
    ("sin(*t)", "*t"),
    ("sin(x=t)", "x=t"),
    ("1/0 + t", "1/0"),
    ("STEP(1/0, 0, 0, 1, 1)", "1/0"),
    ("STEP(t, 0, 0, 1, 1, order=99)", "order=99"),
    ("log(-1)", "log(-1)"),
    ("1j*t", "1j"),
    ("sin(t", "(t"),
]


@pytest.mark.parametrize("text,token", REJECTED, ids=[r[0] for r in REJECTED])
def test_rejections_name_the_token(text, token):
    with pytest.raises(ExpressionError) as info:
        parse(text)
    msg = str(info.value)
    assert repr(text) in msg and "position" in msg
    assert token in msg and token in info.value.token
    assert isinstance(info.value, ValueError)
    assert 0 <= info.value.position <= len(text)


def test_rejection_positions():
    assert pytest.raises(ExpressionError, parse, "2*t + foo").value.position == 6
    assert pytest.raises(ExpressionError, parse, "  sin(t) + t.x").value.position == 11
    assert pytest.raises(ExpressionError, parse, "t +\n bar").value.position == 5
    assert "empty" in str(pytest.raises(ExpressionError, parse, "  ").value)
    assert "**" in str(pytest.raises(ExpressionError, parse, "t^2").value)          # hint
    assert "nested" in str(pytest.raises(ExpressionError, parse, "+".join(["t"] * 500)).value)
    with pytest.raises(TypeError):
        parse(3.0)


# ----------------------------------------------------------------------------- time functions
def test_time_function_from_string_is_exact():
    tf = time_function("pi/6*(1-cos(pi*t/2))")
    assert isinstance(tf, TimeFunction) and tf.expr is not None
    t = np.linspace(0, 2, 9)
    np.testing.assert_allclose(tf.value(t), np.pi / 6 * (1 - np.cos(np.pi * t / 2)), rtol=1e-15)
    np.testing.assert_allclose(tf.d1(t), np.pi**2 / 12 * np.sin(np.pi * t / 2), rtol=1e-15, atol=1e-16)
    assert tf.d2(1.0) == pytest.approx(np.pi**3 / 24 * np.cos(np.pi / 2), abs=1e-16)
    assert time_function(tf) is tf


def test_time_function_constant():
    tf = time_function(0.25)
    assert tf.value(3.0) == 0.25 and tf.d1(3.0) == 0.0 and tf.d2(3.0) == 0.0
    np.testing.assert_array_equal(tf.value(T), np.full(T.shape, 0.25))
    with pytest.raises(TypeError):
        time_function(None)
    with pytest.raises(TypeError):
        time_function(True)


@pytest.mark.parametrize("t", [0.0, 0.7, 3.3, -12.5])
def test_time_function_callable_numpy_complex_step(t):
    tf = time_function(lambda s: np.exp(0.3 * s) * np.sin(2 * s))
    d1 = np.exp(0.3 * t) * (0.3 * np.sin(2 * t) + 2 * np.cos(2 * t))
    d2 = np.exp(0.3 * t) * ((0.09 - 4) * np.sin(2 * t) + 1.2 * np.cos(2 * t))
    scale = np.exp(0.3 * t) * 4
    assert tf.d1(t) == pytest.approx(d1, rel=1e-12, abs=1e-14 * scale)
    assert tf.d2(t) == pytest.approx(d2, rel=1e-9, abs=1e-9 * scale)


def test_time_function_callable_math_only_richardson():
    tf = time_function(lambda s: math.sin(s) + s**3)            # math.sin rejects complex input
    t = np.array([0.2, 1.1, 2.5])
    np.testing.assert_allclose(tf.value(t), np.sin(t) + t**3, rtol=1e-15)  # scalar-only callable, mapped
    np.testing.assert_allclose(tf.d1(t), np.cos(t) + 3 * t**2, rtol=1e-10)
    np.testing.assert_allclose(tf.d2(t), -np.sin(t) + 6 * t, rtol=1e-9)
    assert isinstance(tf.d1(1.0), float)


def test_time_function_rejects_wrong_complex_step():
    tf = time_function(lambda s: s * np.abs(s))                # complex step would give |t|, not 2|t|
    assert tf.d1(0.7) == pytest.approx(1.4, rel=1e-9)
    assert tf.d2(0.7) == pytest.approx(2.0, rel=1e-8)
    branchy = time_function(lambda s: s**2 if s < 1 else 2 * s - 1)   # Python branch: complex raises
    assert branchy.d1(0.5) == pytest.approx(1.0, rel=1e-10)
    assert branchy.d1(3.0) == pytest.approx(2.0, rel=1e-10)


def test_time_function_explicit_derivatives():
    tf = time_function(math.sin, d1=math.cos, d2=lambda s: -math.sin(s))
    assert tf.d1(0.3) == math.cos(0.3) and tf.d2(0.3) == -math.sin(0.3)
    half = time_function(np.sin, d1=np.cos)                     # d2 from d1 numerically
    assert half.d2(0.3) == pytest.approx(-np.sin(0.3), rel=1e-10)
    with pytest.raises(TypeError):
        time_function("sin(t)", d1=np.cos)


def test_integrated_velocity_driver():
    x = integrated("sin(t)", x0=0.5)
    t = np.array([0.0, 0.3, 1.0, 2.7, 6.5, -1.4])
    np.testing.assert_allclose(x.value(t), 0.5 + 1 - np.cos(t), rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(x.d1(t), np.sin(t), rtol=1e-15)
    np.testing.assert_allclose(x.d2(t), np.cos(t), rtol=1e-15)
    assert x.value(4.2) == pytest.approx(1.5 - math.cos(4.2), rel=1e-13)
    assert integrated(3.0).value(2.0) == pytest.approx(6.0, rel=1e-14)


def test_double_integrated_acceleration_driver():
    x0, v0 = 0.1, -0.4
    x = double_integrated(lambda s: np.sin(s), x0, v0)
    t = np.array([0.0, 0.5, 1.9, 3.2, 8.7, -2.3])
    np.testing.assert_allclose(x.value(t), x0 + v0 * t + t - np.sin(t), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(x.d1(t), v0 + 1 - np.cos(t), rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(x.d2(t), np.sin(t), rtol=1e-15)
    assert double_integrated(2.0).value(3.0) == pytest.approx(9.0, rel=1e-13)


def test_time_functions_pickle():
    import pickle
    for tf in (time_function("STEP(t, 0, 0, 1, 2) + sin(t)"), time_function(1.5), time_function(np.sin),
               integrated("cos(t)"), double_integrated(2.0, 1.0, -1.0)):
        back = pickle.loads(pickle.dumps(tf))
        for t in (0.3, 1.7):
            assert back.value(t) == pytest.approx(tf.value(t), rel=1e-15)
            assert back.d1(t) == pytest.approx(tf.d1(t), rel=1e-12)
            assert back.d2(t) == pytest.approx(tf.d2(t), rel=1e-12, abs=1e-14)
