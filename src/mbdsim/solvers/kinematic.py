"""Kinematic analysis of fully driven mechanisms (zero degrees of freedom).

Positions by Newton on phi(q, t) = 0, velocities from phi_q v = nu, accelerations from phi_q vd = gamma,
reactions from the equations of motion phi_q^T lambda_ = Q - M vd (minimum norm where redundant).
"""
from __future__ import annotations


import numpy as np

from .._userwarn import warn
from .._blas import blas_single_thread
from ..errors import AssemblyError, ModelError
from ..results.result import Result
from ..system.dynamics import applied_forces
from ..system.equations import constraint_terms
from ..system.frames import body_frames
from .assembly import assemble_state
from .common import DENSE_LIMIT, increment, project_positions
from ..results.state import state_factory
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model.model import Model
    from typing import Sequence
    from .._types import PathLike, Progress


SINGULAR_TOL = 1e-4   # relative conditioning of the scaled constraint Jacobian flagged as singular


class SingularConfigurationWarning(UserWarning):
    """The driven mechanism passes a singular configuration (dead centre, toggle, bifurcation): the
    constraint Jacobian with drivers loses rank; the analysis keeps the branch by continuity."""


@blas_single_thread
def kinematics(model: Model, end_time: float, output_step: float | None = None, start_time: float = 0.0,
               progress: Progress = None, out: PathLike | None = None,
               markers: bool | Sequence[str] = False) -> Result:
    """Kinematic analysis from start_time to end_time [s], sampled every output_step [s].

    progress: True shows a progress bar on stderr (as `simulate`); a callable progress(t) receives the time
    reached [s] after each sample; Ctrl-C or an exception it raises returns the partial Result
    (success=False; res.error a ProgressError naming analysis.progress); False: nothing; None (default):
    the bar after 2 s in a terminal or notebook; anything else is a ModelError before any work. out: optional .parquet / .csv path that
    `res.to_dataframe(markers=markers)` is written to while the run goes and at the end (see
    mbdsim.results.stream; markers: True every marker's columns, or a list of names, as `simulate`).

    The conditioning of the constraint Jacobian (with drivers, rows normalised, columns scaled by the
    mechanism's geometry: the model's length [m] for translations, 1 for rotations [rad], never by the
    masses, see system.metrics.geometric_scale) is monitored: samples where it falls below
    SINGULAR_TOL are recorded in res.stats["singular"] (time [s], conditioning, joints involved) and
    each passage is warned (SingularConfigurationWarning); the branch is kept by continuity, every
    prediction coming from the last non-singular sample and the rates at a singular sample from that
    sample's extrapolation.  A model the compiled core carries that passes no singular configuration
    is solved by the compiled kinematic sweep (mbdsim.solvers.kinsweep, the same equations;
    res.stats["method"] "kinematic (compiled sweep)"), with progress told each sample's time once the sweep is done.
    Sensors (Model.add_sensor) are not watched: they end or mark simulations (mb.simulate)."""
    from .._progress import progress_of
    from ..results.stream import run_writing
    from .dynamic import _check_markers
    _check_markers(model, markers, "kinematics")
    with progress_of(progress, "kinematics", f"kinematics of {getattr(model, 'name', '')}", start_time,
                     end_time) as bar:
        return run_writing(lambda p: _kinematics(model, end_time, output_step, start_time, p), bar, out,
                           "kinematics", markers)


def _kinematics(model, end_time, output_step, start_time, progress) -> Result:
    from ..results.stream import ProgressError, notify
    from ..system.assemble import assemble_system
    from .dynamic import _check_budget, _number
    check_model(model, "kinematics")
    start_time = _number("start_time", start_time)
    _check_budget(model, start_time, end_time, output_step)
    sys = assemble_system(model)
    rep = assemble_state(sys, sys.q0, sys.v0, start_time)
    if rep.dof > 0:
        raise ModelError(f"model '{model.name}'", "motions", f"kinematic analysis needs every degree of freedom "
                         f"driven; {rep.dof} DOF remain free (add motions or use mb.simulate)")
    times = time_grid(start_time, end_time, output_step)
    fast = _compiled_sweep(sys, rep, times)
    if fast is not None:
        try:
            for t in fast.time:
                notify(progress, t)
        except ProgressError as exc:   # every output is solved already: kept, the run marked failed
            fast.success, fast.status, fast.error = False, -1, exc
            fast.message = f"{exc}; last good state at t = {fast.time[-1]:.9g} s"
        return fast
    sf = state_factory(sys)
    mon = Monitor(sys, rep.rows)
    out, flags, records = [], [], []
    anchor = None            # last non-singular sample
    message, success, error = "ok", True, None
    for t in times:
        try:
            guess = rep.q if anchor is None else _predict(sys, anchor, t)
            state = solve_at(sys, guess, t, sf)
            cond, joints = mon(state[1], t)
            if cond < SINGULAR_TOL:
                state = solve_at(sys, state[1], t, sf, hint=None if anchor is None else _rates_hint(anchor, t))
                records.append({"time": float(t), "conditioning": cond, "joints": joints, "sample": len(out)})
        except (Exception, KeyboardInterrupt) as exc:   # noqa: BLE001 - every failure ends the run, named
            from .common import analysis_error
            exc = analysis_error(exc, t)
            success, error = False, exc
            message = f"{exc}; last good state at t = {out[-1][0] if out else start_time:.9g} s"
            break
        out.append(state)
        flags.append(cond < SINGULAR_TOL)
        if cond >= SINGULAR_TOL:
            anchor = state
        _continue_angles(sys, state)
        try:
            notify(progress, t, lambda n=len(out): _result(sys, out[:n], None, True, "partial (run in progress)"))
        except ProgressError as exc:   # the user's callback raised: the run ends, outputs kept
            success, error, message = False, exc, f"{exc}; last good state at t = {t:.9g} s"
            break
    _warn_singular(records)
    singular = np.array(flags, dtype=bool)
    ev = lambda ts: _evaluate(sys, out, singular, ts, sf)  # noqa: E731
    res = _result(sys, out, ev, success, message)
    res.stats["singular"] = records
    res.error = error
    return res


def _compiled_sweep(sys, rep, times):
    """The Result of the compiled kinematic sweep (solvers.kinsweep: the same equations, every sample in
    compiled code; joint angles of torsion springs and rotational stops continued in the kernel, each
    sub-step turning a body by at most fastkin.MAX_TURN) when the model is carried by the compiled core and
    solves completely; else None, and the analysis below (which reports failures) runs instead. Singular
    configurations (a dead centre, a change point) are passed by continuity: where the constraints do not
    determine the rates the kernel keeps those of its prediction, as the per-sample analysis extrapolates
    them from the last regular sample; the samples whose conditioning (`Monitor`, from one batched SVD of
    every sample) is below SINGULAR_TOL are recorded in res.stats["singular"] and each passage warned."""
    from ..errors import AnalysisInterrupted
    from ..system.compiled import NotCompiled
    from .kinsweep import integrate_kinematic
    try:
        res = integrate_kinematic(sys, rep, times, sensors=False, continuity=True)   # (sensors: not watched)
    except NotCompiled:
        return None
    if res is not None and isinstance(res.error, AnalysisInterrupted):
        return res   # Ctrl-C: what was solved, not the analysis again on the path below
    if res is None or not res.success or len(res.time) != len(times):
        return None
    records = _singular_samples(sys, rep, res)
    _warn_singular(records)
    res.stats = {"method": "kinematic (compiled sweep)", "singular": records,
                 **{k: res.stats[k] for k in ("steps", "substeps", "factorizations", "projections", "assembly",
                                              "change_points")}}
    return res


def _singular_samples(sys, rep, res) -> list:
    """The records (time [s], conditioning, joints, sample) of the samples of `res` whose conditioning is
    below SINGULAR_TOL: one batched SVD of the scaled, row-normalised Jacobians of all rows (rank: that of
    the independent rows; the kernel re-selects its own), `Monitor` at the flagged samples for the joints."""
    if not len(rep.rows) or sys.nv > DENSE_LIMIT:
        return []
    from ..system.equations import jacobians
    from ..system.metrics import geometric_scale
    scale = geometric_scale(sys)
    block = max(1, 2**22 // max(1, sys.nc * sys.nv))   # samples per batch: Jacobians of <= 32 MB at a time
    r = len(rep.rows)
    flagged = []
    for k in range(0, len(res.time), block):
        J = jacobians(sys, res.q[k:k + block]) * scale
        J = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
        sv = np.linalg.svd(J, compute_uv=False)
        flagged += [k + i for i in np.flatnonzero(sv[:, r - 1] < SINGULAR_TOL * np.maximum(sv[:, 0], 1e-300))]
    if not flagged:
        return []
    mon = Monitor(sys, rep.rows)
    out = []
    for i in flagged:
        cond, joints = mon(res.q[i], float(res.time[i]))
        if cond < SINGULAR_TOL:
            out.append({"time": float(res.time[i]), "conditioning": cond, "joints": joints, "sample": int(i)})
    return out


class Monitor:
    """Conditioning of the constraint Jacobian (its columns scaled by the geometry, system.metrics.
    geometric_scale: not by the masses; its rows normalised): the r-th over the largest singular value of
    all its rows in force, r the number of independent rows `rows` (which rows are dependent may change
    along the motion, as for a loop carried on a turning body; only a loss of rank is a singular
    configuration), and the joints/motions of the weakest direction."""

    def __init__(self, sys, rows):
        from ..system.metrics import geometric_scale
        self.sys, self.rank = sys, len(rows)
        self.rows = np.union1d(rows, np.setdiff1d(np.arange(sys.nc), sys.lock_rows)).astype(int)
        self.scale = geometric_scale(sys)

    def __call__(self, q, t):
        sys = self.sys
        if sys.nv > DENSE_LIMIT or not self.rank:
            return 1.0, []
        J = constraint_terms(sys, q, np.zeros(sys.nv), t)[1][self.rows] * self.scale
        J = J / np.maximum(np.linalg.norm(J, axis=1, keepdims=True), 1e-300)
        u, sv, _ = np.linalg.svd(J, full_matrices=False)
        k = self.rank - 1
        weak = np.abs(u[:, k])
        names = list(dict.fromkeys(sys.row_owner[self.rows[i]] for i in np.argsort(-weak)
                                   if weak[i] > 0.2 * weak.max()))
        return float(sv[k] / max(sv.max(), 1e-300)), names


def _warn_singular(records):
    """One warning per passage (consecutive flagged samples), at its worst-conditioned sample."""
    passages = []
    for r in records:
        if passages and r["sample"] == passages[-1][-1]["sample"] + 1:
            passages[-1].append(r)
        else:
            passages.append([r])
    for g in passages:
        worst = min(g, key=lambda r: r["conditioning"])
        warn(f"singular configuration (dead centre, toggle or bifurcation) at t = {worst['time']:.9g} s: "
             f"the constraint Jacobian with drivers is nearly rank deficient (conditioning "
             f"{worst['conditioning']:.3g}); joints involved: {', '.join(worst['joints'])}. The analysis "
             "keeps the branch by continuity; see res.stats['singular']", SingularConfigurationWarning)


def check_model(model, analysis: str | None = None):
    """ModelError unless `model` is an mbdsim Model; with `analysis` (a time-history analysis), also
    unless it has a body or particle besides ground (an empty model has nothing to integrate)."""
    from ..model.model import Model
    if not isinstance(model, Model):
        raise ModelError("analysis", "model", f"expected an mbdsim.Model, got {type(model).__name__}")
    if analysis is not None and len(model.bodies) < 2:
        raise ModelError(f"model '{model.name}'", "bodies", f"{analysis} needs at least one body or particle "
                         "besides ground; the model has none (add_body / add_particle)")


def time_grid(t0, t1, step):
    """Output times from t0 to t1 inclusive with spacing step (default (t1-t0)/500) [s]."""
    from ..model._check import not_a_number
    try:
        if not_a_number(t1):
            raise TypeError
        t1 = float(t1)
    except (TypeError, ValueError):
        raise ModelError("analysis", "end_time", f"expected a number, got {t1!r}") from None
    if not np.isfinite(t1) or t1 <= t0:
        raise ModelError("analysis", "end_time", f"must be greater than the start time {t0}, got {t1!r}")
    try:
        if not_a_number(step):
            raise TypeError
        step = (t1 - t0) / 500 if step is None else float(step)
    except (TypeError, ValueError):
        raise ModelError("analysis", "output_step", f"expected a number, got {step!r}") from None
    if not (step > 0 and np.isfinite(step)):   # also NaN
        raise ModelError("analysis", "output_step", f"must be positive and finite, got {step!r}")
    n = max(1, int(np.ceil((t1 - t0) / step - 1e-9)))
    return np.linspace(t0, t1, n + 1) if abs(n * step - (t1 - t0)) < 1e-9 * step else \
        np.append(t0 + step * np.arange(n), t1)


def solve_at(sys, q_guess, t, sf=None, hint=None):
    """(t, q, v, vd, lambda_) of the driven mechanism at time t [s].

    `hint` = (v, vd) expected by continuity: at a (nearly) singular configuration the rates are the
    hint corrected by the least change (in the geometric metric of the singularity test) that satisfies
    the velocity and acceleration equations."""
    q, res, _ = project_positions(sys, q_guess, t, sys.fixed_rows, tol=1e-13, maxit=30)
    if res > 1e-9:
        phi = constraint_terms(sys, q, np.zeros(sys.nv), t, jacobian=False)[0]
        worst = list(dict.fromkeys(sys.row_owner[k] for k in np.argsort(-np.abs(phi))[:4] if abs(phi[k]) > 1e-9))
        raise AssemblyError(f"position analysis failed (lock-up or impossible motion), residual {res:.3g}",
                            time=t, joints=worst, state=q)
    if hint is None:
        v0, vd0, S, rc = np.zeros(sys.nv), np.zeros(sys.nv), np.ones(sys.nv), None
    else:   # least change in the singularity test's geometric metric, the singular direction to the hint
        from ..system.metrics import geometric_scale
        (v0, vd0), S, rc = hint, geometric_scale(sys), SINGULAR_TOL
    _, J, nu, _ = constraint_terms(sys, q, np.zeros(sys.nv), t)
    v = v0 + S * np.linalg.lstsq(J * S, nu - J @ v0, rcond=rc)[0]
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    vd = vd0 + S * np.linalg.lstsq(J * S, gamma - J @ vd0, rcond=rc)[0]
    Q = applied_forces(sys, body_frames(sys, q, v), t, sf(t, q, v) if sf else None)
    lam = np.linalg.lstsq(J.T, Q - sys.M @ vd, rcond=None)[0]
    return t, q, v, vd, lam


def _continue_angles(sys, state):
    """Re-anchor the joint angles of torsion springs and rotational stops after each solved time (what
    the event tracker does in mb.simulate), so that they continue beyond +-pi instead of wrapping."""
    from ..model.element_specs import Stop, TorsionSpring
    from ..system.force_elements._common import angle_reanchor
    t, q, v = state[:3]
    for e in sys.model.forces.values():
        if isinstance(e, TorsionSpring) or (isinstance(e, Stop) and e.dof == "rotation"):
            angle_reanchor(sys, body_frames(sys, q, v), e.joint, e.name, t)


def _predict(sys, prev, t):
    t0, q, v, vd, _ = prev
    h = t - t0
    return increment(sys, q, h * v + 0.5 * h * h * vd)


def _rates_hint(prev, t):
    """(v, vd) at t extrapolated from the sample `prev` (v + h vd, vd)."""
    t0, _, v, vd, _ = prev
    return v + (t - t0) * vd, vd


def _evaluate(sys, out, singular, ts, sf):
    """States at times ts: predicted from the nearer non-singular of the two samples that bracket each
    t (so the branch of the bracketing samples is kept), then solved; rates by continuity from that
    sample where the configuration is singular."""
    times = np.array([s[0] for s in out])
    good = np.where(~singular)[0] if (~singular).any() else np.arange(len(out))
    states = []
    for t in ts:
        k = int(np.clip(np.searchsorted(times, t), 1, max(len(times) - 1, 1)))
        pair = [i for i in (k - 1, k) if 0 <= i < len(out)]
        cand = [i for i in pair if not singular[i]] or [int(good[np.argmin(np.abs(times[good] - t))])]
        a = min(cand, key=lambda i: abs(times[i] - t))
        st = solve_at(sys, _predict(sys, out[a], t), t, sf)
        if any(singular[i] for i in pair):
            st = solve_at(sys, st[1], t, sf, hint=_rates_hint(out[a], t))
        states.append(st)
    return tuple(np.array([s[i] for s in states]) for i in range(1, 5))


def _result(sys, out, ev, success, message):
    if not out:
        return Result(sys, np.zeros(0), np.zeros((0, sys.nq)), np.zeros((0, sys.nv)), None, None, None,
                      success, -1, message)
    arr = [np.array([s[i] for s in out]) for i in range(5)]
    return Result(sys, *arr, evaluate=ev, success=success, status=0 if success else -1, message=message)
