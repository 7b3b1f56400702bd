"""Python side of the compiled Radau IIA (mbdsim.solvers.fastradau): method "radau" on a model the
compiled kernels carry, and the automatic method's continuation after DOP853 flags stiffness.

`RadauRun` is a `CompiledRun` (the same compiled model, work arrays, outputs, failure reports and step
states) whose step loop is `fastradau.run`. It keeps, for every accepted step, its start state, (t, h)
and the coefficients of its collocation polynomial (within CHECKPOINT_BUDGET bytes), so that `Result.at`
between outputs is the run's own dense output (projected onto the constraints, accelerations and
multipliers from the compiled kernel), nothing integrated again. Sensors are watched on the steps'
polynomials (solvers.fastswitch: DOP853's sensor machinery; a "stop" ends the run at its time, its state
the last sample); contacts and stops are integrated through as on DOP853.
Joint friction with stick/slip runs here (and on HHT): the step loop stops at each switching event,
located on the step's polynomial (solvers.fastswitch), and `integrate` restarts it there with the modes
`friction_run.FrictionModes.decide` takes (the decision of every stepper).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import SolverError
from ..results.stream import ProgressError, notify
from ..system.compiled import NotCompiled
from . import fastdop, fastdyn, fastradau, pyloads
from .compiled_run import (CHECKPOINT_BUDGET, CHUNK, PROGRESS_FAILED, CompiledRun, _MESSAGES, _result, failure)
from .fastdyn import INTERRUPTED

METHOD = "Radau IIA (compiled)"
HISTORY = ("Radau", 5)   # (method, order) of its segment in res.stats["order_history"]


class RadauRun(CompiledRun):
    """A compiled model stepped by the compiled Radau IIA (fastradau.run); stats: steps, rejected, rhs
    evaluations, projections, Jacobians, LU factorisation pairs."""

    dense_q = None
    METHOD, HISTORY, ORDER, N_ST = METHOD, HISTORY, 5, fastradau.N_ST
    LU_PER_FACTORISATION = 2   # a real and a complex LU

    def _scratch(self, n):
        """The step loop's work arrays kept between its calls (J, LU factors, stages)."""
        return (np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n), dtype=np.complex128),
                np.zeros((2, n), dtype=np.int64), np.zeros((fastradau.N_SCRATCH, n)), np.zeros(n, np.complex128))

    def _step_loop(self, a, w, st, y, f, tout, iout, Y, scratch, SY, ST, SQ, ns, start_row):
        """One call of the compiled step loop: (status, next iout)."""
        return fastradau.run(a, w, fastradau.COEFFS, st, y, f, float(tout[-1]), tout, iout, Y, self.rtol, self.atol,
                             self.max_step, self.max_steps, CHUNK, 1e-12, self.stats, *scratch, SY, ST, SQ, ns,
                             start_row)

    @classmethod
    def sharing(cls, run: CompiledRun, rtol, atol, max_step):
        """A RadauRun on the compiled model and work arrays of `run` (the automatic method's hand-over:
        nothing compiled again), with its own tolerances and statistics."""
        new = object.__new__(cls)
        new.__dict__.update({k: v for k, v in run.__dict__.items() if k != "checkpoints"})
        new.rtol, new.atol = float(rtol), float(atol)
        new.max_step = np.inf if not max_step else float(max_step)
        new.stats = np.zeros(6, dtype=np.int64)
        new.stiff_check, new.sensor_events, new.run_error = False, [], None
        return new

    def integrate(self, t0, y0, tout, progress=None, checkpoints=True, partial=None, y_start=None):
        """As CompiledRun.integrate, stepping with Radau IIA; y_start: the integrator's state at t0 (a
        tree's joint state with continuous angles) when known, else taken from y0 (absolute [q, v])."""
        a, w = self.cm.arrays(), self.work.arrays()
        self.angle_ref0 = w[44][7].copy()   # the continued joint angles' references at the start
        nout = len(tout)
        start_row = y_start is None and self.joint_space
        if y_start is not None:
            y = np.array(y_start, dtype=float)
        else:
            y = np.zeros(self.state_size) if self.joint_space else np.array(y0, dtype=float)
        n = len(y)
        Y = np.zeros((nout, len(y0)))
        Y[0] = y0
        iout = 1 if abs(tout[0] - t0) <= 1e-14 * max(1.0, abs(t0)) else 0
        f = np.zeros(n)
        st = np.zeros(self.N_ST)
        st[0] = t0
        scratch = self._scratch(n)
        keep = checkpoints and 4 * n * 8 * 64 <= CHECKPOINT_BUDGET
        cap = 64 if keep else 0
        SY, ST, SQ, ns = np.zeros((cap, n)), np.zeros((cap, 2)), np.zeros((cap, 3, n)), np.zeros(1, np.int64)
        status = 0
        if self.friction is not None:   # the initial modes (all joints at rest decided together)
            self.friction.decide(t0, y)
        try:
            while status in (0, fastdop.CHECKPOINTS_FULL, fastdop.EVENTS_FULL, fastdop.FRICTION_EVENT,
                             fastdop.SWITCH_EVENT) and iout < nout:
                if status in (fastdop.FRICTION_EVENT, fastdop.SWITCH_EVENT):   # restart at the event st[0]: a
                    if status == fastdop.FRICTION_EVENT:   # stick/slip event decided first (the one decision of
                        self.friction.decide(st[0], y)     # every stepper: friction_run); a stop's or contact's zero
                    st[1:] = 0.0
                    if tout[-1] - st[0] <= 1e-14 * max(1.0, abs(st[0])):   # at the end time: its state is the
                        Y[iout:] = y                                         # last output (absolute coordinates)
                        iout, status = nout, 0
                        break
                if status == fastdop.CHECKPOINTS_FULL:   # grow, or stop keeping them beyond the budget
                    if 2 * (SY.size + SQ.size) * 8 <= CHECKPOINT_BUDGET:
                        SY, ST, SQ = (np.concatenate([x, np.zeros_like(x)]) for x in (SY, ST, SQ))
                    else:
                        keep, SY, ST, SQ = False, SY[:0], ST[:0], SQ[:0]
                self._take_events()
                status, iout = self._step_loop(a, w, st, y, f, tout, iout, Y, scratch, SY, ST, SQ, ns, start_row)
                start_row = False   # (a restart at an event starts from the stepper's own state y)
                if st[1] == 0.0:   # the start failed (a restart after a friction event keeps the outputs before it)
                    if st[0] == t0:
                        iout = 0
                    break
                notify(progress, st[0], None if partial is None else (lambda n=iout: partial(Y, n)))
        except KeyboardInterrupt:
            status = INTERRUPTED
        except ProgressError as exc:
            status, self.run_error = PROGRESS_FAILED, exc
        status, self.run_error = pyloads.settle(self.pyloads, status, self.run_error)
        self._take_events()
        self.checkpoints = (SY[:ns[0]].copy(), ST[:ns[0]].copy()) if keep else None
        self.dense_q = SQ[:ns[0]].copy() if keep else None
        if self.joint_space and status != 0:   # (a sensor's stop: continuous with the last output)
            ymax = np.zeros(len(y0))
            fastdyn.write_state(a, w, y, ymax, Y[iout - 1] if status == fastdop.SENSOR_STOP and iout else ymax[:0])
            y = ymax
        return Y, iout, status, st[0], y

    def _from_checkpoints(self, cp, ts, full=True):
        """(q, v, vd, lambda_) at ts from the collocation polynomial of the run's step containing each time
        (projected onto the constraints in absolute coordinates, as the run's own outputs)."""
        from .compiled_run import _full_multipliers
        SY, ST = cp
        sys = self.sys
        a, w = self.cm.arrays(), self.work.arrays()
        nq = sys.nq
        Ys = np.zeros((len(ts), nq + sys.nv))
        step = np.clip(np.searchsorted(ST[:, 0], ts, side="right") - 1, 0, len(ST) - 1)
        yo = np.zeros(SY.shape[1])
        for k, (t, j) in enumerate(zip(ts.tolist(), step.tolist())):
            t0, h = float(ST[j, 0]), float(ST[j, 1])
            fastradau.dense(self.dense_q[j], SY[j], t0, h, min(max(t, t0), t0 + h), yo)
            if not self.joint_space and fastdyn.project(a, w, t, yo[:nq], yo[nq:], 1e-12, False) != 0:
                raise SolverError(_MESSAGES[fastdyn.PROJECTION] + " at a dense-output time", time=t)
            fastdyn.write_state(a, w, yo, Ys[k], Ys[k][:0])
        VD, LAM = self.outputs(ts, Ys)
        return Ys[:, :nq], Ys[:, nq:], VD, (_full_multipliers(sys, self.rows, ts, Ys, VD, LAM) if full else LAM)


def _stats(run: RadauRun, rep) -> dict:
    s = run.stats
    nlu = int(run.LU_PER_FACTORISATION * s[5])
    return {"steps": int(s[0]), "rejected": int(s[1]), "nfev": int(s[2]), "njev": int(s[4]), "nlu": nlu,
            "factorizations": nlu + (0 if run.joint_space else int(s[2] + 2 * s[3])),
            "projections": 0 if run.joint_space else int(s[3]), "order": run.ORDER, "method": run.METHOD,
            "called_back": tuple(run.cm.python_loads),
            "formulation": "joint coordinates (articulated body)" if run.joint_space else
            "absolute coordinates (tree elimination)", "assembly": rep}


def _integrate(sys, rep, run, times, progress=None, y_start=None):
    """The Result of a RadauRun over `times` from the consistent state rep (y_start: the integrator's
    state, for a hand-over)."""
    y0 = np.concatenate([rep.q, rep.v])
    times = np.asarray(times, float)
    partial = lambda Y, n: _result(sys, rep, run, times[:n], Y[:n], stats={"assembly": rep},  # noqa: E731
                                   message="partial (run in progress)")
    Y, n, status, t_fail, y_fail = run.integrate(times[0], y0, times, progress, True, partial, y_start)
    success, message, error = True, "ok", None
    if status == fastdyn.FRICTION_FAILED:   # name the element whose coupled solve failed
        run.run_error = run.friction.failure(t_fail, y_fail)
    if status == fastdop.SENSOR_STOP:   # the state at the sensor's time is the last sample
        times, Y, n, message = sensor_stop(run, times, Y, n, t_fail, y_fail)
        status = 0
    if status != 0:
        error, message = failure(sys, rep, status, t_fail, y_fail, times[:n], "integration failed", run.run_error)
        success = False
    res = _result(sys, rep, run, times[:n], Y[:n], success=success, message=message, stats=_stats(run, rep))
    res.error = error
    res.stats["order_history"] = [(float(times[0]),) + run.HISTORY]
    if run.sensors:
        res.sensor_events = run.sensor_events
    return res


def integrate_radau(sys, rep, times, rtol, atol, max_step, progress=None):
    """Dynamic analysis with the compiled Radau IIA (method "radau"); NotCompiled when the model needs the
    reference path. Sensors and joint friction's stick/slip events are located on the steps' polynomials
    (solvers.fastswitch)."""
    _switching_check(sys)
    run = RadauRun(sys, rep.rows, rtol, atol, max_step, state=(rep.q, rep.v), friction=len(sys.lock_rows) > 0)
    return _integrate(sys, rep, run, times, progress)


def _switching_check(sys):
    """NotCompiled for a held friction group an earlier try met (solvers.friction_run). Joint friction's
    stick/slip events and the sensors are located by the compiled implicit steppers themselves
    (solvers.fastswitch); contacts and stops are loads of the compiled right-hand side, integrated through
    by the step-size control as on the compiled DOP853, and the joint angles of torsion springs, stops and
    expression loads are continued in the kernel (no event needed)."""
    if sys.derived.get("friction not compiled"):
        raise NotCompiled(sys.derived["friction not compiled"])


def sensor_stop(run, times, Y, n, t_fail, y_fail):
    """(times, Y, n, message) of a run a "stop" sensor ended at t_fail [s] in state y_fail: that state
    appended as the last sample (unless an output is at that time already)."""
    if not n or t_fail > times[n - 1] + 1e-14 * max(1.0, abs(t_fail)):
        times, Y = np.append(times[:n], t_fail), np.vstack([Y[:n], y_fail])
        n += 1
    stop = min((e for e in run.sensor_events if e.action == "stop"), key=lambda e: e.time)
    return times, Y, n, f"stopped by sensor '{stop.name}' at t = {t_fail:.12g} s"


# auto's hand-over tries Radau over this many of DOP853's mean accepted steps, or this share of the time
# left, whichever is longer, first (`_probe_end`: Radau's steps take a while to grow from its start), and
# keeps it when it needed at most 1 / PAY of DOP853's right-hand-side evaluations per second of model
# time (an implicit step also factorises and solves: LU factorisations that grow as n^3 with the state)
PROBE_STEPS, PROBE_SHARE, PAY = 50, 0.1, 2.0
# ... the trial's first PROBE_STEPS steps decide already where Radau's steps are SETTLED to EARLY times DOP853's
# and cost more: under way with longer steps than the explicit method, yet not the orders of magnitude longer
# that a stiff model's implicit steps take (steps of DOP853's size or shorter: Radau still resolving a fast
# mode the explicit run left excited, which its growing steps damp; the whole trial decides)
SETTLED, EARLY = 2.0, 10.0
# ... or, the same first part, where Radau's steps stay below RESOLVING times DOP853's without growing: it
# resolves a fast mode that DOP853 steps over at its stability limit (a lightly damped rocking mode that
# friction excites, its amplitude far above the tolerance), so it will not get cheaper
RESOLVING = 0.5


def continue_radau(sys, rep, times, stiff, rtol, atol, max_step, progress, reason):
    """Result over `times` from the explicit prefix of `stiff` (a compiled_run.Stiff) and the compiled Radau
    IIA from its switch time t_s on, at rtol, atol; joined by autoswitch.join
    (outputs, dense output: DOP853's steps up to t_s, Radau's collocation polynomials after; statistics;
    order history with a ("Radau", 5) segment from t_s).

    Stiffness detection says that DOP853 steps at its stability limit, not that Radau is cheaper: where the
    fast modes oscillate with an amplitude above the tolerance (lightly damped contact, an excited stiff
    spring), every method must resolve them and the explicit eighth-order one does it with fewer
    evaluations (a box sliding on four contact corners: Radau 7,900 steps against DOP853's 1,200). So
    (absolute coordinates, no joint friction, no sensors) Radau first runs over a trial (`_probe_end`), and
    when it needed more than 1 / PAY of the right-hand-side evaluations per second of model time that
    DOP853 did before t_s, DOP853 continues from there without the stiffness test (`_after_probe`)."""
    from .autoswitch import _align_quaternions, _Joined, join, merge_stats
    pre, t_s = stiff.prefix, float(stiff.time)
    run, tp, Y = pre["run"], pre["times"], pre["Y"]
    nq = sys.nq
    q_s = _align_quaternions(sys, np.array(pre["y"][:nq]), Y[-1, :nq])
    v_s = np.array(pre["y"][nq:])
    first = _result(sys, rep, run, tp, Y, stats=pre["stats"])
    first.steps = lambda: run.step_states(t_s, np.concatenate([q_s, v_s]))
    rep_s = dataclasses.replace(rep, t=t_s, q=q_s, v=v_s)
    rest = np.concatenate([[t_s], np.asarray(times, float)[len(tp):]])
    rr = RadauRun.sharing(run, rtol, atol, max_step)
    y_start = getattr(run, "last_state", None) if run.joint_space else None
    trial = not (run.joint_space or len(sys.lock_rows) or getattr(sys.model, "sensors", None))
    t_p = _probe_end(pre["stats"], float(times[0]), t_s, rest) if trial else None
    # the trial's first, short part (PROBE_STEPS of DOP853's steps): DOP853 on at once where Radau's steps
    # stay within EARLY of DOP853's, or below RESOLVING of them, and cost more (contact that every method
    # must resolve)
    t_e = _probe_end(pre["stats"], float(times[0]), t_s, rest, 0.0) if t_p is not None else None
    t_e = t_e if t_e is not None and t_e < t_p else None
    t_1 = t_p if t_e is None else t_e
    second = _integrate(sys, rep_s, rr, rest if t_1 is None else rest[rest <= t_1],
                        None if progress is None else _Joined(progress, first, t_s),
                        None if y_start is None else np.array(y_start))
    res = join(first, second, t_s)
    if run.sensors:   # the explicit part's sensor events, then the implicit part's
        res.sensor_events = list(run.sensor_events) + list(getattr(second, "sensor_events", []))
    res.stats = merge_stats(pre["stats"], second.stats, float(times[0]), t_s, reason)
    res.stats["order_history"][-1] = (t_s,) + HISTORY
    res.stats.update(assembly=rep, njev=second.stats["njev"], nlu=second.stats["nlu"], rtol_reached=rtol)
    if t_1 is not None and second.success:
        span = t_s - float(times[0])   # DOP853's mean step and evaluations per second of model time before t_s
        explicit = (span / max(pre["stats"]["steps"], 1), pre["stats"]["nfev"] / span)
        tol = (rtol, atol, max_step)
        if t_e is not None:
            way = _radau_under_way(second, rr)
            if way is not None and PAY * way[1] > explicit[1] and \
                    (SETTLED * explicit[0] <= way[0] < EARLY * explicit[0] or way[0] < RESOLVING * explicit[0]):
                return _after_probe(sys, rep, res, second, rest[rest >= t_e], explicit, rr, tol, progress, reason)
            # not decided: Radau on to the trial's end, where the choice is made on that part's steps
            rr, second, res = _radau_on(sys, rep, res, second, rest[(rest >= t_e) & (rest <= t_p)], rr, tol, progress)
            if not second.success:
                return res
        res = _after_probe(sys, rep, res, second, rest[rest >= t_p], explicit, rr, tol, progress, reason)
    return res


def _radau_on(sys, rep, res, probe, rest, rr, tol, progress):
    """(run, its part, joined Result): `res` continued by Radau over `rest` from the end of `probe` (a
    RadauRun sharing rr's arrays); statistics summed."""
    from .autoswitch import _Joined, join
    t_0 = float(rest[0])
    rep_0 = dataclasses.replace(rep, t=t_0, q=np.array(probe.q[-1]), v=np.array(probe.v[-1]))
    run = RadauRun.sharing(rr, *tol)
    part = _integrate(sys, rep_0, run, rest, None if progress is None else _Joined(progress, res, t_0))
    out = join(res, part, t_0)
    out.stats = _summed(res.stats, part.stats)
    return run, part, out


def _summed(stats, more):
    stats = dict(stats)
    for k in ("steps", "rejected", "nfev", "njev", "nlu", "factorizations", "projections"):
        stats[k] = int(stats.get(k, 0)) + int(more.get(k, 0))
    return stats


def _probe_end(stats, t0, t_s, rest, share=None):
    """The output time of `rest` (from t_s) that ends Radau's trial: the first at least PROBE_STEPS of the
    explicit run's mean accepted step, and `share` (default PROBE_SHARE) of the time left, after t_s; None
    when that is the last (no choice left to make)."""
    if not t_s > t0 or stats.get("steps", 0) < 1:
        return None
    share = PROBE_SHARE if share is None else share
    window = max(PROBE_STEPS * (t_s - t0) / stats["steps"], share * (rest[-1] - t_s))
    later = rest[1:][rest[1:] >= t_s + window]
    return float(later[0]) if len(later) > 1 else None


def _radau_under_way(probe, rr):
    """(largest step [s] of the trial's second half, right-hand-side evaluations per second of model time
    over the trial, its finite-difference Jacobians included: contact recomputes them every few steps)
    of Radau's trial; None without the steps' record, or while its steps still grow at the trial's end
    (the last above twice the median of the second half: an undamped fast mode that the explicit run left
    excited at its error's level, which Radau resolves until its growing steps damp it; Radau continues)."""
    cp = rr.checkpoints
    if cp is None or len(cp[1]) < 2:
        return None
    h = cp[1][:, 1]
    late = h[len(h) // 2:]
    if h[-1] > 2.0 * float(np.median(late)):
        return None
    return float(np.max(late)), probe.stats["nfev"] / (float(probe.time[-1]) - float(probe.time[0]))


def _after_probe(sys, rep, res, probe, rest, explicit, rr, tol, progress, reason):
    """`res` (the run up to the probe's end t_p = rest[0]) continued over `rest`: by Radau when, under way
    (`_radau_under_way`), it needed at most 1 / PAY of the right-hand-side evaluations per second of model
    time of DOP853 before the switch (explicit = (mean step, rate) of DOP853), else by DOP853 without the
    stiffness test; joined, statistics summed."""
    from .autoswitch import _Joined, join
    from .compiled_run import integrate_compiled
    way = _radau_under_way(probe, rr)
    h_d, rate_d = explicit
    if not (way is not None and PAY * way[1] > rate_d):
        return _radau_on(sys, rep, res, probe, rest, rr, tol, progress)[2]
    t_p = float(rest[0])
    rep_p = dataclasses.replace(rep, t=t_p, q=np.array(probe.q[-1]), v=np.array(probe.v[-1]))
    prog = None if progress is None else _Joined(progress, res, t_p)
    third = integrate_compiled(sys, rep_p, rest, *tol, progress=prog)
    out = join(res, third, t_p)
    stats = _summed(res.stats, third.stats)
    t_s = float(res.stats.get("switch_time", probe.time[0]))   # (the trial may be two parts of Radau)
    stats["order_history"] = list(stats["order_history"]) + [(t_p, third.stats["method"], 8)]
    stats["method"] = (f"auto: {third.stats['method']} until t = {t_s:.6g} s, then {METHOD} until t = "
                       f"{t_p:.6g} s, then {third.stats['method']} ({reason}; Radau IIA's steps {way[0]:.3g} s "
                       f"at {way[1]:.3g} evaluations per second of model time, DOP853's {h_d:.3g} s at "
                       f"{rate_d:.3g}: DOP853 on, without the stiffness test)")
    stats["order"] = 8
    out.stats = stats
    return out
