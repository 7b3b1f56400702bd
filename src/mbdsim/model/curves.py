"""Space curves for path (point-on-curve) constraints: mb.Curve and mb.Spline.

A curve is C(s), s a scalar parameter, C a point [m] given in GROUND axes at t = 0 (the curve is then
carried by the body it is fixed on).  `derivatives(s)` returns (C, dC/ds, d2C/ds2).

- `Curve(function, s_range, d1=None, d2=None, closed=False)`: a parametric callable s -> 3 numbers.
  Without d1, dC/ds is taken by complex step (exact to rounding) when the callable accepts complex
  arguments and agrees with a central difference, else by Richardson-extrapolated central
  differences (step `step`, default 1e-4 (b - a)); without d2, d2C/ds2 by Richardson differences of
  dC/ds.  User derivatives are checked against differences at construction.
- `Curve(("x(s)", "y(s)", "z(s)"), s_range)`: the three coordinates as expression strings in `s`
  (mbdsim.expressions grammar); dC/ds and d2C/ds2 are the exact symbolic derivatives, and the
  parsed expressions are kept in `curve.expressions` (for the compiled core, issue 29).
- `Spline(points, closed=False)`: C2 cubic spline (scipy CubicSpline, not-a-knot ends; periodic when
  closed) through the points, parametrised by cumulative chord length [m] (s ~ arc length), with
  exact derivatives.

On the compiled core an expression curve runs as compiled programs, a Spline as its cubics, and a callable
curve as a spline table of it built to the run's tolerance (mbdsim.system.pathtable).

s_range = (a, b): the parameter interval (used to find the initial parameter and the difference
steps); a closed curve is periodic with period b - a.  Beyond the interval of an open curve the
callable is evaluated as given and a spline is extrapolated by its end cubics: keep the motion of
the constrained point within the curve (the integrator's trial stages may probe beyond it).
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import ModelError
from ._check import scalar
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import Array, Vector

ENTITY = "curve"


def _point(fn, s, field):
    try:
        p = np.asarray(fn(s), dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise ModelError(ENTITY, field, f"callable failed at s={s!r}: {exc}") from None
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ModelError(ENTITY, field, f"callable must return 3 finite numbers, got {p!r} at s={s!r}")
    return p


def _richardson(fn, s, h):
    """Central difference of fn at s with one Richardson extrapolation (error O(h^4))."""
    d = lambda k: (np.asarray(fn(s + k), float) - np.asarray(fn(s - k), float)) / (2 * k)  # noqa: E731
    return (4 * d(h / 2) - d(h)) / 3


def _expression_curve(texts, d1, d2):
    """(exprs, C, C', C'') of three coordinate expressions in s; exact symbolic derivatives."""
    from ..expressions import ExpressionError, parse
    if d1 is not None or d2 is not None:
        raise ModelError(ENTITY, "d1", "an expression curve takes its derivatives from the expressions: "
                         "leave d1 and d2 out")
    exprs = []
    for axis, text in zip("xyz", texts):
        try:
            exprs.append(parse(text, ("s",)))
        except ExpressionError as exc:
            raise ModelError(ENTITY, f"function[{axis}]", str(exc)) from None
    try:
        e1 = [e.derivative("s") for e in exprs]
        e2 = [e.derivative("s") for e in e1]
    except ExpressionError as exc:
        raise ModelError(ENTITY, "function", str(exc)) from None

    def vec(es):
        return lambda s: np.array([e.evaluate(s) for e in es])
    return tuple(exprs), vec(exprs), vec(e1), vec(e2)


class Curve:
    """Parametric curve s -> C(s) [m] in ground at t=0: a callable s -> 3 numbers, or three expression
    strings in s (x, y, z [m]; exact symbolic derivatives); see the module docstring."""

    def __init__(self, function, s_range, d1=None, d2=None, closed=False, step=None):
        self.expressions = None
        if isinstance(function, (tuple, list)) and len(function) == 3 and all(isinstance(f, str) for f in function):
            self.expressions, function, d1, d2 = _expression_curve(function, d1, d2)
        if not callable(function):
            raise ModelError(ENTITY, "function", f"expected a callable s -> point, got {function!r}")
        try:
            a, b = (float(x) for x in s_range)
        except (TypeError, ValueError):
            raise ModelError(ENTITY, "s_range", f"expected (start, end), got {s_range!r}") from None
        if not (np.isfinite(a) and np.isfinite(b) and b > a):
            raise ModelError(ENTITY, "s_range", f"needs finite start < end, got {s_range!r}")
        for name, f in (("d1", d1), ("d2", d2)):
            if f is not None and not callable(f):
                raise ModelError(ENTITY, name, f"expected a callable s -> vector, got {f!r}")
        self.s_range, self.closed = (a, b), bool(closed)
        self.h = (b - a) * 1e-4 if step is None else scalar(ENTITY, "step", step, minimum=0.0, strict=True)
        self._f = function
        probe = np.linspace(a, b, 7)[1:-1]
        for s in (a, *probe, b):
            _point(function, s, "function")
        self._d1 = d1 if d1 is not None else self._numeric_d1(probe)
        self._d2 = d2
        self._check(d1, d2, probe)

    # ------------------------------------------------------------------ evaluation
    def point(self, s: float) -> np.ndarray:
        """C(s) [m], ground axes at t=0."""
        return np.asarray(self._f(s), dtype=float).reshape(3)

    def derivatives(self, s: float) -> tuple[Array, Array, Array]:
        """(C, dC/ds, d2C/ds2) at the parameter s."""
        d1 = np.asarray(self._d1(s), dtype=float).reshape(3)
        d2 = self._d2(s) if self._d2 is not None else _richardson(self._d1, s, self.h)
        return self.point(s), d1, np.asarray(d2, dtype=float).reshape(3)

    def nearest(self, p: Vector) -> float:
        """Parameter of the curve point nearest to p [m] (sampling plus bounded refinement)."""
        import scipy.optimize as so
        a, b = self.s_range
        ss = np.linspace(a, b, 401)
        d2 = [float(np.sum((self.point(s) - p) ** 2)) for s in ss]
        k = int(np.argmin(d2))
        lo, hi = ss[max(k - 1, 0)], ss[min(k + 1, len(ss) - 1)]
        r = so.minimize_scalar(lambda s: float(np.sum((self.point(s) - p) ** 2)), bounds=(lo, hi),
                               method="bounded", options={"xatol": 1e-12 * max(1.0, b - a)})
        s = float(r.x) if r.fun <= d2[k] else float(ss[k])
        for _ in range(4):   # Newton on C'.(C - p) = 0: the distance alone fixes s to sqrt(eps) only
            C, C1, C2 = self.derivatives(s)
            den = float(C1 @ C1 + C2 @ (C - p))
            if den <= 0:
                break
            s_new = s - float(C1 @ (C - p)) / den
            if not (lo <= s_new <= hi):
                break
            s = s_new
        return s

    # ------------------------------------------------------------------ derivatives
    def _numeric_d1(self, probe):
        f, h = self._f, self.h

        def complex_step(s):
            eps = 1e-30
            return np.asarray(f(s + 1j * eps), dtype=complex).reshape(3).imag / eps

        try:
            with warnings.catch_warnings():   # a callable that drops the imaginary part fails the check
                warnings.simplefilter("error", np.exceptions.ComplexWarning)
                ok = all(np.allclose(complex_step(s), _richardson(f, s, h), rtol=1e-6, atol=1e-6 * self._scale(s))
                         for s in probe)
        except Exception:  # noqa: BLE001 - any failure of the callable on complex input
            ok = False
        return complex_step if ok else (lambda s: _richardson(f, s, h))

    def _scale(self, s):
        a, b = self.s_range
        return max(1.0, float(np.linalg.norm(self.point(s)))) / max(b - a, 1e-12)

    def _check(self, d1, d2, probe):
        for name, given, ref in (("d1", d1, lambda s: _richardson(self._f, s, self.h)),
                                 ("d2", d2, lambda s: _richardson(self._d1, s, self.h))):
            if given is None:
                continue
            for s in probe:
                g = _point(given, s, name)
                if not np.allclose(g, ref(s), rtol=1e-5, atol=1e-5 * self._scale(s) * (1 + (name == "d2"))):
                    raise ModelError(ENTITY, name, f"does not match the numerical derivative at s={s:.6g}: "
                                     f"{g} vs {ref(s)}")

    def __repr__(self) -> str:
        return f"Curve(s in [{self.s_range[0]:.6g}, {self.s_range[1]:.6g}]{', closed' if self.closed else ''})"


class Spline(Curve):
    """C2 cubic spline through points (n, 3) [m] in ground at t=0; s = cumulative chord length [m]."""

    def __init__(self, points, closed=False):
        try:
            P = np.asarray(points, dtype=float)
        except (TypeError, ValueError):
            raise ModelError("spline", "points", f"expected an (n, 3) array of points, got {points!r}") from None
        if P.ndim != 2 or P.shape[1] != 3 or len(P) < 3 or not np.all(np.isfinite(P)):
            raise ModelError("spline", "points", f"expected at least 3 finite points (n, 3), got shape {P.shape}")
        closed = bool(closed)
        if closed and np.linalg.norm(P[-1] - P[0]) > 0:
            P = np.vstack([P, P[:1]])
        chord = np.linalg.norm(np.diff(P, axis=0), axis=1)
        if np.any(chord <= 1e-12 * max(1.0, float(np.abs(P).max()))):
            k = int(np.argmin(chord))
            raise ModelError("spline", "points", f"consecutive points {k} and {k + 1} coincide")
        u = np.concatenate([[0.0], np.cumsum(chord)])
        self.points = P
        from scipy.interpolate import CubicSpline
        self._cs = CubicSpline(u, P, bc_type="periodic" if closed else "not-a-knot")
        self._c1, self._c2 = self._cs.derivative(1), self._cs.derivative(2)
        self.s_range, self.closed, self.h = (0.0, float(u[-1])), closed, float(u[-1]) * 1e-4
        self._f, self._d1, self._d2 = self._cs, self._c1, self._c2

    def point(self, s: float) -> np.ndarray:
        return self._cs(s)

    def derivatives(self, s: float) -> tuple[Array, Array, Array]:
        return self._cs(s), self._c1(s), self._c2(s)

    def __repr__(self) -> str:
        return f"Spline({len(self.points)} points, length ~{self.s_range[1]:.6g} m{', closed' if self.closed else ''})"
