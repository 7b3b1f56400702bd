"""Extrema and level crossings of a Result's signal refined on the dense output, a grid of times per call.

A scalar search (Brent) takes one `Result.at` per probe: about 25 dense-output evaluations per measure,
each paying the Python cost of a Result.  Here each level evaluates GRID times in ONE `res.at(times)`
call (the dense output of a step is redone once for all the times inside it), and a local polynomial
through the grid values locates the extremum or the root far below the grid spacing.  Result.maximum /
Result.minimum and the studies' measures use `extremum`; the studies' crossing measures `first_crossing`:

- extremum: the vertex of the quartic through the best sample k and its two neighbours on each side (a
  parabola at the ends) centres the first grid, +-REFINE_HALF of a sample step wide (the whole bracket
  [t_(k-1), t_(k+1)] when that grid's best point is at its edge); then the vertex of the quartic through
  the best grid point and its neighbours centres the next level, +-REFINE_HALF grid spacings wide.  Once two successive estimates agree within the
  finer spacing and the value there is the one the polynomial predicted (FIT_RTOL) and the best found,
  the search ends: two calls for a smooth, resolved peak (value to round-off).  Otherwise (a kink, a poorly resolved peak) the window keeps narrowing
  around the best point, +-1 grid spacing per level, to XTOL or MAX_LEVELS.
- crossing: a bracket with a sign change is always kept; the cubic through the four samples around the
  first sign change estimates the root and centres the first grid (+-REFINE_HALF of the sample step),
  the cubic through the four grid points around the sign change gives the next estimate, and two
  successive estimates within the grid spacing end the search (one call when the signal is smooth).

The best value ever evaluated wins, so a refinement is never worse than the samples; the conventions at
plateaus, ends and exact hits are those of Result.crossings, and the values agree with a Brent search on
the dense output to its tolerance (tests/test_study.py).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["extremum", "first_crossing", "GRID"]

GRID = 17                 # times per dense-output call (an odd number: the centre is a grid point)
REFINE_HALF = 1.0 / 8     # half-width of the next window, in grid spacings of the current one
MAX_LEVELS = 14
FIT_RTOL = 1e-6          # a smooth peak: the value at the estimate as predicted, to this fraction of the
#                          spread of the fitted values
NOISE = 1e-14            # relative round-off of a signal's values on the dense output
XTOL = 1e-14              # relative width [s / max(1, |t|)] below which a search stops


def _values(signal, res, ts) -> np.ndarray:
    """signal at the times ts (1-D float array)."""
    return np.asarray(signal(res.at(ts)), dtype=float).reshape(len(ts))


def _fit(ts, vals, idx, deg):
    """Polynomial of degree `deg` through the points idx, in the local coordinate x = (t - ts[i0]) / dt;
    returns (coefficients, highest power first, t0, dt) or None when the values are not finite.  With
    deg + 1 points the fit is the interpolating polynomial: one Vandermonde solve (np.polyfit's least
    squares otherwise)."""
    x0, dt = ts[idx[0]], ts[idx[1]] - ts[idx[0]]
    y = vals[idx]
    if dt <= 0 or not np.all(np.isfinite(y)):
        return None
    x = (ts[idx] - x0) / dt
    if len(idx) == deg + 1:
        try:
            return np.linalg.solve(np.vander(x, deg + 1), y), x0, dt
        except np.linalg.LinAlgError:
            pass
    return np.polyfit(x, y, deg), x0, dt


def _horner(coef, x: float) -> float:
    """Value of the polynomial coef (highest power first) at the scalar x (np.polyval's recurrence)."""
    y = 0.0
    for c in coef:
        y = y * x + c
    return y


def _roots(coef):
    """Roots of the polynomial coef (highest power first, the leading one nonzero): eigenvalues of the
    companion matrix, as np.roots computes them."""
    n = len(coef) - 1
    if n < 1:
        return np.array([])
    if n == 1:
        return np.array([-coef[1] / coef[0]])
    A = np.diag(np.ones(n - 1), -1)
    A[0, :] = -coef[1:] / coef[0]
    return np.linalg.eigvals(A)


def _real_roots_in(coef, lo, hi):
    if not np.any(coef[:-1]):
        return np.array([])
    r = _roots(coef) if coef[0] != 0 and coef[-1] != 0 else np.roots(coef)
    r = r[np.abs(r.imag) <= 1e-9 * np.maximum(1.0, np.abs(r.real))].real
    return r[(r >= lo) & (r <= hi)]


def _peak_estimate(ts, vals, j):
    """(time of the extremum, its value, the spread of the fitted values) of the local polynomial through
    grid point j and its neighbours (inside [ts[j-1], ts[j+1]]), or None."""
    n = len(ts)
    if not 0 < j < n - 1:
        return None
    idx = np.arange(j - 2, j + 3) if 2 <= j <= n - 3 else np.arange(j - 1, j + 2)
    fit = _fit(ts, vals, idx, len(idx) - 1)
    if fit is None:
        return None
    coef, x0, dt = fit
    xj = (ts[j] - x0) / dt
    cand = _real_roots_in(np.polyder(coef), xj - 1, xj + 1)
    if not len(cand):
        return None
    values = [_horner(coef, c) for c in cand.tolist()]
    k = int(np.argmax(values))
    x, top = float(cand[k]), values[k]
    y = vals[idx]
    return float(x0 + x * dt), float(top), float(y.max() - y.min())


def extremum(res, signal, sign: int) -> tuple[float, float]:
    """(time [s], value) of the maximum (sign +1) or minimum (-1) of signal(res) over the run.

    The first sample at the extreme value (up to 1e-12 relative: a plateau counts from its start) is
    refined on the dense output when it is an interior sample; otherwise it is returned as it is."""
    t = res.time
    y = sign * np.asarray(signal(res), dtype=float).reshape(len(t))
    tol = 1e-12 * np.max(np.abs(y))
    k = int(np.argmax(y >= np.max(y) - tol))
    if k in (0, len(y) - 1) or getattr(res, "_evaluate", None) is None:
        return float(t[k]), float(sign * y[k])
    lo, hi = float(t[k - 1]), float(t[k + 1])
    best_t, best_y = float(t[k]), float(y[k])
    # level 0: the polynomial through the samples themselves; the first grid spans +-1/8 sample step
    # around its vertex, or the whole bracket when the samples give no vertex or it proves wrong
    found = _peak_estimate(t, y, k)
    narrow = found is not None
    centre, half, previous = (found[0], REFINE_HALF * min(best_t - lo, hi - best_t), found[0]) if narrow \
        else (best_t, 0.5 * (hi - lo), None)
    for _ in range(MAX_LEVELS):
        ts = np.unique(np.clip(np.linspace(centre - half, centre + half, GRID), lo, hi))
        vals = sign * _values(signal, res, ts)
        j = int(np.argmax(vals))
        if vals[j] > best_y:
            best_t, best_y = float(ts[j]), float(vals[j])
        if narrow and j in (0, len(ts) - 1):     # the samples' estimate was off: search the bracket
            narrow, centre, half, previous = False, best_t, 0.5 * (hi - lo), None
            continue
        narrow = False
        spacing = float(np.min(np.diff(ts))) if len(ts) > 1 else 0.0
        if spacing <= XTOL * max(1.0, abs(best_t)):
            break
        found = _peak_estimate(ts, vals, j)
        est = None if found is None else found[0]
        if found is not None and previous is not None and abs(est - previous) <= spacing:
            val = sign * float(_values(signal, res, np.array([est]))[0])
            if val > best_y:
                best_t, best_y = est, val
            slack = FIT_RTOL * found[2] + NOISE * abs(val)
            if abs(val - found[1]) <= slack and val >= best_y - slack:
                break                  # the polynomial predicted the value: a smooth peak, found
            est = None                 # a kink: the polynomial misleads, narrow around the best point
        if est is None:
            centre, half, previous = best_t, spacing, None
        else:
            centre, half, previous = est, REFINE_HALF * spacing * (GRID - 1) / 2, est
    if best_y <= float(y[k]) + tol and (y[k - 1] >= y[k] - tol or y[k + 1] >= y[k] - tol):
        return float(t[k]), float(sign * y[k])    # a flat top keeps its first sample
    return best_t, sign * best_y


def first_crossing(res, signal, value: float, direction: int = 0) -> float:
    """Time [s] of the first crossing of `value` by signal(res) (direction +1 rising, -1 falling, 0 both);
    NaN when there is none.  The conventions of Result.crossings: a run that starts at the level has not
    crossed it; a sample exactly at the level counts when the signal arrives there."""
    t = res.time
    y = np.asarray(signal(res), dtype=float).reshape(len(t)) - value
    for k in range(len(y) - 1):
        a, b = y[k], y[k + 1]
        if a == 0.0 and k > 0 and y[k - 1] != 0.0 and _arrives(y, k, direction):
            return float(t[k])
        if a * b < 0 and (direction == 0 or np.sign(b - a) == np.sign(direction)):
            if getattr(res, "_evaluate", None) is None:
                return float(t[k] - a * (t[k + 1] - t[k]) / (b - a))
            return _bracketed_root(res, signal, value, float(t[k]), float(t[k + 1]), float(a), float(b),
                                   _root_estimate(t, y, k))
    if len(y) > 1 and y[-1] == 0.0 and y[-2] != 0.0 and (direction == 0 or np.sign(-y[-2]) == np.sign(direction)):
        return float(t[-1])
    return math.nan


def _arrives(y, k, direction) -> bool:
    """Whether the run at the level starting at sample k (k > 0) goes in `direction`."""
    if direction == 0:
        return True
    nz = np.flatnonzero(y[k + 1:])
    nxt = y[k + 1 + nz[0]] if len(nz) else 0.0
    return np.sign(nxt - y[k - 1]) == np.sign(direction) or (nxt == 0.0 and np.sign(-y[k - 1]) == np.sign(direction))


def _root_estimate(pts, fv, m):
    """Root in [pts[m], pts[m+1]] (a sign change) of the cubic through the four points around it, else the
    secant."""
    a, b, fa, fb = pts[m], pts[m + 1], fv[m], fv[m + 1]
    secant = float(a - fa * (b - a) / (fb - fa))
    if len(pts) < 4:
        return secant
    i0 = min(max(m - 1, 0), len(pts) - 4)
    idx = np.arange(i0, i0 + 4)
    if np.ptp(np.diff(pts[idx])) > 1e-9 * (pts[idx[-1]] - pts[idx[0]]):   # unequal spacing (bracket ends)
        return secant
    fit = _fit(pts, fv, idx, 3)
    if fit is None:
        return secant
    coef, x0, dt = fit
    r = _real_roots_in(coef, (a - x0) / dt, (b - x0) / dt)
    return float(x0 + r[0] * dt) if len(r) == 1 else secant


def _bracketed_root(res, signal, value, a, b, fa, fb, guess) -> float:
    """Root of signal - value in [a, b] (fa, fb of opposite signs): grids centred on the estimate, the
    first +-REFINE_HALF of the bracket around `guess` (from the samples)."""
    centre, half, previous = guess, REFINE_HALF * (b - a), guess
    for _ in range(MAX_LEVELS):
        ts = np.unique(np.clip(np.linspace(centre - half, centre + half, GRID), a, b))
        ts = ts[(ts > a) & (ts < b)]
        if not len(ts) or b - a <= XTOL * max(1.0, abs(a)):
            break
        fs = _values(signal, res, ts) - value
        pts, fv = np.concatenate([[a], ts, [b]]), np.concatenate([[fa], fs, [fb]])
        zero = np.flatnonzero(fv == 0.0)
        if len(zero):
            return float(pts[zero[0]])
        m = int(np.flatnonzero(np.sign(fv[:-1]) != np.sign(fv[1:]))[0])
        est = _root_estimate(pts, fv, m)
        a, b, fa, fb = float(pts[m]), float(pts[m + 1]), float(fv[m]), float(fv[m + 1])
        spacing = b - a
        if previous is not None and abs(est - previous) <= spacing:
            return est
        centre, half, previous = est, REFINE_HALF * spacing * (GRID - 1) / 2, est
    return float(a - fa * (b - a) / (fb - fa)) if fb != fa else 0.5 * (a + b)
