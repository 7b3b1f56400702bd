"""Adams-style function library: STEP, STEP5, HAVSIN, IMPACT, BISTOP, POLY, SHF, tabulated splines.

Every function is vectorised over numpy arrays (all arguments broadcast) and returns a float
for scalar input, an ndarray otherwise. The smooth step and harmonic functions take a keyword
``order`` (0 = value, n = n-th derivative with respect to the first argument ``x``), which is
what :mod:`mbdsim.expressions` uses for exact symbolic derivatives; ``STEP_d`` etc. are the
first derivatives. Definitions follow the MSC Adams Solver function reference (the same
definitions are reproduced in the SOLIDWORKS Motion help, "IMPACT", "BISTOP" pages).

Units: the library is unit-agnostic; ``x`` carries the unit of the independent variable
(s when it is time t, m or rad when it is a displacement), ``h0``/``h1``/``a``/``b`` the unit
of the output, ``w`` rad per unit of ``x``; IMPACT/BISTOP return a force [N] (or torque [N m])
for ``k`` in N/m^e and ``cmax`` in N s/m.
"""
from __future__ import annotations

from dataclasses import dataclass
from math import factorial, pi

import numpy as np
from numpy.polynomial import polynomial as _P
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from numpy.typing import ArrayLike
    from typing import Any

__all__ = [
    "step", "step5", "havsin", "poly", "shf", "impact", "bistop", "akispl",
    "step_d", "step5_d", "havsin_d", "poly_d", "shf_d", "impact_d", "bistop_d",
    "impact_partials", "bistop_partials", "Akima", "CubicSplineTable", "LibraryFunction", "LIBRARY",
    "STEP", "STEP5", "HAVSIN", "POLY", "SHF", "IMPACT", "BISTOP", "AKISPL",
    "STEP_d", "STEP5_d", "HAVSIN_d", "POLY_d", "SHF_d", "IMPACT_d", "BISTOP_d",
]


def _out(value, *inputs):
    """float for all-scalar inputs, ndarray otherwise."""
    if any(np.ndim(a) for a in inputs):
        return np.asarray(value, dtype=float)
    return float(value)


def _check_order(order) -> int:
    if int(order) != order or order < 0:
        raise ValueError(f"derivative order must be a non-negative integer, got {order!r}")
    return int(order)


_STEP3 = np.array([0.0, 0.0, 3.0, -2.0])               # s^2 (3 - 2 s)
_STEP5 = np.array([0.0, 0.0, 0.0, 10.0, -15.0, 6.0])   # s^3 (10 - 15 s + 6 s^2)


def _poly_step(coef, x, x0, h0, x1, h1, order):
    order = _check_order(order)
    xa, x0a, h0a, x1a, h1a = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (x, x0, h0, x1, h1)))
    if np.any(x1a <= x0a):
        raise ValueError(f"step functions need x0 < x1, got x0={x0!r}, x1={x1!r}")
    dx = x1a - x0a
    s = (xa - x0a) / dx
    c = _P.polyder(coef, order) if order else coef
    inside = (h1a - h0a) * _P.polyval(s, c) / dx**order
    if order == 0:
        inside = inside + h0a
        out = np.where(xa <= x0a, h0a, np.where(xa >= x1a, h1a, inside))
    else:
        out = np.where((xa <= x0a) | (xa >= x1a), 0.0, inside)
    return _out(out, x, x0, h0, x1, h1)


def step(x: ArrayLike, x0: ArrayLike, h0: ArrayLike, x1: ArrayLike, h1: ArrayLike, order: ArrayLike = 0) -> Any:
    """Adams STEP: cubic smooth step from h0 at x <= x0 to h1 at x >= x1 (C1).

    STEP = h0 + (h1 - h0) * s^2 * (3 - 2 s),  s = (x - x0)/(x1 - x0), for x0 < x < x1.
    ``order`` = n returns d^n STEP / dx^n (piecewise polynomial, 0 outside (x0, x1)). Needs x0 < x1.
    """
    return _poly_step(_STEP3, x, x0, h0, x1, h1, order)


def step5(x: ArrayLike, x0: ArrayLike, h0: ArrayLike, x1: ArrayLike, h1: ArrayLike, order: ArrayLike = 0) -> Any:
    """Adams STEP5: quintic smooth step (C2): h0 + (h1 - h0) * (10 s^3 - 15 s^4 + 6 s^5), s as in STEP."""
    return _poly_step(_STEP5, x, x0, h0, x1, h1, order)


def havsin(x: ArrayLike, x0: ArrayLike, h0: ArrayLike, x1: ArrayLike, h1: ArrayLike, order: ArrayLike = 0) -> Any:
    """Adams HAVSIN: haversine step h0 + (h1 - h0) * (1 - cos(pi s)) / 2, s as in STEP (C1).

    Adams writes the same curve as (h0 + h1)/2 + (h1 - h0)/2 * sin(pi s - pi/2).
    The n-th derivative (n >= 1) inside (x0, x1) is -(h1 - h0)/2 * (pi/(x1 - x0))^n * cos(pi s + n pi/2).
    """
    order = _check_order(order)
    xa, x0a, h0a, x1a, h1a = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (x, x0, h0, x1, h1)))
    if np.any(x1a <= x0a):
        raise ValueError(f"HAVSIN needs x0 < x1, got x0={x0!r}, x1={x1!r}")
    dx = x1a - x0a
    u = pi * (xa - x0a) / dx
    dh = h1a - h0a
    if order == 0:
        out = np.where(xa <= x0a, h0a, np.where(xa >= x1a, h1a, h0a + dh * (1.0 - np.cos(u)) / 2.0))
    else:
        inside = -dh / 2.0 * (pi / dx) ** order * np.cos(u + order * pi / 2.0)
        out = np.where((xa <= x0a) | (xa >= x1a), 0.0, inside)
    return _out(out, x, x0, h0, x1, h1)


def poly(x: ArrayLike, x0: ArrayLike, *coefficients: ArrayLike, order: ArrayLike = 0) -> Any:
    """Adams POLY(x, x0, a0, a1, ..., an) = sum_j a_j (x - x0)^j (n <= 30 in Adams; any n here)."""
    order = _check_order(order)
    if not coefficients:
        raise ValueError("POLY needs at least one coefficient a0")
    u = np.asarray(x, dtype=float) - np.asarray(x0, dtype=float)
    out = np.zeros(np.broadcast_shapes(u.shape, *(np.shape(a) for a in coefficients)))
    for j in range(len(coefficients) - 1, order - 1, -1):        # Horner on the derivative
        out = out * u + np.asarray(coefficients[j], dtype=float) * (factorial(j) // factorial(j - order))
    return _out(out, x, x0, *coefficients)


def shf(x: ArrayLike, x0: ArrayLike, a: ArrayLike, w: ArrayLike, phi: ArrayLike, b: ArrayLike,
        order: ArrayLike = 0) -> Any:
    """Adams SHF (simple harmonic function): a * sin(w (x - x0) - phi) + b.

    w [rad per unit of x], phi [rad]. n-th derivative: a w^n sin(w (x - x0) - phi + n pi/2).
    """
    order = _check_order(order)
    arg = np.asarray(w, dtype=float) * (np.asarray(x, dtype=float) - x0) - phi + order * pi / 2.0
    out = np.asarray(a, dtype=float) * np.asarray(w, dtype=float) ** order * np.sin(arg)
    if order == 0:
        out = out + b
    return _out(out, x, x0, a, w, phi, b)


def _check_contact(k, e, cmax, d):
    if np.any(np.asarray(k) < 0) or np.any(np.asarray(cmax) < 0):
        raise ValueError(f"contact stiffness k and damping cmax must be >= 0, got k={k!r}, cmax={cmax!r}")
    if np.any(np.asarray(e) <= 0) or np.any(np.asarray(d) <= 0):
        raise ValueError(f"contact exponent e and penetration d must be > 0, got e={e!r}, d={d!r}")


def _one_sided(p, v, k, e, c):
    """Force k p^e - c v of a penetration p >= 0 (rate dp/dt = -v) and its partials, clamped at >= 0."""
    pc = np.maximum(p, 0.0)
    raw = k * pc**e - c * v
    on = (p > 0) & (raw > 0)
    return np.where(on, raw, 0.0), on


def impact_partials(x, xdot, x1, k, e, cmax, d):
    """IMPACT and its partial derivatives: (force, dF/dx, dF/dxdot), all vectorised."""
    _check_contact(k, e, cmax, d)
    x, xdot, x1 = (np.asarray(a, dtype=float) for a in (x, xdot, x1))
    c = step(x, x1 - d, cmax, x1, 0.0)
    f, on = _one_sided(x1 - x, xdot, k, e, c)
    p = np.maximum(x1 - x, 0.0)
    dfdx = np.where(on, -k * e * np.where(on, p, 1.0) ** (e - 1.0) - step(x, x1 - d, cmax, x1, 0.0, order=1) * xdot, 0.0)
    dfdv = np.where(on, -np.asarray(c), 0.0)
    return tuple(_out(a, x, xdot, x1, k, e, cmax, d) for a in (f, dfdx, dfdv))


def impact(x: ArrayLike, xdot: ArrayLike, x1: ArrayLike, k: ArrayLike, e: ArrayLike, cmax: ArrayLike,
           d: ArrayLike) -> Any:
    """Adams IMPACT: one-sided compliant contact force that acts when x < x1.

    IMPACT = max(0, k (x1 - x)^e - STEP(x, x1 - d, cmax, x1, 0) * xdot)  for x < x1,
           = 0                                                            for x >= x1.
    The damping coefficient ramps from 0 at first contact to cmax at penetration d, so the force
    is continuous at contact onset; the max(0, .) keeps it from pulling (never negative).
    k >= 0 [N/m^e], e > 0 (e > 1 stiffening), cmax >= 0 [N s/m], d > 0 [m].
    """
    return impact_partials(x, xdot, x1, k, e, cmax, d)[0]


def impact_d(x, xdot, x1, k, e, cmax, d):
    """Partial derivative d IMPACT / dx at fixed xdot (zero where the force is zero)."""
    return impact_partials(x, xdot, x1, k, e, cmax, d)[1]


def bistop_partials(x, xdot, x1, x2, k, e, cmax, d):
    """BISTOP and its partial derivatives: (force, dF/dx, dF/dxdot), all vectorised."""
    if np.any(np.asarray(x2) <= np.asarray(x1)):
        raise ValueError(f"BISTOP needs x1 < x2, got x1={x1!r}, x2={x2!r}")
    lo = impact_partials(x, xdot, x1, k, e, cmax, d)
    # upper wall: mirror image of IMPACT about x2 (x -> -x, xdot -> -xdot, force -> -force)
    hi = impact_partials(-np.asarray(x, dtype=float), -np.asarray(xdot, dtype=float), -np.asarray(x2, dtype=float),
                         k, e, cmax, d)
    f, dfdx, dfdv = lo[0] - hi[0], lo[1] + hi[1], lo[2] + hi[2]
    return tuple(_out(a, x, xdot, x1, x2, k, e, cmax, d) for a in (f, dfdx, dfdv))


def bistop(x: ArrayLike, xdot: ArrayLike, x1: ArrayLike, x2: ArrayLike, k: ArrayLike, e: ArrayLike, cmax: ArrayLike,
           d: ArrayLike) -> Any:
    """Adams BISTOP: two-sided gap element, free for x1 <= x <= x2.

    BISTOP = max(k (x1 - x)^e - STEP(x, x1 - d, cmax, x1, 0) * xdot, 0)   for x < x1,
           = 0                                                           for x1 <= x <= x2,
           = min(-k (x - x2)^e - STEP(x, x2, 0, x2 + d, cmax) * xdot, 0) for x > x2.
    Needs x1 < x2; parameters as IMPACT.
    """
    return bistop_partials(x, xdot, x1, x2, k, e, cmax, d)[0]


def bistop_d(x, xdot, x1, x2, k, e, cmax, d):
    """Partial derivative d BISTOP / dx at fixed xdot."""
    return bistop_partials(x, xdot, x1, x2, k, e, cmax, d)[1]


class _Table:
    """Common behaviour of tabulated-data splines: call(x, order=0), derivative(n)."""

    _interp = None

    def __call__(self, x, order=0):
        order = _check_order(order)
        return _out(self._interp(np.asarray(x, dtype=float), nu=order), x)

    def derivative(self, order: int = 1) -> Any:
        """Callable x -> d^order y / dx^order."""
        return lambda x: self(x, order)

    @property
    def domain(self):
        """(x_min, x_max) of the data."""
        return float(self.xs[0]), float(self.xs[-1])


class Akima(_Table):
    """Akima spline through (xs, ys), like Adams AKISPL (C1; its 2nd derivative jumps at the knots).

    xs strictly increasing (>= 2 points). Outside the data the end polynomials are extrapolated
    (extrapolate=True) or NaN is returned (False). ``method="makima"`` gives scipy's modified Akima.
    """

    def __init__(self, xs, ys, *, extrapolate=True, method="akima"):
        self.xs, self.ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        _check_table(self.xs, self.ys)
        from scipy.interpolate import Akima1DInterpolator, CubicSpline   # lazy: keeps `import mbdsim` fast
        if self.xs.size == 2:                         # scipy needs >= 2 points; 2 points = line
            self._interp = CubicSpline(self.xs, self.ys, bc_type="natural", extrapolate=extrapolate)
        else:
            self._interp = Akima1DInterpolator(self.xs, self.ys, method=method, extrapolate=extrapolate)


class CubicSplineTable(_Table):
    """C2 cubic spline through (xs, ys) (scipy CubicSpline; bc_type "not-a-knot", "natural", "clamped", "periodic")."""

    def __init__(self, xs, ys, *, bc_type="not-a-knot", extrapolate=True):
        self.xs, self.ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        _check_table(self.xs, self.ys)
        from scipy.interpolate import CubicSpline
        self._interp = CubicSpline(self.xs, self.ys, bc_type=bc_type, extrapolate=extrapolate)


def _check_table(xs, ys):
    if xs.ndim != 1 or xs.shape != ys.shape or xs.size < 2:
        raise ValueError(f"table needs 1-D xs and ys of equal length >= 2, got shapes {xs.shape} and {ys.shape}")
    if not np.all(np.diff(xs) > 0):
        raise ValueError("table xs must be strictly increasing")


def akispl(x: ArrayLike, xs: ArrayLike, ys: ArrayLike, order: ArrayLike = 0) -> Any:
    """Adams AKISPL(x, 0, spline, iord): Akima interpolation of (xs, ys) at x; order 0, 1 or 2."""
    if order not in (0, 1, 2):
        raise ValueError(f"AKISPL order must be 0, 1 or 2, got {order!r}")
    return Akima(xs, ys)(x, order)


def _d1(fn):
    def first_derivative(*args):
        return fn(*args, order=1)
    first_derivative.__name__ = fn.__name__ + "_d"
    first_derivative.__doc__ = f"d/dx of {fn.__name__.upper()} (first argument); see {fn.__name__}."
    return first_derivative


step_d, step5_d, havsin_d, poly_d, shf_d = (_d1(f) for f in (step, step5, havsin, poly, shf))

STEP, STEP5, HAVSIN, POLY, SHF, IMPACT, BISTOP, AKISPL = step, step5, havsin, poly, shf, impact, bistop, akispl
STEP_d, STEP5_d, HAVSIN_d, POLY_d, SHF_d, IMPACT_d, BISTOP_d = step_d, step5_d, havsin_d, poly_d, shf_d, impact_d, bistop_d


@dataclass(frozen=True)
class LibraryFunction:
    """A library function usable in expressions: fn(x, *params, order=n) = d^n/dx^n of the function."""

    name: str
    fn: object
    min_args: int
    max_args: int | None     # None: unbounded


def _contact_fn(fn, fn_d, name):
    def f(x, *params, order=0):
        if order == 0:
            return fn(x, *params)
        if order == 1:
            return fn_d(x, *params)
        raise ValueError(f"{name} has derivatives of order 0 and 1 (with respect to x) only")
    f.__name__ = name.lower()
    return f


# the functions mbdsim.expressions accepts (upper case; lower-case aliases are added there)
LIBRARY = {
    "IMPACT": LibraryFunction("IMPACT", _contact_fn(impact, impact_d, "IMPACT"), 7, 7),
    "BISTOP": LibraryFunction("BISTOP", _contact_fn(bistop, bistop_d, "BISTOP"), 8, 8),
    "STEP": LibraryFunction("STEP", step, 5, 5),
    "STEP5": LibraryFunction("STEP5", step5, 5, 5),
    "HAVSIN": LibraryFunction("HAVSIN", havsin, 5, 5),
    "POLY": LibraryFunction("POLY", poly, 3, None),
    "SHF": LibraryFunction("SHF", shf, 6, 6),
}
