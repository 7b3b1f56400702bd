"""A Python-callable point-on-curve curve tabulated as the compiled core's cubic spline (issue 29).

`tabulate(curve, rtol, atol)` samples `mb.Curve(function, (a, b))` at n + 1 equally spaced knots and builds
the piecewise cubic through the points whose second derivative is the linear interpolant of d2C/ds2 at the
knots (6th-order central differences of C with a fixed step of 1e-3 (b - a): no eps / h^2 rounding of an
interpolating spline's C'', which would floor it near 1e-8 of |C| for fine tables), in the layout
`system.pathcoords` packs for an `mb.Spline` (curve kind 1), so the kernels (solvers.pathcoord) never call
Python. C and C'' are continuous; dC/ds jumps at a knot by O(h^3). n starts at N0 segments and grows by
powers of two (the next one the h^2 fall of the error predicts to suffice) until, at the midpoints of the
segments (where a cubic's error peaks) and at the knots, for a probe of up to PROBES of them, the table
matches the callable's C, dC/ds and d2C/ds2 (curve.derivatives: the user's d1/d2, else its complex step /
Richardson differences) to

    |C_table - C| <= TABLE_FRACTION (rtol max|C| + atol),   |C_table^(k) - C^(k)| <= TABLE_FRACTION rtol max|C^(k)|

(k = 1, 2; maxima over the probe; rtol and atol those of the run's step control: under "auto" the
requested ones / 20, i.e. 5e-9 and 5e-11 [m] at the defaults); the errors fall as h^4, h^3 and h^2, so
d2C/ds2 sets n: about L / sqrt(8 TABLE_FRACTION rtol) segments for a helix over L rad (7 rad at the
defaults: 2^16, 0.5 s to build). At most MAX_SEGMENTS (then the best table is used, with a warning naming
the constraint). Beyond [a, b] an open table extrapolates by its end cubics, like a Spline.
"""
from __future__ import annotations

import warnings

import numpy as np

N0, MAX_SEGMENTS, PROBES, TABLE_FRACTION, H_FRACTION = 64, 2 ** 18, 257, 1.0, 1e-3


def _points(curve, s) -> np.ndarray:
    """C at the parameters s (n, 3): one vectorised call of the user's function when it takes arrays, else
    one call per point."""
    f = curve._f
    try:
        with np.errstate(all="ignore"):
            p = np.asarray(f(s), dtype=float)
        if p.shape == (3, len(s)):
            return p.T.copy()
        if p.shape == (len(s), 3):
            return p.copy()
    except Exception:  # noqa: BLE001 - a callable of a float only: point by point below
        pass
    return np.array([curve.point(float(x)) for x in s])


def _second_derivatives(curve, s) -> np.ndarray:
    """d2C/ds2 at the knots s (n, 3): the 6th-order central difference of C with the fixed step
    H_FRACTION (b - a) (vectorised with the points; error about 1e-11 of max|C| / H^2 [rounding], far below
    the table's), and the curve's own derivatives at the knots whose stencil would leave [a, b]."""
    a, b = curve.s_range
    H = H_FRACTION * (b - a)
    w = (-49.0 / 18.0, 3.0 / 2.0, -3.0 / 20.0, 1.0 / 90.0)
    M = w[0] * _points(curve, s)
    for k in (1, 2, 3):
        M += w[k] * (_points(curve, s + k * H) + _points(curve, s - k * H))
    M /= H * H
    if not curve.closed:
        ends = np.flatnonzero((s - 3 * H < a) | (s + 3 * H > b))
        for i in ends:
            M[i] = curve.derivatives(float(s[i]))[2]
    return M


def _table(s, P, M):
    """The piecewise cubic (scipy PPoly, coefficients (4, n, 3) of u^3 .. u^0, u = s - s_i) with the values
    P and second derivatives M at the knots s: c'' the linear interpolant of M (continuous), c through P."""
    from scipy.interpolate import PPoly
    h = np.diff(s)[:, None]
    c = np.empty((4, len(s) - 1, 3))
    c[0] = (M[1:] - M[:-1]) / (6.0 * h)
    c[1] = M[:-1] / 2.0
    c[2] = (P[1:] - P[:-1]) / h - h * (2.0 * M[:-1] + M[1:]) / 6.0
    c[3] = P[:-1]
    return PPoly(c, s, extrapolate=True)


def tabulate(curve, rtol=None, atol=None, name="curve"):
    """(the table: scipy PPoly of C(s) [m], number of segments) of a Python-callable Curve; see the module
    docstring."""
    rtol = 1e-7 if rtol is None else float(rtol)
    atol = 1e-9 if atol is None else float(atol)
    a, b = curve.s_range
    n, best = N0, None
    while True:
        s = np.linspace(a, b, n + 1)
        table = _table(s, _points(curve, s), _second_derivatives(curve, s))
        err = _error(curve, table, s, rtol, atol)
        if best is None or err < best[0]:
            best = (err, table, n)
        if err <= 1.0:
            return table, n
        if 2 * n > MAX_SEGMENTS:
            warnings.warn(f"point-on-curve '{name}': the table of the Python-callable curve reaches "
                          f"{best[0]:.2g} times its tolerance with {best[2]} segments: give the curve as "
                          "expression strings or an mb.Spline for a tighter fit", stacklevel=3)
            return best[1], best[2]
        # the error falls as h^2: the next power of two that should reach the tolerance (at least twice n)
        n = min(MAX_SEGMENTS, n * 2 ** max(1, int(np.ceil(np.log2(1.2 * np.sqrt(err))))))


def _error(curve, cs, s, rtol, atol) -> float:
    """Largest ratio of the table's error to its tolerance over the probe (midpoints and knots)."""
    n = len(s) - 1
    k = np.unique(np.linspace(0, n - 1, min(PROBES, n)).astype(int))
    probe = np.concatenate([(s[k] + s[k + 1]) / 2, s[k]])
    ref = [np.array(x) for x in zip(*(curve.derivatives(float(x)) for x in probe))]   # C, C', C'' (m, 3)
    worst, scale, span = 0.0, 0.0, float(s[-1] - s[0])
    for order in range(3):
        got = cs(probe, order)   # (a derivative's scale at least the previous one's over the range: a line's C'' = 0)
        scale = max(float(np.max(np.linalg.norm(ref[order], axis=1))), scale / span if order else 0.0)
        tol = TABLE_FRACTION * (rtol * scale + (atol if order == 0 else 0.0)) + 1e-300
        worst = max(worst, float(np.max(np.linalg.norm(got - ref[order], axis=1))) / tol)
    return worst
