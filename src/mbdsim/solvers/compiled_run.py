"""Python side of the compiled integrator: chunks of outputs, failure reports, Result building.

`integrate_compiled` runs `fastdop.run` over the output grid in chunks (Python is re-entered once per
chunk of outputs, for Ctrl-C and progress), and turns a failure status into a SolverError naming the
time and the joints while keeping every output written before it. `Result.at` between samples
re-integrates from the bracketing sample with the same tolerances (dense output on demand, no
per-step storage).
"""
from __future__ import annotations

import numpy as np

from ..errors import MbdsimError, SolverError
from ..results.result import Result
from ..system.compiled import Work, compile_system
from . import fastdop
from .fastdyn import INTERRUPTED, MAX_STEPS, NONFINITE, PROJECTION, SINGULAR, STIFF, TINY_STEP

_MESSAGES = {SINGULAR: "singular equations of motion (lock-up or singular configuration)",
             PROJECTION: "projection onto the constraints does not converge",
             NONFINITE: "non-finite state (the solution diverged)",
             TINY_STEP: "step size collapsed below the round-off limit (lock-up, singular configuration "
                        "or a discontinuity)",
             MAX_STEPS: "step budget exhausted (max_steps)",
             STIFF: "the model is stiff for an explicit method",
             INTERRUPTED: "interrupted (KeyboardInterrupt)"}
CHUNK = 256


class CompiledRun:
    """A compiled model and its work arrays for one analysis (immutable model, per-run state)."""

    def __init__(self, sys, rows, rtol, atol, max_step, max_steps=10_000_000, stiff_check=False):
        self.sys, self.rows = sys, rows
        self.cm = compile_system(sys, rows)
        self.work = Work.for_model(self.cm)
        self.rtol, self.atol = float(rtol), float(atol)
        self.max_step = np.inf if not max_step else float(max_step)
        self.max_steps = int(max_steps)
        self.stats = np.zeros(6, dtype=np.int64)
        self.stiff_check = bool(stiff_check)

    def integrate(self, t0, y0, tout, progress=None):
        """Output states (Y, n_written, status, t_fail, y_last) from the consistent state y0 at t0 over
        tout; accelerations and multipliers at them come from `outputs` (on demand)."""
        a, w = self.cm.arrays(), self.work.arrays()
        n, nout = len(y0), len(tout)
        Y = np.zeros((nout, n))
        y, f = np.array(y0, dtype=float), np.zeros(n)
        status = fastdop.rhs(a, w, t0, y, f)
        iout = 0
        if status == 0 and abs(tout[0] - t0) <= 1e-14 * max(1.0, abs(t0)):
            Y[0] = y
            iout = 1
        st = np.array([t0, 0.0])
        if status == 0:
            st[1] = fastdop.initial_step(a, w, t0, y, f, self.rtol, self.atol, self.max_step, np.zeros(n),
                                         np.zeros(n), np.zeros(n))
        K, F, sc = np.zeros((16, n)), np.zeros((7, n)), np.zeros((4, n))
        try:
            while status == 0 and iout < nout:
                status, iout = fastdop.run(a, w, fastdop.COEFFS, st, y, f, float(tout[-1]), tout, iout, Y,
                                           self.rtol, self.atol, self.max_step, self.max_steps, CHUNK,
                                           1e-12, self.stats, K, F, sc, self.stiff_check)
                if progress is not None:
                    progress(float(st[0]))
        except KeyboardInterrupt:   # arrives between chunks; every output written so far is kept
            status = INTERRUPTED
        return Y, iout, status, st[0], y

    def outputs(self, times, Y):
        """(VD, LAM): accelerations and multipliers of the independent rows at the output states Y;
        SolverError naming the time if the equations of motion are singular at one of them."""
        sys = self.sys
        VD, LAM = np.zeros((len(times), sys.nv)), np.zeros((len(times), sys.nc))
        done = fastdop.outputs_at(self.cm.arrays(), self.work.arrays(), np.asarray(times, float), Y, VD, LAM)
        if done < len(times):
            raise SolverError(_MESSAGES[SINGULAR] + " at an output time", time=float(times[done]))
        return VD, LAM

    def states_at(self, times, Y, ts):
        """(q, v, vd, lambda_) at times ts by re-integrating from the sample at or before each t."""
        out = []
        for t in np.atleast_1d(ts):
            k = max(int(np.searchsorted(times, t, side="right")) - 1, 0)
            if abs(times[k] - t) <= 1e-14 * max(1.0, abs(t)):
                out.append(Y[k])
                continue
            Yk, m, status, _, _ = self.integrate(times[k], Y[k], np.array([times[k], t]))
            if m < 2:
                raise SolverError(_MESSAGES.get(status, "integration failed"), time=float(t))
            out.append(Yk[-1])
        nq = self.sys.nq
        Ys = np.array(out).reshape(-1, len(Y[0]))
        VD, LAM = self.outputs(np.atleast_1d(ts), Ys)
        return Ys[:, :nq], Ys[:, nq:], VD, _full_multipliers(self.sys, self.rows, np.atleast_1d(ts), Ys, VD, LAM)


class Stiff(Exception):
    """The explicit method detected stiffness (the automatic method then switches to an implicit one)."""

    def __init__(self, t):
        super().__init__(f"stiff at t = {t:.9g} s")
        self.time = t


def integrate_compiled(sys, rep, times, rtol, atol, max_step, progress=None, stiff_check=False) -> Result:
    """Dynamic analysis of System `sys` from the assembled state `rep` over the output grid `times`
    with the compiled DOP853 (raises NotCompiled when the model needs the reference path, and Stiff
    when stiff_check is set and the model is stiff). progress(t) is called with the time reached [s]
    every chunk of outputs; Ctrl-C ends the run with success=False and every output before it."""
    run = CompiledRun(sys, rep.rows, rtol, atol, max_step, stiff_check=stiff_check)
    y0 = np.concatenate([rep.q, rep.v])
    success, message, error = True, "ok", None
    Y, n, status, t_fail, y_fail = run.integrate(times[0], y0, np.asarray(times, float), progress)
    if status == STIFF:
        raise Stiff(float(t_fail))
    if status != 0:
        from .dynamic import _weak_joints
        try:
            joints = [] if status == INTERRUPTED else _weak_joints(sys, y_fail[:sys.nq], y_fail[sys.nq:], t_fail,
                                                                   rep.rows)
        except (MbdsimError, np.linalg.LinAlgError, ValueError):
            joints = []
        error = SolverError(_MESSAGES.get(status, "integration failed"), time=float(t_fail), joints=joints,
                            state=y_fail[:sys.nq])
        last = f"{times[n - 1]:.9g}" if n else "none"
        success, message = False, f"{error}; last good output at t = {last} s"
    nq = sys.nq
    t_out, Y = times[:n], Y[:n]

    def accelerations():   # on first use of vd / lambda_ (most runs are read for positions only)
        VD, LAM = run.outputs(t_out, Y)
        return VD, _full_multipliers(sys, rep.rows, t_out, Y, VD, LAM)

    res = Result(sys, t_out, Y[:, :nq], Y[:, nq:], None, None,
                 evaluate=lambda ts: run.states_at(t_out, Y, ts), success=success,
                 status=0 if success else -1, message=message,
                 stats={"steps": int(run.stats[0]), "rejected": int(run.stats[1]), "nfev": int(run.stats[2]),
                        "njev": 0, "factorizations": int(run.stats[2] + 2 * run.stats[3]),
                        "projections": int(run.stats[3]), "order": 8, "method": "DOP853 (compiled)",
                        "assembly": rep}, accelerations=accelerations)
    res.error = error
    return res


def _full_multipliers(sys, rows, times, Y, VD, LAM):
    """Multipliers of every row: as solved when all rows are independent, else the minimum-norm
    solution of phi_q^T lambda_ = Q - M vd over all rows (determinate components exact)."""
    if len(rows) == sys.nc or not len(times):
        return LAM
    from ..system.dynamics import applied_forces
    from ..system.equations import constraint_terms
    from ..system.frames import body_frames
    from .state import state_factory
    sf = state_factory(sys)
    out = np.zeros_like(LAM)
    for k, t in enumerate(times):
        q, v = Y[k, :sys.nq], Y[k, sys.nq:]
        _, J, _, _ = constraint_terms(sys, q, v, t)
        Q = applied_forces(sys, body_frames(sys, q, v), t, sf(t, q, v) if sf else None)
        out[k] = np.linalg.lstsq(J.T, Q - sys.M @ VD[k], rcond=None)[0]
    return out
