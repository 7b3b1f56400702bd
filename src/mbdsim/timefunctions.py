"""Time functions for drivers: value and first/second time derivatives of f(t).

Units: t in s; value in the driven coordinate's SI unit (m or rad), d1 in that unit per s,
d2 per s^2. Build them with :func:`time_function` (re-exported by :mod:`mbdsim.expressions`):

* a string is parsed by :func:`mbdsim.expressions.parse` and differentiated exactly;
* a number is a constant (d1 = d2 = 0);
* a callable of t gets numerical derivatives unless ``d1=``/``d2=`` callables are given:
  d1 by the complex step f'(t) = Im f(t + ih)/h when the callable accepts complex input (the
  result is checked against a central difference, else dropped), otherwise, and for d2, by
  Richardson-extrapolated central differences (Ridders' tableau: initial step 0.1 max(1, |t|) s,
  halved 7 times, the estimate with the smallest error estimate kept), about 1e-9 relative for
  functions smooth on a 0.1 s scale.

:func:`integrated` and :func:`double_integrated` turn a velocity or acceleration driver into a
displacement TimeFunction by adaptive quadrature (scipy.integrate.quad).
"""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from scipy.integrate import quad

__all__ = ["TimeFunction", "time_function", "integrated", "double_integrated"]


def _shape_out(y, t):
    """float for scalar t, ndarray shaped like t otherwise."""
    if np.ndim(t):
        return np.array(np.broadcast_to(np.asarray(y, dtype=float), np.shape(t)))
    return float(np.asarray(y, dtype=float).reshape(-1)[0]) if np.size(y) == 1 else float(y)


def _apply(f, t):
    """f(t) for scalar or array t; a callable that only takes scalars is mapped element-wise."""
    if np.ndim(t) == 0:
        return f(t)
    t = np.asarray(t)
    try:
        y = np.asarray(f(t))
        if y.shape == t.shape or y.ndim == 0:
            return np.broadcast_to(y, t.shape)
    except (TypeError, ValueError):
        pass
    return np.array([f(ti) for ti in t.ravel()]).reshape(t.shape)


@dataclass(frozen=True)
class TimeFunction:
    """A driver function of time: ``value(t)`` [unit], ``d1(t)`` [unit/s], ``d2(t)`` [unit/s^2].

    t may be a float (float returned) or a numpy array (array returned). ``expr`` is the parsed
    :class:`~mbdsim.expressions.Expr` when the function came from a string, else None.
    """

    f: Callable[[Any], Any]
    f_d1: Callable[[Any], Any]
    f_d2: Callable[[Any], Any]
    description: str = ""
    expr: Any = field(default=None, compare=False)

    def value(self, t):
        return _shape_out(_apply(self.f, t), t)

    def d1(self, t):
        return _shape_out(_apply(self.f_d1, t), t)

    def d2(self, t):
        return _shape_out(_apply(self.f_d2, t), t)

    __call__ = value

    def __repr__(self) -> str:
        return f"TimeFunction({self.description})"


# ----------------------------------------------------------------------------- numerical derivatives
_H0, _LEVELS = 0.1, 7


def _richardson(f, t, order):
    """Ridders/Richardson extrapolation of central differences (first or second derivative)."""
    t = np.asarray(t, dtype=float)
    h = _H0 * np.maximum(1.0, np.abs(t))
    f0 = np.asarray(_apply(f, t), dtype=float) if order == 2 else None
    best, err, prev = None, np.full(t.shape, np.inf), None
    for _ in range(_LEVELS):
        fp, fm = (np.asarray(_apply(f, t + s * h), dtype=float) for s in (1.0, -1.0))
        row = [(fp - fm) / (2.0 * h) if order == 1 else (fp - 2.0 * f0 + fm) / h**2]
        for k in range(1, len(prev) + 1 if prev else 1):
            row.append(row[k - 1] + (row[k - 1] - prev[k - 1]) / (4.0**k - 1.0))
            e = np.maximum(np.abs(row[k] - row[k - 1]), np.abs(row[k] - prev[k - 1]))
            better = e <= err
            best, err = np.where(better, row[k], best if best is not None else row[k]), np.where(better, e, err)
        if best is None:
            best = row[0]
        prev, h = row, h / 2.0
    return best[()] if best.ndim == 0 else best


def _complex_step(f, t):
    """Im f(t + ih)/h if f accepts complex input and agrees with a central difference; else None."""
    t = np.asarray(t, dtype=float)
    scale = np.maximum(1.0, np.abs(t))
    h = 1e-20 * scale
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            y = np.asarray(_apply(f, t + 1j * h))
    except (TypeError, ValueError, ArithmeticError):
        return None
    if not np.iscomplexobj(y) or y.shape not in (t.shape, ()) or not np.all(np.isfinite(y)):
        return None
    d = np.imag(y) / h
    hc = 1e-5 * scale
    with np.errstate(all="ignore"):
        cd = (np.asarray(_apply(f, t + hc), dtype=float) - np.asarray(_apply(f, t - hc), dtype=float)) / (2 * hc)
    tol = 1e-6 * (np.abs(d) + np.abs(cd)) + 1e-9 * np.abs(np.real(y)) / scale + 1e-300
    if not np.all(np.abs(d - cd) <= tol):
        return None
    return d[()] if d.ndim == 0 else d


def _numeric_d1(f):
    def d1(t):
        d = _complex_step(f, t)
        return _richardson(f, t, 1) if d is None else d
    return d1


def _numeric_d2(f):
    return lambda t: _richardson(f, t, 2)


def time_function(f, d1=None, d2=None) -> TimeFunction:
    """Make a :class:`TimeFunction` of t [s] from a str expression, a number, a callable or a TimeFunction.

    ``d1``/``d2``: optional exact derivative callables for a callable ``f`` (when only ``d1`` is
    given, d2 is the numerical derivative of d1).
    """
    from .expressions import Expr, parse
    if isinstance(f, TimeFunction) and d1 is None and d2 is None:
        return f
    if isinstance(f, str):
        f = parse(f)
    if isinstance(f, Expr):
        if d1 is not None or d2 is not None:
            raise TypeError("d1/d2 are derived exactly from an expression; give them only with a callable")
        if set(f.variables) != {"t"}:
            raise ValueError(f"a time function is an expression of t only, not of {f.variables}")
        e1 = f.derivative("t")
        return TimeFunction(f, e1, e1.derivative("t"), repr(f.text), f)
    if isinstance(f, numbers.Real) and not isinstance(f, bool):
        c = float(f)
        if not math.isfinite(c):
            raise ValueError(f"a constant time function must be finite, got {f!r}")
        return TimeFunction(lambda t: c, lambda t: 0.0, lambda t: 0.0, f"constant {c!r}")
    if not callable(f):
        raise TypeError(f"a time function is a str expression, a number or a callable of t, not {type(f).__name__}")
    name = getattr(f, "__name__", type(f).__name__)
    fd1 = d1 if d1 is not None else _numeric_d1(f)
    fd2 = d2 if d2 is not None else (_numeric_d1(d1) if d1 is not None else _numeric_d2(f))
    how = "exact" if d1 is not None and d2 is not None else "numerical"
    return TimeFunction(f, fd1, fd2, f"callable {name} ({how} derivatives)")


# ----------------------------------------------------------------------------- integrals
class _Cumulative:
    """t -> integral_0^t w(tau) g(tau) dtau by quad, anchored on a cached grid of whole seconds."""

    STEP = 1.0

    def __init__(self, g, weight=None):
        self.g, self.weight, self.anchors = g, weight, {0: 0.0}

    def _quad(self, a, b):
        w = self.weight
        integrand = (lambda s: float(self.g(s))) if w is None else (lambda s: w(s) * float(self.g(s)))
        return quad(integrand, a, b, epsabs=1e-13, epsrel=1e-13, limit=200)[0]

    def _anchor(self, k):
        if k not in self.anchors:
            sgn = 1 if k > 0 else -1
            j = k - sgn
            while j not in self.anchors:
                j -= sgn
            for m in range(j + sgn, k + sgn, sgn):
                self.anchors[m] = self.anchors[m - sgn] + self._quad((m - sgn) * self.STEP, m * self.STEP)
        return self.anchors[k]

    def scalar(self, t):
        k = int(math.floor(t / self.STEP))
        return self._anchor(k) + self._quad(k * self.STEP, t)

    def __call__(self, t):
        if np.ndim(t) == 0:
            return self.scalar(float(t))
        t = np.asarray(t, dtype=float)
        return np.array([self.scalar(x) for x in t.ravel()]).reshape(t.shape)


def integrated(f, x0=0.0) -> TimeFunction:
    """Displacement x(t) = x0 + integral_0^t f of a velocity driver f (d1 = f, d2 = f'); x0 at t = 0."""
    g = time_function(f)
    integral = _Cumulative(g.value)
    return TimeFunction(lambda t: x0 + integral(t), g.value, g.d1, f"x0 + integral of {g.description}")


def double_integrated(f, x0=0.0, v0=0.0) -> TimeFunction:
    """Displacement of an acceleration driver f: x = x0 + v0 t + integral_0^t (t - tau) f(tau) dtau.

    d1 = v0 + integral_0^t f, d2 = f; x0 and v0 are the values at t = 0.
    """
    g = time_function(f)
    i1, i2 = _Cumulative(g.value), _Cumulative(g.value, weight=lambda s: s)

    def value(t):
        return x0 + v0 * t + t * i1(t) - i2(t)
    return TimeFunction(value, lambda t: v0 + i1(t), g.value, f"x0 + v0 t + double integral of {g.description}")
