"""SPLINE statements of an .adm dataset and the AKISPL / CUBSPL functions that read them.

SPLINE/id, X = x1, ..., xn, Y = y1, ..., yn [, LINEAR_EXTRAPOLATE]: one curve (a family of curves in z,
FILE= and channels are refused).  `AKISPL(x, z, id[, iord])` interpolates it by Akima's method,
`CUBSPL(x, z, id[, iord])` by a C2 cubic spline (not-a-knot ends), iord = the derivative order 0..2.
Beyond the data Adams extrapolates by the parabola through the first (last) three points, or by the
line through the first (last) two with LINEAR_EXTRAPOLATE (Adams View's spline dialog): the table
carries these polynomials as its end pieces, so the compiled interpreter (mbdsim.system.exprvm, a
piecewise cubic by scipy's PPoly layout) and Python evaluate the same function everywhere.

The numbers of a SPLINE are not converted to SI: the argument of AKISPL arrives in the dataset's units
(measures are divided back, see adm_expr) and the function's result is scaled as a whole.  The table is
registered in `model.tables` under the name AKISPL_<id> / CUBSPL_<id>, which the load expressions call.
"""
from __future__ import annotations

import numpy as np

from ..functions import _Table

KINDS = ("AKISPL", "CUBSPL")


class AdamsSpline(_Table):
    """Adams' interpolation of (xs, ys): `kind` "AKISPL" (Akima) or "CUBSPL" (cubic, not-a-knot), with
    Adams' parabolic (or `linear`) extrapolation as end pieces; call(x, order=0) as mbdsim's tables."""

    def __init__(self, xs, ys, kind: str = "AKISPL", linear: bool = False):
        from scipy.interpolate import Akima1DInterpolator, CubicSpline, PPoly
        self.xs, self.ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        self.kind, self.linear = kind, bool(linear)
        inner = (Akima1DInterpolator(self.xs, self.ys) if kind == "AKISPL"
                 else CubicSpline(self.xs, self.ys, bc_type="not-a-knot"))
        h = self.xs[-1] - self.xs[0]
        lo = _end_poly(self.xs[:3], self.ys[:3], self.linear, self.xs[0] - h)    # about its own left end
        hi = _end_poly(self.xs[-3:], self.ys[-3:], self.linear, self.xs[-1], right=True)
        c = np.column_stack([lo, inner.c, hi])
        x = np.concatenate([[self.xs[0] - h], inner.x, [self.xs[-1] + h]])
        self._interp = PPoly(c, x, extrapolate=True)


def _end_poly(x3, y3, linear, at, right=False):
    """Cubic coefficients (PPoly column, highest power first, in powers of x - at) of the parabola
    through three points, or of the line through the two at the end (`right`: the last two)."""
    if linear:
        (x0, x1), (y0, y1) = (x3[-2:], y3[-2:]) if right else (x3[:2], y3[:2])
        b = (y1 - y0) / (x1 - x0)
        return np.array([0.0, 0.0, b, y0 + b * (at - x0)])
    # Newton form about x0: y0 + d1 (x - x0) + d2 (x - x0)(x - x1), re-expanded about `at`
    x0, x1, x2 = x3
    d1 = (y3[1] - y3[0]) / (x1 - x0)
    d2 = ((y3[2] - y3[1]) / (x2 - x1) - d1) / (x2 - x0)
    u0, u1 = x0 - at, x1 - at      # x - x0 = u - u0, x - x1 = u - u1 with u = x - at
    return np.array([0.0, d2, d1 - d2 * (u0 + u1), y3[0] - d1 * u0 + d2 * u0 * u1])


def spline(imp, st) -> None:
    """SPLINE/id, X=, Y= [, LINEAR_EXTRAPOLATE]: kept (imp.splines) for AKISPL / CUBSPL."""
    ys_args = [x for x in st.args if x.key == "Y"]
    if len(ys_args) > 1:
        imp.fail(st, "Y", "a family of curves (several Y = z, y1, ... lists) is not supported; mbdsim reads "
                 "one curve", ys_args[1].line)
    a, fl = imp.args(st, ("X", "Y", "FILE", "CHANNEL", "BLOCK"), ("LINEAR_EXTRAPOLATE",))
    for key in ("FILE", "CHANNEL", "BLOCK"):
        if key in a:
            imp.fail(st, key, "a SPLINE read from a file is not supported; give X= and Y=", a[key].line)
    xs, ys = imp.nums(st, a, "X"), imp.nums(st, a, "Y")
    if xs is None or ys is None:
        imp.fail(st, "X" if xs is None else "Y", "is required for a SPLINE")
    if len(xs) != len(ys):
        imp.fail(st, "Y", f"has {len(ys)} values for {len(xs)} X values", a["Y"].line)
    if len(xs) < 3:
        imp.fail(st, "X", f"needs at least 3 points (Adams: 4), got {len(xs)}", a["X"].line)
    if not np.all(np.diff(xs) > 0):
        imp.fail(st, "X", "values must be strictly increasing", a["X"].line)
    imp.splines[st.id] = (np.array(xs), np.array(ys), "LINEAR_EXTRAPOLATE" in fl)


def table_name(imp, st, line, sid: int, kind: str) -> str:
    """The name of the table of SPLINE/sid interpolated by `kind` (registered in model.tables on first use)."""
    from ..errors import ModelFileError
    if sid not in imp.splines:
        raise ModelFileError(st.label, "FUNCTION", f"{kind}(..., {sid}): no SPLINE/{sid} in the dataset",
                             imp.source, line)
    name = f"{kind}_{sid}"
    tables = imp.model.__dict__.setdefault("tables", {})
    if name not in tables:
        xs, ys, linear = imp.splines[sid]
        tables[name] = AdamsSpline(xs, ys, kind, linear)
    return name
