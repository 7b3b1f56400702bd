"""Energy bookkeeping: cumulative dissipated energy of a Result.

D(t) = integral from t0 to t of P(s) ds [J], with P [W] the sum of the `dissipation` power of every
force element (damping of spring-dampers, torsion springs, bushings, contacts, stops, friction ...).
P is evaluated on the solver's dense output.  Each accepted integrator step (contact onset/separation
and stick/slip events end a step, so the kinks of P lie on step ends) is a segment on which P is
interpolated at 16 Chebyshev points and integrated exactly (Clenshaw-Curtis-like); a segment whose
last Chebyshev coefficients exceed `rtol` of the total is halved, recursively.  D at any output time
inside a segment comes from the interpolant's antiderivative, so the cost does not grow with the
number of output samples.  The states come from the index-1 trajectory's dense outputs, or from the
interpolant of the accepted steps (`interpolated(ts)` of the HHT stepper: cubic Hermite, not projected,
no Newton solve per point); without step information the output intervals are the segments (evaluated
through Result.at); without dense output the samples are integrated by the trapezoidal rule.

A compiled run of simulate(monitor=True) accumulates D in its step loop instead (solvers.energy_run,
Result.energy): `dissipated_energy` serves those values at the samples that are the run's own outputs
(the Result itself, or a subset of its samples) and falls back to the quadrature above
(`dissipated_energy_reference`, the independent reference of the tests) everywhere else.
"""
from __future__ import annotations

import numpy as np

from ..system.force_elements import evaluator
from ..system.frames import body_frames

_C = np.polynomial.chebyshev
_N = 16
_XC = np.cos(np.pi * (np.arange(_N) + 0.5) / _N)          # Chebyshev points of the first kind on [-1, 1]
_FIT = np.linalg.inv(_C.chebvander(_XC, _N - 1)).T          # values at _XC -> Chebyshev coefficients
_INT = np.array([_C.chebint(e, lbnd=-1) for e in np.eye(_N)])  # coefficients -> antiderivative (0 at -1)


def dissipation_power(sys, fr, t) -> np.ndarray:
    """Total dissipation power [W] (N,) of all force elements for time-axis frames at times t (N,)."""
    P = np.zeros(len(np.atleast_1d(t)))
    for el in sys.model.forces.values():
        ev = evaluator(el)
        if hasattr(ev, "dissipation"):
            P = P + ev.dissipation(sys, fr, el, t)
    return P


def _dense_sampler(res):
    """(power(ts), breakpoints) from the index-1 trajectory's step-wise dense outputs, or from the
    interpolant of a stepper's accepted steps (HHT), or None."""
    traj = getattr(res._evaluate, "__self__", None)
    sys = res.system
    if hasattr(traj, "interpolated") and hasattr(traj, "steps") and len(traj.steps) > 1:
        states = traj.interpolated
        breaks = np.array([s.t for s in traj.steps])
    elif traj is None or not hasattr(traj, "dense") or not hasattr(traj, "t_end") or not traj.dense:
        return None
    else:
        t_end = np.asarray(traj.t_end)
        breaks = np.union1d(np.array([d[0] for d in traj.dense]), t_end)

        def states(ts):
            k = np.clip(np.searchsorted(t_end, ts, side="left"), 0, len(t_end) - 1)
            Y = np.zeros((len(ts), sys.nq + sys.nv))
            for kk in np.unique(k):
                sel = k == kk
                Y[sel] = np.asarray(traj.dense[kk][1](ts[sel])).T
            return Y

    def power(ts):
        Y = states(ts)
        q, v = Y[:, :sys.nq], Y[:, sys.nq:]
        fr = body_frames(sys, q, v)
        fr.t = ts
        fr.q, fr.v = q, v   # raw states, for elements whose power needs the multipliers (joint friction)
        return dissipation_power(sys, fr, ts)

    return power, breaks


def _at_sampler(res):
    def power(ts):
        r = res.at(ts)
        return dissipation_power(res.system, r.frames, ts)
    return power


def _share(h, span):
    """Share of the error budget of a segment of length h: its share of the span, at least 1e-3 (so
    that a kink inside a step is resolved to rtol / 1000 of the total, not to its tiny length share)."""
    return np.maximum(h / span, 1e-3)


def _segments(power, a, b, rtol, max_depth=40):
    """Accepted segments covering the intervals [a_k, b_k]: (a, b, antiderivative coefficients) arrays."""
    span = max(float(np.max(b) - np.min(a)), 1e-300)
    done_a, done_b, done_c = [], [], []
    scale = p_max = None
    budget = 50 * len(a) + 2000                               # segments evaluated at most
    for depth in range(max_depth):
        half, mid = 0.5 * (b - a), 0.5 * (a + b)
        P = power((mid[:, None] + half[:, None] * _XC[None, :]).reshape(-1)).reshape(len(a), _N)
        coef = P @ _FIT
        anti = half[:, None] * (coef @ _INT)                  # antiderivative in the local variable
        if scale is None:
            scale = max(float(np.sum(np.abs(_C.chebval(1.0, anti.T)))), 1e-300)
            p_max = float(np.max(np.abs(P)))
        tail = np.sum(np.abs(coef[:, -3:]), axis=1)
        budget -= len(a)
        ok = ((half * tail <= rtol * scale * _share(b - a, span)) | (tail <= 1e-13 * p_max)   # accurate or roundoff
              | (depth == max_depth - 1) | (budget < 2 * len(a)))
        done_a.append(a[ok])
        done_b.append(b[ok])
        done_c.append(anti[ok])
        if np.all(ok):
            break
        a, b = np.concatenate([a[~ok], mid[~ok]]), np.concatenate([mid[~ok], b[~ok]])
    a, b, c = np.concatenate(done_a), np.concatenate(done_b), np.concatenate(done_c)
    order = np.argsort(a)
    return a[order], b[order], c[order]


def run_energy(res, key="D"):
    """The compiled run's accumulated `key` ("D": dissipated energy, "W": applied loads' work) [J] at the
    samples of res since res.time[0], or None when the run kept none or a sample is not one of its outputs."""
    base = res._parent or res
    kept = getattr(base, "energy", None)
    got = None if kept is None else kept.get(key)
    if got is None or not len(res.time):
        return None
    if res is base:
        return got - got[0]
    k = np.clip(np.searchsorted(base.time, res.time), 0, len(base.time) - 1)
    if not np.all(base.time[k] == res.time):
        return None
    return got[k] - got[k[0]]


def dissipated_energy(res, rtol=1e-10) -> np.ndarray:
    """Cumulative energy dissipated by all force elements since res.time[0], (N,) [J]: the compiled run's
    own (`run_energy`) where it kept it, else `dissipated_energy_reference`."""
    D = run_energy(res, "D")
    return D if D is not None else dissipated_energy_reference(res, rtol)


def dissipated_energy_reference(res, rtol=1e-10) -> np.ndarray:
    """Cumulative energy dissipated by all force elements since res.time[0], (N,) [J], integrated after the
    run on its dense output (module docstring)."""
    t = res.time
    if len(t) < 2:
        return np.zeros(len(t))
    base = res._parent or res
    if base._evaluate is None:
        P = dissipation_power(res.system, res.frames, t)
        return np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(t))])
    dense = _dense_sampler(base)
    power, breaks = dense if dense is not None else (_at_sampler(base), t)
    edges = np.union1d([t[0], t[-1]], breaks[(breaks > t[0]) & (breaks < t[-1])])
    a, b, anti = _segments(power, edges[:-1], edges[1:], rtol)
    total = _C.chebval(1.0, anti.T)
    start = np.concatenate([[0.0], np.cumsum(total)])
    k = np.clip(np.searchsorted(b, t, side="left"), 0, len(a) - 1)
    x = np.clip((2 * t - a[k] - b[k]) / (b[k] - a[k]), -1.0, 1.0)
    D = start[k] + np.array([_C.chebval(xi, anti[i]) for xi, i in zip(x, k)])
    return D - D[0]
