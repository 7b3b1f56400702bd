"""Python side of the compiled integrator: chunks of outputs, failure reports, Result building.

`integrate_compiled` runs `fastdop.run` over the output grid in chunks (Python is re-entered once per
chunk of outputs, for Ctrl-C and progress), and turns a failure status into a SolverError naming the
time and the joints while keeping every output written before it. `Result.at` between samples
re-integrates from the bracketing sample with the same tolerances (dense output on demand, no
per-step storage).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import AnalysisInterrupted, MbdsimError, SolverError
from ..results.result import Result
from ..results.stream import ProgressError, notify
from ..system.compiled import NotCompiled, Work, compile_system
from ..system.equations import jacobians
from ..system.reactions import keep_jacobians
from . import anglerefs, energy_run, fastdop, fastdyn, minnorm, pyloads
from .sensors import SensorEvent
from .fastdyn import (CALLBACK_FAILED, FRICTION_FAILED, INTERRUPTED, MAX_STEPS, NONFINITE, PROJECTION, SINGULAR,
                      STIFF, TINY_STEP)
from . import friction_run

_MESSAGES = {SINGULAR: "singular equations of motion (lock-up or singular configuration)",
             PROJECTION: "projection onto the constraints does not converge",
             NONFINITE: "non-finite state (the solution diverged)",
             TINY_STEP: "step size collapsed below the round-off limit (lock-up, singular configuration "
                        "or a discontinuity)",
             MAX_STEPS: "step budget exhausted (max_steps)",
             STIFF: "the model is stiff for an explicit method",
             INTERRUPTED: "interrupted (KeyboardInterrupt)", CALLBACK_FAILED: "a load or driver written as a Python callable failed",
             FRICTION_FAILED: "the coupled joint-friction solve does not converge",
             fastdop.SENSOR_FAILED: "a sensor's value is not finite"}
PROGRESS_FAILED = 100   # run status (Python side): the progress callback raised (CompiledRun.run_error)
CHUNK = 256
CHECKPOINT_BUDGET = 256 * 2**20   # bytes of step checkpoints a run keeps for dense output on demand


class CompiledRun:
    """A compiled model and its work arrays for one analysis (immutable model, per-run state)."""

    def __init__(self, sys, rows, rtol, atol, max_step, max_steps=10_000_000, stiff_check=False, state=None,
                 friction=False, energy_outputs=-1):
        """energy_outputs >= 0: the run keeps the energy bookkeeping for that many outputs when
        `energy_run.wanted` (monitor=True, every element's power compiled)."""
        self.sys, self.rows = sys, rows
        self.cm = compile_system(sys, rows, state, friction, (rtol, atol))
        keep = energy_outputs >= 0 and energy_run.wanted(sys, self.cm)
        self.work = Work.for_model(self.cm, energy_outputs if keep else -1)
        self.energy = None   # after integrate: the bookkeeping's D and W at the outputs (energy_run.take)
        self.friction = friction_run.FrictionModes(sys, self.cm, self.work) if len(self.cm.friction[0]) else None
        self.pyloads = pyloads.attach(sys, self.cm, self.work)   # Python-callable loads, called back
        self.rtol, self.atol = float(rtol), float(atol)
        self.max_step = np.inf if not max_step else float(max_step)
        self.max_steps = int(max_steps)
        self.stats = np.zeros(6, dtype=np.int64)
        self.stiff_check = bool(stiff_check)
        self.sensors = list(getattr(sys.model, "sensors", {}).values())   # watched by the kernel (fastdop.run)
        self.sensor_events = []
        self.run_error = None   # the error that ended the run (a raising progress callback or load callable)

    def integrate(self, t0, y0, tout, progress=None, checkpoints=False, partial=None):
        """Output states (Y, n_written, status, t_fail, y_last) from the consistent state y0 at t0 over
        tout; accelerations and multipliers at them come from `outputs` (on demand). With `checkpoints`,
        every accepted step's start state and (t, h) are kept (self.checkpoints, within
        CHECKPOINT_BUDGET bytes, else None) for dense output on demand. After each chunk of outputs,
        `notify(progress, t, build)` with build() = partial(Y, n_written) when `partial` is given."""
        a, w = self.cm.arrays(), self.work.arrays()
        self.angle_ref0 = w[44][7].copy()   # the continued joint angles' references at the start
        nout = len(tout)
        y = np.zeros(self.state_size) if self.joint_space else np.array(y0, dtype=float)  # trees: set by run
        n = len(y)
        Y = np.zeros((nout, len(y0)))
        f = np.zeros(n)
        Y[0] = y0   # the start row (a tree's joint state is read from it; else the first output overwrites it)
        iout = 0
        if abs(tout[0] - t0) <= 1e-14 * max(1.0, abs(t0)):
            iout = 1
        st = np.array([t0, 0.0])   # h = 0: the kernel starts with f(t0, y0) and its starting step
        status = 0
        K, F, sc = np.zeros((16, n)), np.zeros((7, n)), np.zeros((4, n))
        keep = checkpoints and n * 8 * 64 <= CHECKPOINT_BUDGET
        SY, ST, ns = np.zeros((64 if keep else 0, n)), np.zeros((64 if keep else 0, 2)), np.zeros(1, np.int64)
        watch = bool(self.sensors) or self.friction is not None
        if self.friction is not None:   # the initial modes (all joints at rest decided together)
            self.friction.decide(t0, y)
        try:
            while status in (0, fastdop.CHECKPOINTS_FULL, fastdop.EVENTS_FULL, fastdop.FRICTION_EVENT) and iout < nout:
                if status == fastdop.FRICTION_EVENT:   # a stick/slip event at st[0]: decide, restart there
                    self.friction.decide(st[0], y)
                    st[1] = 0.0
                if status == fastdop.CHECKPOINTS_FULL:   # grow, or stop keeping them beyond the budget
                    if 2 * SY.size * 8 <= CHECKPOINT_BUDGET:
                        SY = np.concatenate([SY, np.zeros_like(SY)])
                        ST = np.concatenate([ST, np.zeros_like(ST)])
                    else:
                        keep, SY, ST = False, SY[:0], ST[:0]
                self._take_events()
                status, iout = fastdop.run(a, w, fastdop.COEFFS, st, y, f, float(tout[-1]), tout, iout, Y,
                                           self.rtol, self.atol, self.max_step, self.max_steps, CHUNK,
                                           1e-12, self.stats, K, F, sc, self.stiff_check, SY, ST, ns, watch)
                if st[1] == 0.0:   # the start failed: not even the initial state is an output
                    if st[0] == t0:   # (a restart after a friction event keeps the outputs before it)
                        iout = 0
                    break
                notify(progress, st[0], None if partial is None else (lambda n=iout: partial(Y, n)))
        except KeyboardInterrupt:   # arrives between chunks; every output written so far is kept
            status = INTERRUPTED
        except ProgressError as exc:   # the same for a raising progress callback
            status, self.run_error = PROGRESS_FAILED, exc
        status, self.run_error = pyloads.settle(self.pyloads, status, self.run_error)
        energy_run.take(self, iout)
        self._take_events()
        if checkpoints:
            self.checkpoints = (SY[:ns[0]].copy(), ST[:ns[0]].copy()) if keep else None
        self.last_state = y.copy()   # the integrator's own last state (a tree's joint state: the hand-over)
        if self.joint_space and status != 0:   # the last state as absolute coordinates (failure reports, and
            ymax = np.zeros(len(y0))            # a sensor's stop: continuous with the last output)
            fastdyn.write_state(a, w, y, ymax, Y[iout - 1] if status == fastdop.SENSOR_STOP and iout else ymax[:0])
            y = ymax
        return Y, iout, status, st[0], y

    def _take_events(self):
        """Move the sensor events the kernel found (time [s], sensor index) to self.sensor_events."""
        if not self.sensors:
            return
        ew = self.work.arrays()[44]
        for t, k in ew[4][:int(ew[5][0])].tolist():
            s = self.sensors[int(k)]
            self.sensor_events.append(SensorEvent(s.name, float(t), float(s.value), s.action))
        ew[5][0] = 0

    @property
    def joint_space(self) -> bool:
        """True when the model is integrated in joint coordinates (a tree of one-DOF joints)."""
        return int(self.cm.dims[5]) == 1

    @property
    def state_size(self) -> int:
        """Length of the integrator's state: nq + nv, or twice the moving joints of a tree."""
        if not self.joint_space:
            return int(self.cm.dims[0] + self.cm.dims[1])
        return 2 * int(np.count_nonzero(self.cm.tree[7] >= 0))

    def state_of(self, yrow):
        """The integrator's state of an output row [q, v] (joint coordinates and rates for a tree)."""
        yrow = np.asarray(yrow, dtype=float)
        if not self.joint_space:
            return yrow.copy()
        y = np.zeros(self.state_size)
        fastdyn.read_state(self.cm.arrays(), self.work.arrays(), yrow, y)
        return y

    def outputs(self, times, Y):
        """(VD, LAM): accelerations and multipliers of the independent rows at the output states Y;
        SolverError naming the time if the equations of motion are singular at one of them."""
        sys = self.sys
        VD, LAM = np.zeros((len(times), sys.nv)), np.zeros((len(times), sys.nc))
        YJ = self.joint_states(times, Y)
        if YJ is None:   # absolute coordinates: the references of the joint angles read from the frames
            YJ = self.angle_refs(times, Y)
        times = np.asarray(times, float)
        with self.kept_angle_refs():
            for sel in ([slice(None)] if self.friction is None else self.friction.groups(times)):   # the modes then
                YJs = np.zeros((len(times), 0)) if YJ is None else YJ
                VDs, LAMs = np.zeros_like(VD[sel]), np.zeros_like(LAM[sel])
                done = fastdop.outputs_at(self.cm.arrays(), self.work.arrays(), times[sel],
                                          np.ascontiguousarray(Y[sel]), np.ascontiguousarray(YJs[sel]), VDs, LAMs)
                if done < len(VDs):
                    raise SolverError(_MESSAGES[SINGULAR] + " at an output time", time=float(times[sel][done]))
                VD[sel], LAM[sel] = VDs, LAMs
        return VD, LAM

    def angle_refs(self, times, Y, steps=False):
        """The joint angles' references at the rows Y (solvers.anglerefs.angle_refs)."""
        return anglerefs.angle_refs(self, times, Y, steps)

    def kept_angle_refs(self):
        """A context keeping the run's joint-angle references (solvers.anglerefs.kept)."""
        return anglerefs.kept(self.work.arrays()[44][7])

    def joint_states(self, times, Y):
        """Tree path: the joint state [theta, theta_dot] of each output row Y[k] at times[k] with continuous
        angles, each continued from the run's own state at the last accepted step before it when the run
        kept its steps (checkpoints), else from the previous row (np.unwrap); None on the absolute path."""
        if not self.joint_space:
            return None
        a, w = self.cm.arrays(), self.work.arrays()
        Y = np.ascontiguousarray(Y, dtype=float)
        YJ = np.zeros((len(Y), self.state_size))
        cp = getattr(self, "checkpoints", None)
        if cp is not None and len(cp[1]):
            SY, ST = cp
            k = np.clip(np.searchsorted(ST[:, 0], np.asarray(times, float), side="right") - 1, 0, len(ST) - 1)
            fastdyn.joint_rows(a, w, Y, np.ascontiguousarray(SY[k]), YJ)
        else:
            fastdyn.joint_rows(a, w, Y, np.zeros((1, self.state_size)), YJ)
            jtype, qadr = self.cm.tree[1], self.cm.tree[7]
            ang = qadr[(qadr >= 0) & (jtype == 1)]
            YJ[:, ang] = np.unwrap(YJ[:, ang], axis=0)
        return YJ

    def states_at(self, times, Y, ts):
        """(q, v, vd, lambda_) at times ts: from the dense output of the run's own step containing each t
        (redone from its checkpoint), else by re-integrating from the sample at or before t (one compiled
        call per time: `fastdop.span`)."""
        ts = np.atleast_1d(np.asarray(ts, dtype=float))
        cp = getattr(self, "checkpoints", None)
        if cp is not None and len(cp[1]):
            k = np.clip(np.searchsorted(times, ts), 0, len(times) - 1)
            k = np.where((k > 0) & (np.abs(times[k - 1] - ts) < np.abs(times[k] - ts)), k - 1, k)
            at_sample = np.abs(times[k] - ts) <= 1e-14 * np.maximum(1.0, np.abs(ts))
            if not np.any(at_sample):
                return self._from_checkpoints(cp, ts)
            # output times give the stored samples themselves (bit-identical), the rest the dense output
            Ys = np.array(Y[k], dtype=float)
            VD, LAM = self.outputs(ts, Ys)
            if not np.all(at_sample):
                rest = np.flatnonzero(~at_sample)
                q, v, vd, lam = self._from_checkpoints(cp, ts[rest], full=False)
                Ys[rest], VD[rest], LAM[rest] = np.hstack([q, v]), vd, lam
            nq = self.sys.nq
            return Ys[:, :nq], Ys[:, nq:], VD, _full_multipliers(self.sys, self.rows, ts, Ys, VD, LAM)
        n = Y.shape[1]
        Ys, VD, LAM = np.zeros((len(ts), n)), np.zeros((len(ts), self.sys.nv)), np.zeros((len(ts), self.sys.nc))
        a, w = self.cm.arrays(), self.work.arrays()
        ns = len(self.state_of(Y[0]))
        YJ0 = self.joint_states(times, Y)   # a tree's continuous joint states to restart from
        R0 = self.angle_refs(times, Y)      # (absolute coordinates: the joint angles' references there)
        K, F, sc, f = np.zeros((16, ns)), np.zeros((7, ns)), np.zeros((4, ns)), np.zeros(ns)
        with self.kept_angle_refs():
            self._spans(times, Y, ts, YJ0, R0, Ys, VD, LAM, K, F, sc, f)
        nq = self.sys.nq
        return Ys[:, :nq], Ys[:, nq:], VD, _full_multipliers(self.sys, self.rows, ts, Ys, VD, LAM)

    def _spans(self, times, Y, ts, YJ0, R0, Ys, VD, LAM, K, F, sc, f):
        """`states_at` without checkpoints: one short re-integration (`fastdop.span`) per time in ts from the
        output at or before it, into Ys, VD, LAM."""
        a, w = self.cm.arrays(), self.work.arrays()
        n, ns = Y.shape[1], len(f)
        for j, t in enumerate(ts):
            k = max(int(np.searchsorted(times, t, side="right")) - 1, 0)
            tout = np.array([t]) if abs(times[k] - t) <= 1e-14 * max(1.0, abs(t)) else np.array([times[k], t])
            Yk, VDk, LAMk = np.zeros((len(tout), n)), np.zeros((len(tout), self.sys.nv)), np.zeros((len(tout), self.sys.nc))
            y0 = self.state_of(Y[k]) if YJ0 is None else YJ0[k].copy()
            if R0 is not None:
                w[44][7][:] = R0[k]
            if self.friction is not None:   # the modes at the restart sample (the run's steps are not kept)
                self.friction.set_modes(float(times[k]))
            YJk = np.zeros((len(tout), 0 if YJ0 is None else ns))
            status, m = fastdop.span(a, w, fastdop.COEFFS, np.array([times[k], 0.0]), y0, f, tout, Yk, YJk, VDk, LAMk,
                                     self.rtol, self.atol, self.max_step, self.max_steps, self.stats, K, F, sc)
            if m < len(tout):
                raise SolverError(_MESSAGES.get(status, "integration failed"), time=float(t))
            Ys[j], VD[j], LAM[j] = Yk[-1], VDk[-1], LAMk[-1]


    def step_states(self, t_last, y_last):
        """(t, q, v) at the start of every accepted step (the checkpoints, absolute coordinates) and at
        (t_last, y_last), or None when the run kept no checkpoints."""
        cp = getattr(self, "checkpoints", None)
        if cp is None or not len(cp[1]):
            return None
        SY, ST = cp
        inside = ST[:, 0] < t_last
        SY, ST = SY[inside], ST[inside]
        n = self.sys.nq + self.sys.nv
        Y = np.zeros((len(SY) + 1, n))
        if self.joint_space:
            a, w = self.cm.arrays(), self.work.arrays()
            for j in range(len(SY)):
                fastdyn.write_state(a, w, SY[j].copy(), Y[j], Y[j][:0])
        else:
            Y[:-1] = SY
        Y[-1] = y_last
        return np.append(ST[:, 0], t_last), Y[:, :self.sys.nq], Y[:, self.sys.nq:]

    def _from_checkpoints(self, cp, ts, full=True):
        SY, ST = cp
        sys = self.sys
        n, ns = sys.nq + sys.nv, SY.shape[1]
        Ys, VD, LAM = np.zeros((len(ts), n)), np.zeros((len(ts), sys.nv)), np.zeros((len(ts), sys.nc))
        a, w = self.cm.arrays(), self.work.arrays()
        K, F, sc, f = np.zeros((16, ns)), np.zeros((7, ns)), np.zeros((4, ns)), np.zeros(ns)
        step = np.clip(np.searchsorted(ST[:, 0], ts, side="right") - 1, 0, len(ST) - 1)
        R = self.angle_refs(ST[:, 0], SY, steps=True)   # the joint angles' references at the steps
        with self.kept_angle_refs():
            self._redo_steps(SY, ST, ts, step, R, Ys, VD, LAM, K, F, sc, f)
        nq = sys.nq
        return Ys[:, :nq], Ys[:, nq:], VD, (_full_multipliers(sys, self.rows, ts, Ys, VD, LAM) if full else LAM)

    def _redo_steps(self, SY, ST, ts, step, R, Ys, VD, LAM, K, F, sc, f):
        """The outputs at ts of the run's steps `step` redone from their checkpoints (`fastdop.from_checkpoint`)
        into Ys, VD, LAM; R: the joint angles' references at the steps (or None)."""
        sys = self.sys
        n = sys.nq + sys.nv
        a, w = self.cm.arrays(), self.work.arrays()
        for j in np.unique(step):
            sel = np.flatnonzero(step == j)
            t0, h = ST[j]
            if R is not None:
                w[44][7][:] = R[j]
            if self.friction is not None:   # the modes in force during that step
                self.friction.set_modes(float(t0))
            tq = np.clip(ts[sel], t0, t0 + h)
            Yk, VDk, LAMk = np.zeros((len(sel), n)), np.zeros((len(sel), sys.nv)), np.zeros((len(sel), sys.nc))
            status = fastdop.from_checkpoint(a, w, fastdop.COEFFS, float(t0), float(h), SY[j].copy(), f, tq, Yk,
                                             VDk, LAMk, K, F, sc)
            if status != 0:
                raise SolverError(_MESSAGES.get(status, "integration failed"), time=float(ts[sel[0]]))
            Ys[sel], VD[sel], LAM[sel] = Yk, VDk, LAMk


class Stiff(Exception):
    """The explicit method detected stiffness (the automatic method then switches to an implicit one).

    time: the start [s] of the step that was flagged; prefix: what the explicit run computed up to it
    (the automatic method continues from there: mbdsim.solvers.autoswitch), a dict with run (the
    CompiledRun, its checkpoints kept), times and Y (output times [s] <= time and their [q, v] rows),
    y (the consistent [q, v] at `time`, absolute coordinates) and stats (the explicit run's statistics)."""

    def __init__(self, t, prefix=None):
        super().__init__(f"stiff at t = {t:.9g} s")
        self.time = t
        self.prefix = prefix


def integrate_compiled(sys, rep, times, rtol, atol, max_step, progress=None, stiff_check=False) -> Result:
    """Dynamic analysis of System `sys` from the assembled state `rep` over the output grid `times`
    with the compiled DOP853 (raises NotCompiled when the model needs the reference path, and Stiff
    when stiff_check is set and the model is stiff). progress(t) is called with the time reached [s]
    every chunk of outputs; Ctrl-C ends the run with success=False and every output before it."""
    friction = len(sys.lock_rows) > 0   # joint friction: absolute coordinates (stiff: on to Radau, its modes)
    if sys.derived.get("friction not compiled"):   # a held group met by an earlier try (solvers.friction_run)
        raise NotCompiled(sys.derived["friction not compiled"])
    run = CompiledRun(sys, rep.rows, rtol, atol, max_step, stiff_check=stiff_check, state=(rep.q, rep.v),
                      friction=friction, energy_outputs=len(times))
    y0 = np.concatenate([rep.q, rep.v])
    success, message, error = True, "ok", None
    times = np.asarray(times, float)
    partial = lambda Y, n: _result(sys, rep, run, times[:n], Y[:n], stats={"assembly": rep})  # noqa: E731
    Y, n, status, t_fail, y_fail = run.integrate(times[0], y0, times, progress, True, partial)
    if status == FRICTION_FAILED:   # name the element whose coupled solve failed
        run.run_error = run.friction.failure(t_fail, y_fail)
    if status == STIFF:
        raise Stiff(float(t_fail), dict(run=run, times=times[:n], Y=Y[:n], y=y_fail, stats=_stats(run, rep)))
    extra = False   # the last sample is the run's end state (for its energy bookkeeping)
    if status == fastdop.SENSOR_STOP:   # the state at the sensor's time is the last sample
        from .radau_run import sensor_stop
        n_before = n
        times, Y, n, message = sensor_stop(run, times, Y, n, t_fail, y_fail)
        extra = n > n_before
        status = 0
    if status != 0:
        error, message = failure(sys, rep, status, t_fail, y_fail, times[:n], "integration failed",
                                 run.run_error)
        success = False
    stats = _stats(run, rep)
    res = _result(sys, rep, run, times[:n], Y[:n], success=success, message=message, stats=stats)
    energy_run.attach(res, run, extra)
    res.error = error
    if run.sensors:
        res.sensor_events = run.sensor_events
    return res


def failure(sys, rep, status, t_fail, y_fail, t_done, fallback, error=None):
    """(error, message) of a compiled run that ended with kernel status `status` at t_fail [s] in state
    y_fail = [q, v]: a SolverError naming the time and the joints nearest to dependent rows (or
    AnalysisInterrupted for Ctrl-C; `error` itself when given, e.g. the ProgressError of status
    PROGRESS_FAILED), and the Result's message with the last output time of t_done [s]; `fallback`: the
    text for a status without a message of its own."""
    from ..system.dynamics import massless_note
    from .common import _weak_joints, blame_load
    if error is None and status in (NONFINITE, TINY_STEP):   # a load that is not finite there, named
        for t in (float(t_fail), float(t_fail) + 1e-9 * max(1.0, abs(t_fail))):   # (also just past a collapse)
            error = blame_load(sys, t, y_fail)
            if error is not None:
                break
    if error is None:
        try:
            joints = [] if status in (INTERRUPTED, PROGRESS_FAILED, CALLBACK_FAILED) else \
                _weak_joints(sys, y_fail[:sys.nq], y_fail[sys.nq:], t_fail, rep.rows)
        except (MbdsimError, np.linalg.LinAlgError, ValueError):
            joints = []
        cls = AnalysisInterrupted if status == INTERRUPTED else SolverError
        text = _MESSAGES.get(status, fallback)
        if status == SINGULAR:
            text = text[:-1] + massless_note(sys) + ")"
        error = cls(text, time=float(t_fail), joints=joints, state=y_fail[:sys.nq])
    last = f"{t_done[-1]:.9g}" if len(t_done) else "none"
    return error, f"{error}; last good output at t = {last} s"


def _stats(run, rep) -> dict:
    """res.stats of a compiled run (steps, rejected, evaluations, factorisations, projections, order)."""
    return {"steps": int(run.stats[0]), "rejected": int(run.stats[1]), "nfev": int(run.stats[2]),
            "njev": 0,   # joint coordinates: no factorisation (ABA) and nothing to project
            "factorizations": 0 if run.joint_space else int(run.stats[2] + 2 * run.stats[3]),
            "projections": int(run.stats[3]) if not run.joint_space or len(run.cm.coords[3]) > 1 else 0,
            "order": 8,   # (a tree projects only onto its coordinate constraints: solvers.treecoord)
            "method": "DOP853 (compiled)", "called_back": tuple(run.cm.python_loads),
            "formulation": "joint coordinates (articulated body)" if run.joint_space else
            "absolute coordinates (tree elimination)", "assembly": rep}


def _result(sys, rep, run, t_out, Y, success=True, message="ok", stats=None) -> Result:
    """The Result of output states Y (positions and velocities) at t_out; accelerations and multipliers
    computed on first use (most runs are read for positions only), dense output from the run."""
    nq = sys.nq

    def accelerations():
        VD, LAM = run.outputs(t_out, Y)
        return VD, _full_multipliers(sys, rep.rows, t_out, Y, VD, LAM)

    res = Result(sys, t_out, Y[:, :nq], Y[:, nq:], None, None, evaluate=lambda ts: run.states_at(t_out, Y, ts),
                 success=success, status=0 if success else -1, message=message, stats=stats,
                 accelerations=accelerations)
    if len(t_out):   # the run's own steps (checkpoints), for joint angles independent of the sampling
        res.steps = lambda: run.step_states(float(t_out[-1]), Y[-1])
    res.residual_check = residual_check(run, t_out, Y)
    return res


def residual_check(run, t_out, Y):
    """Result.residual_check of a compiled run (CompiledRun or KinematicRun) with output rows Y = [q, v]
    (absolute coordinates) at t_out [s]: check(idx, rows) -> (max |phi[rows]| [m or rad] at each sample
    idx, the row where it occurs), all samples in one compiled call (`fastdyn.residuals`)."""
    def check(idx, rows):
        idx, rows = np.asarray(idx, dtype=np.int64), np.asarray(rows, dtype=np.int64)
        val, arg = np.zeros(len(idx)), np.zeros(len(idx), dtype=np.int64)
        fastdyn.residuals(run.cm.arrays(), run.work.arrays(), t_out, Y, idx, rows, val, arg)
        return val, arg
    return check


# bytes of dense Jacobians that the minimum-norm multipliers of a model with redundant rows hold at once
# (samples are taken in chunks within it; a model whose single sample exceeds it gets a clear error)
MULTIPLIER_BYTES = 512 * 2 ** 20


def _full_multipliers(sys, rows, times, Y, VD, LAM):
    """Multipliers of every row: as solved when all rows are independent, else the minimum-norm
    lambda_ with phi_q^T lambda_ = phi_q,rows^T lambda_rows (the constraint load the solve found) over all
    rows, so that the determinate components are exact. All samples in one compiled call with r x r and
    d x d Cholesky solves only (d dependent rows; mbdsim.solvers.minnorm), the SVD pseudo-inverse where
    the rows are dependent at the sample's configuration too (a change point) or where the kernel solved
    for other loop rows than `rows` (re-selected as the configuration changed: LAM nonzero off `rows`).
    The lock rows of joint friction keep their multipliers as solved (the friction loads) and take no share."""
    keep = np.asarray(getattr(sys, "lock_rows", ()), dtype=np.int64)
    if len(rows) + len(keep) == sys.nc or not len(times):
        return LAM
    per_sample = 8 * sys.nc * sys.nv   # bytes of one sample's dense Jacobian
    if per_sample > MULTIPLIER_BYTES:
        names = sorted({sys.row_owner[r] for r in np.setdiff1d(np.arange(sys.nc), rows)})
        raise MbdsimError(
            f"the minimum-norm multipliers of the {sys.nc - len(rows)} redundant constraint rows (of "
            f"{', '.join(names[:5])}{', ...' if len(names) > 5 else ''}) need "
            f"a dense {sys.nc} x {sys.nv} Jacobian per sample ({per_sample / 1e9:.2g} GB, over the "
            f"{MULTIPLIER_BYTES / 1e9:.2g} GB budget): remove the redundant rows (e.g. spherical or "
            "universal joints instead of revolutes in a closed loop) to have reactions on a model this large; "
            "positions, velocities and accelerations are not affected")
    step = max(1, MULTIPLIER_BYTES // per_sample)
    if len(times) > step:   # in chunks of samples, so that the Jacobians in memory stay within the budget
        parts = [_full_multipliers(sys, rows, times[k:k + step], Y[k:k + step], None, LAM[k:k + step])
                 for k in range(0, len(times), step)]
        return np.concatenate(parts)
    J = jacobians(sys, Y[:, :sys.nq])                       # (N, nc, nv); LAM is zero off `rows` unless re-selected
    cols = np.setdiff1d(np.arange(sys.nc), keep)   # the rows that share the constraint load (all but locks)
    Js = J if not len(keep) else np.ascontiguousarray(J[:, cols])
    rows = np.searchsorted(cols, np.asarray(rows, dtype=np.int64)).astype(np.int64)
    key = ("dependent rows", rows.tobytes(), keep.tobytes())
    dep = sys.derived.get(key)
    if dep is None:   # the same rows at every call of a run: computed once (the rows not in `rows`, sorted)
        free = np.ones(len(cols), dtype=bool)
        free[rows] = False
        dep = sys.derived[key] = np.flatnonzero(free).astype(np.int64)
    LAMs = np.ascontiguousarray(LAM[:, cols], dtype=float)
    outs, bad = np.zeros_like(LAMs), np.zeros(len(LAMs), dtype=np.bool_)
    minnorm.min_norm_multipliers(Js, LAMs, rows, dep, outs, bad)
    bad |= np.any(LAMs[:, dep] != 0.0, axis=1)   # the kernel re-selected its loop rows (fastdyn._reselect)
    if np.any(bad):   # rows dependent at this configuration too (a change point): SVD pseudo-inverse
        load = np.einsum("nri,nr->ni", Js[bad], LAMs[bad])
        rcond = np.finfo(float).eps * max(sys.nc, sys.nv)
        outs[bad] = np.einsum("nij,nj->ni", np.linalg.pinv(np.transpose(Js[bad], (0, 2, 1)), rcond=rcond), load)
    out = np.array(LAM, dtype=float)   # (the locks' columns as solved)
    out[:, cols] = outs
    keep_jacobians(sys, out, J)   # the reactions read from these multipliers reuse their Jacobians
    return out


def _rms(x, scale) -> float:
    s = 0.0
    for xi, si in zip(x.tolist(), scale):
        r = xi / si
        s += r * r   # numba's x ** 2 (integer literal) is x * x
    return math.sqrt(s / len(scale))


def initial_step(a, w, t0, y0, f0, rtol, atol, max_step) -> float:
    """`fastdop.initial_step` (Hairer's starting step [s]) in Python around the already loaded `fastdop.rhs`:
    the same IEEE operations in the same order, so the same bits (tests/test_stream_memory.py compares
    them), without loading that kernel's ~11 MB of machine code for one call per run. a, w: the compiled
    model's and work arrays; y0, f0: state and its derivative at t0."""
    scale = [atol + abs(v) * rtol for v in y0.tolist()]
    d0, d1 = _rms(y0, scale), _rms(f0, scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, max_step)
    y1 = y0 + h0 * f0
    work = np.zeros(len(y0))
    if fastdop.rhs(a, w, t0 + h0, y1, work, True) != fastdop.OK:
        return h0
    d2 = _rms(work - f0, scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, max_step)
