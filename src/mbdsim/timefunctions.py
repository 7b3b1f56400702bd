"""Time functions for drivers: value and first/second time derivatives of f(t).

Units: t in s; value in the driven coordinate's SI unit (m or rad), d1 in that unit per s,
d2 per s^2. Build them with :func:`time_function` (re-exported by :mod:`mbdsim.expressions`):

* a string is parsed by :func:`mbdsim.expressions.parse` and differentiated exactly;
* a number is a constant (d1 = d2 = 0);
* a callable of t gets numerical derivatives unless ``d1=``/``d2=`` callables are given:
  d1 by the complex step f'(t) = Im f(t + ih)/h when the callable accepts complex input (the
  result is checked against a central difference, else dropped), otherwise, and for d2, by
  Richardson-extrapolated central differences (Ridders' tableau: initial step 0.1 s, halved 9
  times, the estimate with the smallest error estimate kept): about 1e-9 relative for smooth
  functions whose time scale is 0.003 s or longer (e.g. sin(300 t)); faster features, or kinks
  within 0.1 s of t, need explicit d1/d2 or an expression. Steps at which the callable raises (it
  fails beyond some time) are skipped, so its derivatives are those of the finer steps.
  (Inside the compiled step loop, a driver's d1/d2 come from a cheaper 9-point stencil checked
  against its own 4th-order differences, falling back to these: solvers.pydrive.)

:func:`integrated` and :func:`double_integrated` turn a velocity or acceleration driver into a
displacement TimeFunction: an exact expression when the driver's expression has a closed-form
antiderivative (mbdsim._exprint), else by adaptive quadrature (scipy.integrate.quad).
"""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

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
    :class:`~mbdsim.expressions.Expr` when the function came from a string, else None; ``symbolic`` the
    driver's trees in t and the model inputs it reads when it reads any (mbdsim.model.input_drivers: the
    value/d1/d2 here are those with the inputs' declared values).
    """

    f: Callable[[Any], Any]
    f_d1: Callable[[Any], Any]
    f_d2: Callable[[Any], Any]
    description: str = ""
    expr: Any = field(default=None, compare=False)
    symbolic: Any = field(default=None, compare=False)   # a driver reading model inputs (model.input_drivers)

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
_H0, _LEVELS = 0.1, 10


def _richardson(f, t, order):
    """Ridders/Richardson extrapolation of central differences (first or second derivative).

    Steps h = 0.1 s, 0.05 s, ... (the actual steps (t + h) - t and t - (t - h) are used, so large
    t only costs roundoff). All 10 levels are always run (20 calls of f): stopping early on a
    growing error estimate mistakes garbage at coarse steps for convergence when f varies fast.
    Levels at which f raises are skipped while no level has succeeded (a callable that fails beyond
    some time, e.g. a sensor lost at 0.12 s, still has its derivatives at 0.02 s from the finer steps,
    so an analysis keeps every sample up to the fault); later failures end the tableau with what it
    has; when every level raised, the last exception is raised.
    """
    t = np.asarray(t, dtype=float)
    h = np.full(t.shape, _H0)
    f0 = np.asarray(_apply(f, t), dtype=float) if order == 2 else None
    best, err, prev, failed = None, np.full(t.shape, np.inf), None, None
    for _ in range(_LEVELS):
        tp, tm = t + h, t - h
        hp, hm = tp - t, t - tm
        try:
            fp, fm = np.asarray(_apply(f, tp), dtype=float), np.asarray(_apply(f, tm), dtype=float)
        except Exception as exc:  # noqa: BLE001 - the user's f, re-raised below when no level succeeds
            if best is not None:
                break
            failed, h = exc, h / 2.0
            continue
        if order == 1:
            row = [(fp - fm) / (hp + hm)]
        else:
            row = [2.0 * (hm * fp - (hp + hm) * f0 + hp * fm) / (hp * hm * (hp + hm))]
        for k in range(1, len(prev) + 1 if prev else 1):
            row.append(row[k - 1] + (row[k - 1] - prev[k - 1]) / (4.0**k - 1.0))
            e = np.maximum(np.abs(row[k] - row[k - 1]), np.abs(row[k] - prev[k - 1]))
            better = e <= err
            best, err = np.where(better, row[k], best), np.where(better, e, err)
        if best is None:
            best = row[0]
        prev, h = row, h / 2.0
    if best is None:
        raise failed
    return best[()] if best.ndim == 0 else best


def _complex_step(f, t):
    """Im f(t + ih)/h if f accepts complex input and agrees with a central difference; else None."""
    from .userfunctions import is_numba
    if is_numba(f):   # a numba function of float64 (a complex argument would compile another one, or fail typing)
        return None
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


@dataclass(frozen=True)
class _NumericDerivative:
    """t -> d^order f/dt^order (order 1: complex step if valid, else Richardson; order 2: Richardson)."""

    f: Callable[[Any], Any]
    order: int

    def __call__(self, t):
        d = _complex_step(self.f, t) if self.order == 1 else None
        return _richardson(self.f, t, self.order) if d is None else d


@dataclass(frozen=True)
class _Constant:
    c: float

    def __call__(self, t):
        return self.c


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
        return TimeFunction(_Constant(c), _Constant(0.0), _Constant(0.0), f"constant {c!r}")
    if not callable(f):
        raise TypeError(f"a time function is a str expression, a number or a callable of t, not {type(f).__name__}")
    name = getattr(f, "__name__", type(f).__name__)
    fd1 = d1 if d1 is not None else _NumericDerivative(f, 1)
    fd2 = d2 if d2 is not None else (_NumericDerivative(d1, 1) if d1 is not None else _NumericDerivative(f, 2))
    how = "exact" if d1 is not None and d2 is not None else "numerical"
    return TimeFunction(f, fd1, fd2, f"callable {name} ({how} derivatives)")


# ----------------------------------------------------------------------------- integrals
class _Cumulative:
    """t -> integral_0^t g(tau) dtau (moment=True: of tau g(tau)) by quad, anchored on a cached 1 s grid."""

    STEP = 1.0

    def __init__(self, g, moment=False):
        self.g, self.moment, self.anchors = g, moment, {0: 0.0}

    def _integrand(self, s):
        return s * float(self.g(s)) if self.moment else float(self.g(s))

    def _quad(self, a, b):
        size = max(1e-300, *(abs(self._integrand(s)) for s in np.linspace(a, b, 5))) * abs(b - a)
        from scipy.integrate import quad   # imported here: scipy.integrate costs ~0.3 s at start-up
        return quad(self._integrand, a, b, epsabs=1e-13 * size, epsrel=1e-13, limit=200)[0]

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


@dataclass(frozen=True)
class _Integrated:
    """t -> a + b t + I1(t) (i2 None), or a + b t + t I1(t) - I2(t) (the double integral)."""

    a: float
    b: float
    i1: _Cumulative
    i2: _Cumulative | None = None

    def __call__(self, t):
        rest = self.i1(t) if self.i2 is None else t * self.i1(t) - self.i2(t)
        return self.a + self.b * t + rest


def _closed_form(g, times, x0, v0):
    """TimeFunction of the `times`-fold integral of expression TimeFunction g (x0 + v0 t + ...), from the
    closed-form antiderivative (mbdsim._exprint), or None when g is not an expression or has none."""
    from ._exprint import antiderivative
    from ._exprtree import Const, Var, add, mul
    from .expressions import Expr
    if isinstance(g.f, _Constant):
        g = TimeFunction(Expr(Const(g.f.c)), Expr(Const(0.0)), Expr(Const(0.0)), g.description, Expr(Const(g.f.c)))
    if g.expr is None:
        return None
    F = antiderivative(g.expr.node, "t", times)
    if F is None:
        return None
    F = add(add(Const(float(x0)), mul(Const(float(v0)), Var("t"))), F)
    value = Expr(F, ("t",))
    if times == 1:
        d1, d2 = g.f, g.f_d1
    else:
        G = antiderivative(g.expr.node, "t", 1)
        d1, d2 = Expr(add(Const(float(v0)), G), ("t",)), g.f
    kind = "integral" if times == 1 else "double integral"
    return TimeFunction(value, d1, d2, f"{x0} + {kind} of {g.description} (closed form)", value)


def integrated(f, x0=0.0) -> TimeFunction:
    """Displacement x(t) = x0 + integral_0^t f of a velocity driver f (d1 = f, d2 = f'); x0 at t = 0.

    An expression with a closed-form antiderivative (polynomials, sin/cos/exp of a t + b times
    polynomials, STEP/STEP5/HAVSIN/POLY/SHF: mbdsim._exprint) gives an exact expression (`expr` set: the
    compiled core evaluates it); anything else is integrated by adaptive quadrature when evaluated."""
    g = time_function(f)
    exact = _closed_form(g, 1, x0, 0.0)
    if exact is not None:
        return exact
    return TimeFunction(_Integrated(float(x0), 0.0, _Cumulative(g.value)), g.value, g.d1,
                        f"{x0} + integral of {g.description}")


def double_integrated(f, x0=0.0, v0=0.0) -> TimeFunction:
    """Displacement of an acceleration driver f: x = x0 + v0 t + integral_0^t (t - tau) f(tau) dtau.

    d1 = v0 + integral_0^t f, d2 = f; x0 and v0 are the values at t = 0. Closed form when the
    expression allows (see `integrated`), else quadrature.
    """
    g = time_function(f)
    exact = _closed_form(g, 2, x0, v0)
    if exact is not None:
        return exact
    i1, i2 = _Cumulative(g.value), _Cumulative(g.value, moment=True)
    return TimeFunction(_Integrated(float(x0), float(v0), i1, i2), _Integrated(float(v0), 0.0, i1), g.value,
                        f"{x0} + {v0} t + double integral of {g.description}")
