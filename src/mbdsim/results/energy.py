"""Energy bookkeeping: cumulative dissipated energy of a Result.

D(t) = integral from t0 to t of P(s) ds [J], with P [W] the sum of the `dissipation` power of every
force element (damping of spring-dampers, torsion springs, bushings, contacts, stops, friction ...).
P is evaluated on the solver's dense output and integrated by adaptive Gauss-Legendre quadrature
(10 nodes, interval halving until two levels agree to `rtol` of the total), on sub-intervals split at
every output time and every accepted integrator step (contact onset/separation events end a step, so
the kinks of P lie on interval ends).  Without dense output the samples are integrated by the
trapezoidal rule (first order accurate at kinks; use a fine output_step).
"""
from __future__ import annotations

import numpy as np

from ..system.force_elements import evaluator
from ..system.frames import body_frames

_X, _W = np.polynomial.legendre.leggauss(10)


def dissipation_power(sys, fr, t) -> np.ndarray:
    """Total dissipation power [W] (N,) of all force elements for time-axis frames at times t (N,)."""
    P = np.zeros(len(np.atleast_1d(t)))
    for el in sys.model.forces.values():
        ev = evaluator(el)
        if hasattr(ev, "dissipation"):
            P = P + ev.dissipation(sys, fr, el, t)
    return P


def _dense_sampler(res):
    """(power(ts), breakpoints) from the index-1 trajectory's step-wise dense outputs, or None."""
    traj = getattr(res._evaluate, "__self__", None)
    if traj is None or not hasattr(traj, "dense") or not hasattr(traj, "t_end") or not traj.dense:
        return None
    sys = res.system
    t_end = np.asarray(traj.t_end)
    starts = np.array([d[0] for d in traj.dense])

    def power(ts):
        k = np.clip(np.searchsorted(t_end, ts, side="left"), 0, len(t_end) - 1)
        Y = np.zeros((len(ts), sys.nq + sys.nv))
        for kk in np.unique(k):
            sel = k == kk
            Y[sel] = np.asarray(traj.dense[kk][1](ts[sel])).T
        q, v = Y[:, :sys.nq], Y[:, sys.nq:]
        fr = body_frames(sys, q, v)
        fr.t = ts
        fr.q, fr.v = q, v   # raw states, for elements whose power needs the multipliers (joint friction)
        return dissipation_power(sys, fr, ts)

    return power, np.union1d(starts, t_end)


def _at_sampler(res):
    def power(ts):
        r = res.at(ts)
        return dissipation_power(res.system, r.frames, ts)
    return power


def _gauss(power, a, b):
    """Gauss-Legendre integrals over the intervals [a_k, b_k] (vectorised)."""
    if len(a) == 0:
        return np.zeros(0)
    h = 0.5 * (b - a)
    ts = (0.5 * (a + b))[:, None] + h[:, None] * _X[None, :]
    P = power(ts.reshape(-1)).reshape(ts.shape)
    return h * (P @ _W)


def _adaptive(power, edges, rtol, max_depth=60):
    """Integrals over the consecutive intervals of `edges`, adaptively refined."""
    a, b = edges[:-1], edges[1:]
    out = np.zeros(len(a))
    whole = _gauss(power, a, b)
    idx = np.arange(len(a))
    scale = None
    for _ in range(max_depth):
        m = 0.5 * (a + b)
        left, right = _gauss(power, a, m), _gauss(power, m, b)
        halves = left + right
        if scale is None:
            scale = max(float(np.sum(np.abs(halves))), 1e-300)
        ok = np.abs(halves - whole) <= rtol * scale * np.maximum((b - a) / (edges[-1] - edges[0]), 1e-3) + 1e-300
        np.add.at(out, idx[ok], halves[ok])
        bad = ~ok
        if not np.any(bad):
            return out
        a, m, b, idx = a[bad], m[bad], b[bad], idx[bad]
        a, b = np.concatenate([a, m]), np.concatenate([m, b])
        whole = np.concatenate([left[bad], right[bad]])
        idx = np.concatenate([idx, idx])
    np.add.at(out, idx, whole)
    return out


def dissipated_energy(res, rtol=1e-12) -> np.ndarray:
    """Cumulative energy dissipated by all force elements since res.time[0], (N,) [J]."""
    t = res.time
    if len(t) < 2:
        return np.zeros(len(t))
    base = res._parent or res
    if base._evaluate is None:
        P = dissipation_power(res.system, res.frames, t)
        return np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(t))])
    dense = _dense_sampler(base)
    power, breaks = dense if dense is not None else (_at_sampler(base), np.zeros(0))
    inner = breaks[(breaks > t[0]) & (breaks < t[-1])]
    edges = np.union1d(t, inner)
    pieces = _adaptive(power, edges, rtol)
    cum = np.concatenate([[0.0], np.cumsum(pieces)])
    return cum[np.searchsorted(edges, t)]
