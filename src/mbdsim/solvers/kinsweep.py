"""Zero-DOF models under the automatic method: a kinematic sweep instead of an integration.

When the joints and motion drivers leave no degree of freedom (assembly's `dof == 0`: nv minus the
rank of the independent constraint rows, drivers included), the motion is fixed by the constraints:
each output time is solved from phi(q, t) = 0, phi_q v = nu and the equations of motion
M vd + phi_q^T lambda_ = Q, phi_q vd = gamma (as MSC Adams does for a dynamic simulation of a
zero-DOF model). The result is exact to the Newton tolerance PROJ_TOL (no integration error, no
rtol): `fastkin.sweep` does the whole grid in compiled code, Python is re-entered once per chunk
of outputs (progress, Ctrl-C). A failure (a driver moving the mechanism into lock-up) ends the run
with success=False, every output before it kept, and a SolverError naming the time and the joints,
as the compiled integrator does (`compiled_run.integrate_compiled`). docs/theory.md section 6b.
"""
from __future__ import annotations

import numpy as np

from ..errors import SolverError
from ..results.result import Result
from ..results.stream import ProgressError, notify
from ..system.compiled import Work, compile_system
from . import anglerefs, fastdyn, fastkin, pyloads
from .compiled_run import CHUNK, PROGRESS_FAILED, _MESSAGES, _full_multipliers, failure, residual_check
from .fastdyn import INTERRUPTED, OK

PROJ_TOL = 1e-12   # Newton tolerance on max |phi| [m or rad], as the compiled integrator's projection
METHOD = "kinematic (0 DOF)"


class KinematicRun:
    """A compiled zero-DOF model, its work arrays and counters for one kinematic sweep."""

    def __init__(self, sys, rep):
        self.sys, self.rows = sys, rep.rows
        self.cm = compile_system(sys, rep.rows, (rep.q, rep.v))
        self.work = Work.for_model(self.cm)
        self.pyloads = pyloads.attach(sys, self.cm, self.work)   # Python-callable loads, called back
        self.stats = np.zeros(6, dtype=np.int64)   # see fastkin: outputs, sub-steps, retried, projections, factorisations
        self.run_error = None   # the error that ended the sweep (a raising progress callback or load callable)
        self.refs = np.zeros((0, 0))   # the continued joint angles' references [rad] at each output (`sweep`)

    @property
    def joint_space(self) -> bool:
        """True when the compiled model is a joint-coordinate tree (integrated by DOP853 instead)."""
        return int(self.cm.dims[5]) == 1

    def _scratch(self):
        sys, nf = self.sys, int(self.cm.dims[3])
        return (np.zeros((3, max(sys.nq, sys.nv, 1))), np.zeros((nf, 6)), np.zeros((nf, 6)), np.zeros((nf, 6)))

    def sweep(self, t0, y0, tout, progress=None, partial=None):
        """(Y, VD, LAM, MN, n, status, t_last, y_last): output rows [q, v], accelerations vd and
        multipliers at tout [s] from the consistent state y0 = [q, v] at t0 [s] (tout[0] == t0): the
        minimum-norm multipliers of all rows where MN (bool) is set, else those of the independent rows
        (zero elsewhere; `multipliers` completes them); n outputs written; on failure t_last [s] and
        y_last are the last solved state. After each chunk of outputs, `notify(progress, t, build)`
        (build: partial(Y, VD, LAM, MN, n))."""
        sys = self.sys
        a, w = self.cm.arrays(), self.work.arrays()
        nout, nq = len(tout), sys.nq
        Y, VD, LAM = np.zeros((nout, nq + sys.nv)), np.zeros((nout, sys.nv)), np.zeros((nout, sys.nc))
        MN = np.zeros(nout, dtype=np.bool_)
        REF = self.refs = np.zeros((nout, len(w[44][7])))   # the continued joint angles' references there
        q, v = np.array(y0[:nq], dtype=float), np.array(y0[nq:], dtype=float)
        vd, lam = np.zeros(sys.nv), np.zeros(sys.nc)
        st = np.array([float(t0), np.inf, 0.0])
        status = fastdyn.accelerations(a, w, float(t0), q, v, q, vd, lam, True)
        self.stats[4] += 1
        iout = 0
        if status == OK:
            MN[0] = fastkin.min_norm_at(a, w, lam)
            Y[0], VD[0], LAM[0], REF[0] = y0, vd, lam, w[44][7]
            iout = 1
        S, dx6, a6, p6 = self._scratch()
        try:
            while status == OK and iout < nout:
                status, iout = fastkin.sweep(a, w, st, tout, iout, Y, VD, LAM, MN, REF, q, v, vd, lam, PROJ_TOL,
                                             CHUNK, self.stats, S, dx6, a6, p6)
                notify(progress, st[0], None if partial is None else
                       (lambda n=iout: partial(Y, VD, LAM, MN, n)))
        except KeyboardInterrupt:   # arrives between chunks; every output written so far is kept
            status = INTERRUPTED
        except ProgressError as exc:   # the same for a raising progress callback
            status, self.run_error = PROGRESS_FAILED, exc
        status, self.run_error = pyloads.settle(self.pyloads, status, self.run_error)
        return Y, VD, LAM, MN, iout, status, float(st[0]), np.concatenate([q, v])

    def multipliers(self, times, Y, VD, LAM, MN):
        """Multipliers of every row at the outputs (times [s], rows Y = [q, v]): LAM where MN says they
        are the minimum-norm ones already, `compiled_run._full_multipliers` for the others."""
        if MN.all():
            return LAM
        todo = np.flatnonzero(~MN)
        if len(todo) == len(MN):
            return _full_multipliers(self.sys, self.rows, times, Y, VD, LAM)
        out = LAM.copy()
        out[todo] = _full_multipliers(self.sys, self.rows, times[todo], Y[todo], VD[todo], LAM[todo])
        return out

    def outputs(self, times, Y):
        """(VD, LAM): accelerations and multipliers of the independent rows recomputed at the output rows
        Y = [q, v] (times [s]), as `CompiledRun.outputs`; SolverError naming the time if singular."""
        sys, a, w = self.sys, self.cm.arrays(), self.work.arrays()
        VD, LAM = np.zeros((len(times), sys.nv)), np.zeros((len(times), sys.nc))
        for k, t in enumerate(np.asarray(times, float)):
            y = np.array(Y[k], dtype=float)
            if fastdyn.accelerations(a, w, float(t), y[:sys.nq], y[sys.nq:], y[:sys.nq], VD[k], LAM[k], True) != OK:
                raise SolverError(_MESSAGES[fastdyn.SINGULAR] + " at an output time", time=float(t))
        return VD, LAM

    def states_at(self, times, Y, VD, LAM, MN, ts):
        """(q, v, vd, lambda_) at the times ts [s]: the same kinematic solve from the output at or before
        each t (all of ts in one compiled call); an output time gives its stored sample (times, Y, VD,
        LAM, MN: the outputs of `sweep`)."""
        sys = self.sys
        ts = np.atleast_1d(np.asarray(ts, dtype=float))
        n = len(ts)
        Yo, VDo, LAMo = np.zeros((n, Y.shape[1])), np.zeros((n, sys.nv)), np.zeros((n, sys.nc))
        S, dx6, a6, p6 = self._scratch()
        MNo = np.zeros(n, dtype=np.bool_)
        w = self.work.arrays()
        with anglerefs.kept(w[44][7]):   # (restarts from each output's references; the run's own kept)
            done = fastkin.states_at(self.cm.arrays(), w, np.asarray(times, float), Y, VD, LAM, MN,
                                     self.refs[:len(times)], ts, Yo, VDo, LAMo, MNo, PROJ_TOL, np.zeros(6, np.int64),
                                     S, dx6, a6, p6, np.zeros(sys.nq), np.zeros(sys.nv), np.zeros(sys.nv),
                                     np.zeros(sys.nc), np.zeros(3))
        if done < n:
            raise SolverError(_MESSAGES[fastdyn.PROJECTION] + " (kinematic solve)", time=float(ts[done]))
        nq = sys.nq
        return Yo[:, :nq], Yo[:, nq:], VDo, self.multipliers(ts, Yo, VDo, LAMo, MNo)


def integrate_kinematic(sys, rep, times, progress=None, sensors=True, continuity=False) -> Result | None:
    """Kinematic analysis of the zero-DOF System `sys` (rep: its assembled state, rep.dof == 0) over the
    output grid `times` [s]; None when the compiled model is a joint-coordinate tree or a successful
    sweep met a change point (loop rows dependent at a solved configuration, e.g. a driven parallelogram
    with its links collinear: the rates there are decided by continuity, not by the constraints): the
    caller integrates the model instead. A sweep that fails (lock-up) is reported as it is. Raises NotCompiled when the model needs the reference path. res.stats: "method"
    METHOD, "steps" the outputs solved (the first is the assembled state), "substeps" and "rejected" the
    sub-steps taken and retried between outputs, "nfev" and "njev" 0 (no right-hand side, no Jacobian
    by differences), "factorizations" and "projections" counted, "order" None (no integration formula:
    every output is exact to the Newton tolerance PROJ_TOL). sensors=False: the model's sensors are not
    watched (mb.kinematics: sensors end simulations), so they do not send the model to DOP853;
    continuity=True (mb.kinematics): a change point's rates are those of the prediction (the sub-steps'
    Taylor series), the sweep's result is returned (res.stats["change_points"]: the configurations where
    the factorisation dropped dependent rows) instead of None."""
    if sensors and getattr(sys.model, "sensors", None):   # located on an integrator's dense output (DOP853 runs it)
        from ..system.compiled import NotCompiled
        raise NotCompiled(f"sensor '{next(iter(sys.model.sensors))}': the kinematic sweep does not watch sensors")
    run = KinematicRun(sys, rep)
    if run.joint_space:
        return None
    times = np.asarray(times, float)
    y0 = np.concatenate([rep.q, rep.v])
    partial = lambda Y, VD, LAM, MN, n: _result(sys, rep, run, times[:n], Y[:n], VD[:n], LAM[:n],  # noqa: E731
                                                MN[:n], stats={"assembly": rep})
    Y, VD, LAM, MN, n, status, t_fail, y_fail = run.sweep(times[0], y0, times, progress, partial)
    if status == OK and run.stats[5] and not continuity:   # rates left to continuity somewhere: integrate instead
        return None
    success, message, error = True, "ok", None
    if status != OK:
        error, message = failure(sys, rep, status, t_fail, y_fail, times[:n], "kinematic solve failed",
                                 run.run_error)
        success = False
    s = run.stats
    stats = {"steps": int(n), "substeps": int(s[1]), "rejected": int(s[2]), "nfev": 0, "njev": 0,
             "factorizations": int(s[4]), "projections": int(s[3]), "order": None, "method": METHOD,
             "formulation": "absolute coordinates (tree elimination)", "assembly": rep, "change_points": int(s[5])}
    res = _result(sys, rep, run, times[:n], Y[:n], VD[:n], LAM[:n], MN[:n], success, message, stats)
    res.error = error
    return res


def _result(sys, rep, run, t_out, Y, VD, LAM, MN, success=True, message="ok", stats=None) -> Result:
    """The Result of the solved outputs: positions and velocities at t_out [s], accelerations and the
    multipliers of every row (minimum norm where redundant) from the stored VD, LAM, MN on first use;
    dense output (`Result.at`) by the same kinematic solve; res.steps: the outputs themselves."""
    nq = sys.nq
    res = Result(sys, t_out, Y[:, :nq], Y[:, nq:], None, None,
                 evaluate=lambda ts: run.states_at(t_out, Y, VD, LAM, MN, ts), success=success,
                 status=0 if success else -1, message=message, stats=stats,
                 accelerations=lambda: (VD, run.multipliers(t_out, Y, VD, LAM, MN)))
    if len(t_out):
        res.steps = lambda: (t_out.copy(), Y[:, :nq].copy(), Y[:, nq:].copy())
    res.residual_check = residual_check(run, t_out, Y)
    return res
