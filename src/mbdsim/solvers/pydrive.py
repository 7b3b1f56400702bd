"""Value, d1, d2 of a Python-callable driver at one time, cheaply (the driver callback of solvers.pyloads).

`triple(fn)` returns t -> (value [unit], d1 [unit/s], d2 [unit/s^2]) of a TimeFunction `fn` for a float t
[s], calling the user's functions directly on the float (no array shaping: about 1 us per call of plain
Python instead of ~15 us through TimeFunction.value/d1/d2).

When the derivatives are numerical (a bare callable f, timefunctions._NumericDerivative) they come from
ONE 9-point stencil of f at t + k h, k = -4..4, h = H_STEP s (nine calls of f for all three values,
instead of the ~40 calls of the Richardson tableau): the 8th-order central differences of d1 and d2,
accepted when they agree with the 4th-order differences of the same points to ACCEPT (relative, or
absolute for values below 1), which for a smooth f bounds the 8th-order error far below it (about
ACCEPT^2: 1e-12 and better for time scales of f above ~0.05 s). Otherwise (fast features, a kink or a
failure of f within 4 h of t) the reference tableau (TimeFunction.d1/d2: Ridders' extrapolation) is used
for that instant, so the accuracy is never below the documented one of timefunctions.
"""
from __future__ import annotations

import math

from ..timefunctions import _NumericDerivative

H_STEP, ACCEPT = 0.01, 1e-6

# central-difference weights at offsets 1..4 (antisymmetric for d1, symmetric for d2; c0 the centre)
_D1_8 = (4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0)
_D2_8 = (8.0 / 5.0, -1.0 / 5.0, 8.0 / 315.0, -1.0 / 560.0)
_D2_8_C0 = -205.0 / 72.0
_D1_4, _D2_4, _D2_4_C0 = (2.0 / 3.0, -1.0 / 12.0), (4.0 / 3.0, -1.0 / 12.0), -5.0 / 2.0


def _num(x) -> float:
    """float of a scalar the user's function returned (a number or a one-element array)."""
    try:
        return float(x)
    except TypeError:
        import numpy as np
        return float(np.asarray(x, dtype=float).reshape(()))


def triple(fn):
    """t -> (value, d1, d2) of TimeFunction `fn` at float t [s] (see the module docstring)."""
    f, g1, g2 = fn.f, fn.f_d1, fn.f_d2
    numeric = (isinstance(g1, _NumericDerivative) and g1.f is f and g1.order == 1
               and isinstance(g2, _NumericDerivative) and g2.f is f and g2.order == 2)
    if numeric:
        return lambda t: _stencil(fn, t)

    def direct(t):
        try:
            return _num(f(t)), _num(g1(t)), _num(g2(t))
        except (TypeError, ValueError):   # not callable on a float: the TimeFunction's own shaping
            return fn.value(t), fn.d1(t), fn.d2(t)
    return direct


def _stencil(fn, t):
    """(value, d1, d2) at t from the 9-point stencil, or the reference tableau where it is not accepted."""
    f = fn.f
    h = (t + H_STEP) - t
    try:
        f0 = float(f(t))
        p1, p2, p3, p4 = float(f(t + h)), float(f(t + 2 * h)), float(f(t + 3 * h)), float(f(t + 4 * h))
        m1, m2, m3, m4 = float(f(t - h)), float(f(t - 2 * h)), float(f(t - 3 * h)), float(f(t - 4 * h))
    except Exception:  # noqa: BLE001 - f fails near t, or returns an array: the reference tableau
        return _num(fn.value(t)), _num(fn.d1(t)), _num(fn.d2(t))
    a1, a2, a3, a4 = p1 - m1, p2 - m2, p3 - m3, p4 - m4
    s1, s2, s3, s4 = p1 + m1, p2 + m2, p3 + m3, p4 + m4
    c1, c2 = _D1_8, _D2_8
    d1 = (c1[0] * a1 + c1[1] * a2 + c1[2] * a3 + c1[3] * a4) / h
    d2 = (_D2_8_C0 * f0 + c2[0] * s1 + c2[1] * s2 + c2[2] * s3 + c2[3] * s4) / (h * h)
    d1_4 = (_D1_4[0] * a1 + _D1_4[1] * a2) / h
    d2_4 = (_D2_4_C0 * f0 + _D2_4[0] * s1 + _D2_4[1] * s2) / (h * h)
    ok = math.isfinite(f0) and math.isfinite(d1) and math.isfinite(d2)
    if not ok or abs(d1 - d1_4) > ACCEPT * max(1.0, abs(d1)):
        d1 = _num(fn.d1(t))
    if not ok or abs(d2 - d2_4) > ACCEPT * max(1.0, abs(d2)):
        d2 = _num(fn.d2(t))
    return f0, d1, d2
