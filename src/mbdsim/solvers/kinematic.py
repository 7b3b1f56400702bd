"""Kinematic analysis of fully driven mechanisms (zero degrees of freedom).

Positions by Newton on phi(q, t) = 0, velocities from phi_q v = nu, accelerations from phi_q vd = gamma,
reactions from the equations of motion phi_q^T lambda_ = Q - M vd (minimum norm where redundant).
"""
from __future__ import annotations

import numpy as np

from ..errors import AssemblyError, ModelError
from ..results.result import Result
from ..system.dynamics import applied_forces
from ..system.equations import constraint_terms
from ..system.frames import body_frames
from .assembly import assemble_state
from .common import increment, project_positions
from .state import state_factory


def kinematics(model, end_time, output_step=None, start_time=0.0) -> Result:
    """Kinematic analysis from start_time to end_time [s], sampled every output_step [s]."""
    from ..system.assemble import assemble_system
    check_model(model)
    sys = assemble_system(model)
    rep = assemble_state(sys, sys.q0, sys.v0, start_time)
    if rep.dof > 0:
        raise ModelError(f"model '{model.name}'", "motions", f"kinematic analysis needs every degree of freedom "
                         f"driven; {rep.dof} DOF remain free (add motions or use mb.simulate)")
    times = time_grid(start_time, end_time, output_step)
    sf = state_factory(sys)
    out, q = [], rep.q
    prev = None
    message, success, error = "ok", True, None
    for t in times:
        try:
            q = _predict(sys, prev, t) if prev is not None else q
            state = solve_at(sys, q, t, sf)
        except AssemblyError as exc:
            success, error = False, exc
            message = f"{exc}; last good state at t = {prev[0] if prev else start_time:.9g} s"
            break
        out.append(state)
        prev = state
        _continue_angles(sys, state)
    ev = lambda ts: _evaluate(sys, out, ts, sf)  # noqa: E731
    res = _result(sys, out, ev, success, message)
    res.error = error
    return res


def check_model(model):
    """ModelError unless `model` is an mbdsim Model."""
    from ..model.model import Model
    if not isinstance(model, Model):
        raise ModelError("analysis", "model", f"expected an mbdsim.Model, got {type(model).__name__}")


def time_grid(t0, t1, step):
    """Output times from t0 to t1 inclusive with spacing step (default (t1-t0)/500) [s]."""
    try:
        t1 = float(t1)
    except (TypeError, ValueError):
        raise ModelError("analysis", "end_time", f"expected a number, got {t1!r}") from None
    if not np.isfinite(t1) or t1 <= t0:
        raise ModelError("analysis", "end_time", f"must be greater than the start time {t0}, got {t1!r}")
    try:
        step = (t1 - t0) / 500 if step is None else float(step)
    except (TypeError, ValueError):
        raise ModelError("analysis", "output_step", f"expected a number, got {step!r}") from None
    if not (step > 0 and np.isfinite(step)):   # also NaN
        raise ModelError("analysis", "output_step", f"must be positive and finite, got {step!r}")
    n = max(1, int(np.ceil((t1 - t0) / step - 1e-9)))
    return np.linspace(t0, t1, n + 1) if abs(n * step - (t1 - t0)) < 1e-9 * step else \
        np.append(t0 + step * np.arange(n), t1)


def solve_at(sys, q_guess, t, sf=None):
    """(t, q, v, vd, lambda_) of the driven mechanism at time t [s]."""
    q, res, _ = project_positions(sys, q_guess, t, sys.fixed_rows, tol=1e-13, maxit=30)
    if res > 1e-9:
        phi = constraint_terms(sys, q, np.zeros(sys.nv), t, jacobian=False)[0]
        worst = list(dict.fromkeys(sys.row_owner[k] for k in np.argsort(-np.abs(phi))[:4] if abs(phi[k]) > 1e-9))
        raise AssemblyError(f"position analysis failed (lock-up or impossible motion), residual {res:.3g}",
                            time=t, joints=worst, state=q)
    _, J, nu, _ = constraint_terms(sys, q, np.zeros(sys.nv), t)
    v = np.linalg.lstsq(J, nu, rcond=None)[0]
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    vd = np.linalg.lstsq(J, gamma, rcond=None)[0]
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


def _evaluate(sys, out, ts, sf):
    times = np.array([s[0] for s in out])
    states = []
    for t in ts:
        k = int(np.argmin(np.abs(times - t)))
        states.append(solve_at(sys, _predict(sys, out[k], t), t, sf))
    return tuple(np.array([s[i] for s in states]) for i in range(1, 5))


def _result(sys, out, ev, success, message):
    if not out:
        return Result(sys, np.zeros(0), np.zeros((0, sys.nq)), np.zeros((0, sys.nv)), None, None, None,
                      success, -1, message)
    arr = [np.array([s[i] for s in out]) for i in range(5)]
    return Result(sys, *arr, evaluate=ev, success=success, status=0 if success else -1, message=message)
