"""The automatic method's hand-over from the explicit DOP853 to an implicit method when it detects stiffness:
the joining of the two parts (`join`, `merge_stats`), used by the compiled Radau IIA's continuation
(mbdsim.solvers.radau_run.continue_radau; the earlier HHT continuation is gone with the compiled Radau).

The compiled DOP853 stops at the start t_s of the step its stiffness test flagged (`compiled_run.Stiff`,
whose `prefix` holds the outputs at times <= t_s, the consistent state at t_s and the run with its step
checkpoints). Radau IIA then continues from that state over the remaining output times, and the two parts are
joined into one Result: outputs, accelerations and multipliers (on demand for the explicit part, as in a
compiled run), dense output (`Result.at`: the explicit run's own steps up to t_s, Radau's collocation
polynomials after), the solver's step states, and the statistics (sums, and `order_history` naming
which method and order held from which time). Nothing before t_s is integrated twice.

Order history (res.stats["order_history"]): a list of (t_start [s], method, order) segments in time
order; each method keeps a fixed order (DOP853: 8, HHT-alpha: 2, scipy's RK45: 5, Radau: 5) except
scipy's BDF, which changes its order (1..5) itself and whose changes are recorded as they happen.
"""
from __future__ import annotations

import numpy as np

from ..results.result import Result

ORDERS = {"DOP853": 8, "DOP853 (compiled)": 8, "RK45": 5, "Radau": 5, "HHT": 2}


def single_history(t0: float, method: str, order: int | None) -> list:
    """The order history of a run by one fixed-order method: [(t0 [s], method, order)]."""
    return [(float(t0), method, order)]


class OrderTrack:
    """Order history of a scipy OdeSolver run: a new segment whenever the order of a step differs from
    the previous step's (scipy's BDF chooses its order, 1..5, itself; after an event it restarts at 1)."""

    def __init__(self, t0, name, solver):
        self.name = name
        self.history = [(float(t0), name, self.order(solver))]

    def order(self, solver):
        """The order the solver's next step uses."""
        order = getattr(solver, "order", None)
        return int(order) if order is not None else ORDERS.get(self.name)

    def step(self, t_old, order):
        """Record the order of the step just taken from t_old [s]."""
        if order != self.history[-1][2]:
            self.history.append((float(t_old), self.name, order))


class AccuracyWarning(UserWarning):
    """The automatic method could not run at the requested (or default) tolerance: HHT, second order, ran
    at a looser rtol (`res.stats["rtol_reached"]`): a stiff model the compiled core does not carry (the
    compiled models hand over to the compiled Radau IIA at the target tolerance)."""


def warn_reached(res, reached: float, target: float, reason: str) -> None:
    """Record in res.stats["rtol_reached"] the rtol HHT ran at and warn (AccuracyWarning) when it is
    looser than the target rtol of the outputs."""
    from .._userwarn import warn
    res.stats["rtol_reached"] = reached
    if reached > target:
        warn(f"simulate: {reason}; HHT (second order) ran at rtol {reached:g}, so the outputs from there are "
             f"accurate to about that, not to the target {target:g} (give rtol to tighten HHT, at the cost of "
             "its second order)", AccuracyWarning)


def join(first: Result, second: Result, t_s: float) -> Result:
    """One Result of `first` (outputs at times <= t_s) and `second` (from t_s on; its first sample, at
    t_s, is left out): outputs, on-demand accelerations and multipliers, dense output and step states."""
    sl = slice(1, None)

    def accelerations():
        return (np.concatenate([first.vd, second.vd[sl]]), np.concatenate([first.lambda_, second.lambda_[sl]]))

    evaluate = None
    if first._evaluate is not None and second._evaluate is not None:
        def evaluate(ts):
            ts = np.asarray(ts, float)
            lo = ts <= t_s
            got = [(m, f(ts[m])) for m, f in ((lo, first._evaluate), (~lo, second._evaluate)) if m.any()]
            return tuple(_scatter(len(ts), [(m, p[i]) for m, p in got]) for i in range(4))

    res = Result(first.system, np.concatenate([first.time, second.time[sl]]),
                 np.concatenate([first.q, second.q[sl]]), np.concatenate([first.v, second.v[sl]]), None, None,
                 evaluate=evaluate, success=second.success, status=second.status, message=second.message,
                 stats=dict(second.stats), accelerations=accelerations)
    res.error = second.error
    if first.steps is not None and second.steps is not None:
        def steps():
            a = first.steps() if callable(first.steps) else first.steps
            b = second.steps() if callable(second.steps) else second.steps
            if a is None or b is None:
                return None
            return tuple(np.concatenate([x, y[1:]]) for x, y in zip(a, b))
        res.steps = steps
    if hasattr(second, "sensor_events"):
        res.sensor_events = list(second.sensor_events)
    return res


def _scatter(n, parts):
    """(n, k) array with the rows of each (mask, rows) part at its mask."""
    out = np.zeros((n, parts[0][1].shape[1]))
    for mask, rows in parts:
        out[mask] = rows
    return out


def merge_stats(a: dict, b: dict, t0: float, t_s: float, reason: str) -> dict:
    """Statistics of an explicit run `a` over [t0, t_s] followed by an implicit run `b` from t_s: counts
    summed (the flagged explicit step, computed but not kept, counts as rejected), "order" the order of
    the method that finished the run, "order_history" both segments."""
    out = {k: int(a.get(k, 0)) + int(b.get(k, 0)) for k in ("steps", "rejected", "nfev", "njev", "factorizations",
                                                          "projections")}
    out["steps"] -= 1      # the explicit step that was flagged stiff is discarded (HHT redoes it): rejected
    out["rejected"] += 1
    out.update(order=b.get("order"), switch_time=t_s, alpha=b.get("alpha"), formulation=a.get("formulation"),
               method=f"auto: {a['method']} until t = {t_s:.6g} s, then {b['method']} ({reason})",
               order_history=single_history(t0, a["method"], a.get("order"))
               + single_history(t_s, b["method"], b.get("order")))
    return out


def _align_quaternions(sys, q, q_prev):
    """q with each body's Euler parameters sign-flipped where they point away from q_prev's (the same
    rotation; keeps the output rows continuous across the hand-over)."""
    if len(sys.p_idx):
        p, pp = q[sys.p_idx], q_prev[sys.p_idx]
        flip = np.sum(p * pp, axis=1) < 0
        q[sys.p_idx[flip]] = -p[flip]
    return q


class _Joined:
    """Progress of the implicit part: times forwarded, partial Results offered with the explicit prefix
    in front (so that a file written during the run holds every output so far)."""

    def __init__(self, progress, first, t_s):
        self.progress, self.first, self.t_s = progress, first, t_s

    def __call__(self, t):
        self.progress(float(t))

    def offer(self, build):
        offer = getattr(self.progress, "offer", None)
        if offer is not None:
            offer(lambda: join(self.first, build(), self.t_s))
