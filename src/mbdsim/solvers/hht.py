"""HHT-alpha on the index-3 DAE, on the configuration Lie group, with error-controlled steps.

Unknowns of a step: accelerations a = vd_{n+1} (nv) and multipliers lambda_ (independent rows).
    dq      = h v_n + h^2 (1/2 - beta) a_n + h^2 beta a            (increment, CM translation & body rotation)
    q_{n+1} = q_n (+) dq,   v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a
    M a + (1 + alpha) (phi_q^T lambda_ - Q)_{n+1} - alpha (phi_q^T lambda_ - Q)_n = 0
    phi(q_{n+1}, t_{n+1}) / (beta h^2) = 0                           (scaled position-level constraints)
with beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha, alpha in [-1/3, 0] (default -0.05: mild numerical
damping of high frequencies, second order).  Newton iteration matrix
    [[M + gamma h C + beta h^2 K, (1 + alpha) phi_q^T], [phi_q, 0]]
with K = -dQ/dq, C = -dQ/dv by finite differences, refreshed when convergence slows.
Local error estimate (Zienkiewicz-Xie): e = h^2 (beta - 1/6) (a_{n+1} - a_n), weighted by atol + rtol |dq|.
Velocities are projected onto phi_q v = nu after each step; output between steps uses cubic Hermite
interpolation of (q, v) in the tangent space followed by projection and an index-1 acceleration solve.
"""
from __future__ import annotations

import numpy as np

from .._blas import scipy_linalg
from ..errors import SolverError
from ..results.result import Result
from ..system.dynamics import applied_forces
from ..system.equations import constraint_terms
from ..system.frames import body_frames
from .common import accelerations, increment, normalize, project_positions, project_velocities
from .common import consistent_state
from .driver import Step, drive
from .events import EventTracker
from ..results.state import state_factory

ALPHA = -0.05


class _Step:
    """State at a step boundary: t, q, v, a (accelerations), lam (independent rows), residual force."""

    def __init__(self, t, q, v, a, lam, f):
        self.t, self.q, self.v, self.a, self.lam, self.f = t, q, v, a, lam, f


class HHTStepper:
    """HHT-alpha steps for `solvers.driver.drive`, error-controlled, over [t0, t_end] [s] from the
    assembled state `rep`; outputs are (q, v, vd, lambda_) tuples, or (q, v) when `outputs` completes
    them on demand (see integrate_hht)."""

    out_tol = 1e-12

    def __init__(self, sys, rep, t0, t_end, rtol, atol, max_step, alpha, sf, outputs=None, project=None):
        self.sys, self.rep, self.rows, self.sf = sys, rep, rep.rows, sf
        self.rtol, self.atol, self.max_step, self.alpha = rtol, atol, max_step, alpha
        self.beta, self.gamma = (1 - alpha) ** 2 / 4, 0.5 - alpha
        self.t_end, self.outputs = float(t_end), outputs
        a0, lam_full = accelerations(sys, rep.q, rep.v, t0, self.rows, sf)
        lam0 = lam_full[self.rows]
        self.cur = _Step(t0, rep.q, rep.v, a0, lam0, _force_term(sys, rep.q, rep.v, t0, lam0, self.rows, sf))
        self.h = min(max_step or np.inf, (self.t_end - t0) / 100, _initial_step(sys, self.cur, rtol, atol))
        self.steps = [self.cur]
        self.sample = _dense if outputs is None else lambda *a: _dense_qv(*a, project=project)
        self.nrej = 0
        self.tan = _Tangent()

    @property
    def t(self) -> float:
        return self.cur.t

    @property
    def y(self) -> np.ndarray:
        return np.concatenate([self.cur.q, self.cur.v])

    def first(self):
        return self.here()

    def here(self):
        cur = self.cur
        return self.sample(self.sys, cur, cur, cur.t, self.rows, self.sf)

    def step(self, t_stop=None):
        """The next accepted step (Newton failures refresh the tangent, then cut the step; the error
        estimate rejects and shrinks it); with t_stop, the step is at most as long as to reach t_stop."""
        sys, cur, tan = self.sys, self.cur, self.tan
        if t_stop is not None:
            self.h = t_stop - cur.t
        while True:
            h = self.h = min(self.h, self.t_end - cur.t, self.max_step or np.inf)
            new, ok = _try_step(sys, cur, h, self.alpha, self.beta, self.gamma, self.rows, self.sf, tan)
            if not ok:
                self.nrej += 1
                if not tan.fresh:       # first refresh the tangent, then cut the step
                    tan.K = None
                    continue
                tan.K = None
                self.h *= 0.25
                if self.h < 1e-14 * max(1.0, abs(cur.t)):
                    raise SolverError("HHT step size underflow (Newton does not converge)", time=cur.t,
                                      joints=_names(sys, self.rows), state=cur.q)
                continue
            err = _error(cur, new, h, self.beta, self.rtol, self.atol)
            if err > 1.0:
                self.nrej += 1
                self.h *= max(0.2, 0.9 * err ** (-1 / 3))
                if self.h < 1e-14 * max(1.0, abs(cur.t)):   # the tolerance cannot be met: a floor, not a hang
                    raise SolverError(f"HHT step size underflow: the error estimate stays above the tolerance "
                                      f"(rtol {self.rtol:g}, atol {self.atol:g}) at steps below {self.h:.3g} s",
                                      time=cur.t, joints=_names(sys, self.rows), state=cur.q)
                continue
            return Step(cur.t, new.t, np.concatenate([new.q, new.v]),
                        lambda t, a=cur, b=new: _hermite_y(sys, a, b, t),
                        lambda t, a=cur, b=new: self.sample(sys, a, b, t, self.rows, self.sf), (new, err))

    def to_event(self, step, t_hit, locate=None):
        """The step redone to end at the event. HHT's cubic interpolant of a step whose end already feels
        the switched force places the root only to about 1e-9 s, so the redone step, which ends at the
        estimate, is searched again on its own interpolant (`locate`) and redone to any root still inside
        it (at most 4 times); reached: the step ends at the event."""
        for _ in range(4):
            tol = 1e-13 * max(1.0, abs(step.t_new))
            if t_hit is None or t_hit >= step.t_new - tol:
                return step, True
            step = self.step(t_stop=t_hit)
            if abs(step.t_new - t_hit) > tol:   # Newton or the error test shortened it: not there yet
                return step, False
            t_hit = None if locate is None else locate(step)
        return step, True

    def take(self, step):
        new, err = step.data
        self.steps.append(new)
        self.cur = new
        self.h *= min(2.0, max(0.5, 0.9 * max(err, 1e-10) ** (-1 / 3)))

    def restart(self):
        """Nothing to restart: each HHT step starts from its own state."""

    def has_steps(self) -> bool:
        return True

    def evaluate(self, ts):
        steps, sys = self.steps, self.sys
        tk = np.array([s.t for s in steps])
        states = []
        for t in ts:
            k = int(np.clip(np.searchsorted(tk, t) - 1, 0, len(steps) - 2)) if len(steps) > 1 else 0
            states.append(self.sample(sys, steps[k], steps[min(k + 1, len(steps) - 1)], t, self.rows, self.sf))
        cols = tuple(np.array([s[i] for s in states]) for i in range(len(states[0])))
        if self.outputs is None:
            return cols
        return cols + self.outputs(np.asarray(ts, float), np.hstack(cols))

    def interpolated(self, ts):
        """Rows [q, v] at times ts [s] from the cubic Hermite interpolant of the accepted steps, neither
        projected nor completed (cheap: for quantities integrated over the run, e.g. dissipated energy)."""
        steps, sys = self.steps, self.sys
        tk = np.array([s.t for s in steps])
        k = np.clip(np.searchsorted(tk, ts) - 1, 0, max(len(steps) - 2, 0))
        return np.array([_hermite_y(sys, steps[i], steps[min(i + 1, len(steps) - 1)], t) for t, i in zip(ts, k)])

    def step_states(self):
        steps = self.steps
        return np.array([s.t for s in steps]), np.array([s.q for s in steps]), np.array([s.v for s in steps])

    def stats(self) -> dict:
        tan = self.tan
        return {"steps": len(self.steps) - 1, "rejected": self.nrej, "nfev": tan.nfev, "njev": tan.njev,
                "factorizations": tan.nlu, "order": 2, "method": "HHT", "alpha": self.alpha, "assembly": self.rep}

    def result(self, times, out, **kw) -> Result:
        return _outputs(self.sys, times, out, self.outputs, **kw)


def integrate_hht(sys, rep, times, rtol, atol, max_step, alpha=ALPHA, progress=None, outputs=None, project=None):
    """HHT-alpha integration over the output grid `times` [s]; returns a Result. progress: see
    mbdsim.results.stream.notify; Ctrl-C ends the run with success=False and every output before it.
    outputs: optional callable (times [s], Y = [q, v] rows) -> (VD, LAM) giving the accelerations and
    multipliers (all rows) at output states; with it they are computed on first use (as a compiled run
    does; the automatic method passes the compiled kernel's), else at every output. project: optional
    callable (t [s], y = [q, v]) -> (q, v) projecting an output state onto the constraints (default: the
    minimum-norm Newton projection of mbdsim.solvers.common). Events: a step that changes the sign of a
    switching function is redone to end at its root (mbdsim.solvers.driver)."""
    sf = state_factory(sys)
    t0 = float(times[0])
    events = EventTracker(sys, rep.rows, sf)
    events.start(t0, np.concatenate([rep.q, rep.v]))
    stepper = HHTStepper(sys, rep, t0, times[-1], rtol, atol, max_step, alpha, sf, outputs, project)
    return drive(stepper, sys, rep, times, events, progress)


def _outputs(sys, times, out, outputs, **kw) -> Result:
    """Result of the output states `out` ((q, v, vd, lam) each, or (q, v) with `outputs` computing vd and
    lambda_ on first use)."""
    cols = [np.array([s[i] for s in out]) for i in range(len(out[0]))]
    if outputs is None:
        return Result(sys, times, *cols, **kw)
    Y = np.hstack(cols)
    return Result(sys, times, *cols, None, None, accelerations=lambda: outputs(times, Y), **kw)


def _force_term(sys, q, v, t, lam, rows, sf):
    """phi_q^T lambda_ - Q at a state (nv,)."""
    Q = applied_forces(sys, body_frames(sys, q, v), t, sf(t, q, v) if sf else None)
    _, J, _, _ = constraint_terms(sys, q, v, t)
    return J[rows].T @ lam - Q


def _initial_step(sys, s, rtol, atol):
    scale = atol + rtol * np.maximum(np.abs(s.v), 1e-3)
    an = np.sqrt(np.mean((s.a / np.maximum(scale, 1e-300)) ** 2)) if sys.nv else 0.0
    return 0.1 * (1.0 / max(an, 1e-10)) ** 0.5 if an > 0 else 1e-2


class _Tangent:
    """Cached stiffness K = d(phi_q^T lambda_ - Q)/dx and damping C = -dQ/dv (finite differences);
    refreshed only when Newton stalls, as in a modified Newton method."""

    def __init__(self):
        self.K = self.C = None
        self.fresh = False
        self.njev = self.nlu = self.nfev = 0   # tangent evaluations, factorisations, force evaluations


def _try_step(sys, cur, h, alpha, beta, gamma, rows, sf, tan):
    """One HHT step of size h from `cur`; returns (new _Step or None, converged)."""
    sla = scipy_linalg()   # imported on first use: ~0.3 s at start-up
    t1 = cur.t + h
    a, lam = cur.a.copy(), cur.lam.copy()
    nv = sys.nv
    base_dq = h * cur.v + h * h * (0.5 - beta) * cur.a
    base_v = cur.v + h * (1 - gamma) * cur.a
    prev_norm, lu = np.inf, None
    for it in range(8):
        q1 = increment(sys, cur.q, base_dq + h * h * beta * a)
        v1 = base_v + h * gamma * a
        Q = applied_forces(sys, body_frames(sys, q1, v1), t1, sf(t1, q1, v1) if sf else None)
        tan.nfev += 1
        phi, J, _, _ = constraint_terms(sys, q1, v1, t1)
        J, phi = J[rows], phi[rows]
        r1 = sys.M @ a + (1 + alpha) * (J.T @ lam - Q) - alpha * cur.f
        r2 = phi / (beta * h * h)
        if tan.K is None:
            tan.K, tan.C = _tangent(sys, q1, v1, t1, lam, rows, sf)
            tan.fresh = True
            tan.njev += 1
            tan.nfev += 2 * nv + 1
        if lu is None:
            lu = _iteration_matrix(sys, tan, J, h, alpha, beta, gamma)
            tan.nlu += 1
        try:
            d = sla.lu_solve(lu, -np.concatenate([r1, r2]))
        except (ValueError, sla.LinAlgError):
            return None, False
        if not np.all(np.isfinite(d)):
            return None, False
        a += d[:nv]
        lam += d[nv:]
        norm = np.max(np.abs(d[:nv]), initial=0.0) * beta * h * h
        if norm < 1e-12 * (1 + np.max(np.abs(base_dq), initial=0.0)) and \
                (len(phi) == 0 or np.max(np.abs(phi)) < 1e-10):
            q1 = increment(sys, cur.q, base_dq + h * h * beta * a)
            v1 = base_v + h * gamma * a
            q1, _, _ = project_positions(sys, q1, t1, rows, tol=1e-12, maxit=3)
            tan.fresh = False
            return _Step(t1, q1, v1, a, lam, _force_term(sys, q1, v1, t1, lam, rows, sf)), True
        if it > 2 and norm > 0.5 * prev_norm:   # slow convergence: stop and let the caller react
            break
        prev_norm = norm
    return None, False


def _iteration_matrix(sys, tan, J, h, alpha, beta, gamma):
    sla = scipy_linalg()   # imported on first use: ~0.3 s at start-up
    nv, nr = sys.nv, J.shape[0]
    A = np.zeros((nv + nr, nv + nr))
    A[:nv, :nv] = sys.M + (1 + alpha) * (gamma * h * tan.C + beta * h * h * tan.K)
    A[:nv, nv:] = (1 + alpha) * J.T
    A[nv:, :nv] = J
    return sla.lu_factor(A, check_finite=False)


def _tangent(sys, q, v, t, lam, rows, sf, eps=1e-7):
    """K = d(phi_q^T lambda_ - Q)/dx and C = d(-Q)/dv by forward differences (nv x nv)."""
    f0 = _force_term(sys, q, v, t, lam, rows, sf)
    n = sys.nv
    K, C = np.zeros((n, n)), np.zeros((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = eps
        K[:, k] = (_force_term(sys, increment(sys, q, e), v, t, lam, rows, sf) - f0) / eps
        C[:, k] = (_force_term(sys, q, v + e, t, lam, rows, sf) - f0) / eps
    return K, C


def _error(cur, new, h, beta, rtol, atol):
    e = h * h * abs(beta - 1.0 / 6.0) * (new.a - cur.a)
    scale = atol + rtol * np.maximum(np.abs(h * cur.v), np.abs(h * new.v)) + rtol * 1e-3
    return float(np.sqrt(np.mean((e / scale) ** 2))) if len(e) else 0.0


def _hermite_y(sys, s0, s1, t):
    """[q, v] at t in [s0.t, s1.t]: cubic Hermite interpolation of (q, v) in the tangent space."""
    h = s1.t - s0.t
    if h <= 0 or t <= s0.t:
        return np.concatenate([s0.q, s0.v])
    tau = (t - s0.t) / h
    delta = _log_increment(sys, s0.q, s1.q, 0.5 * h * (s0.v + s1.v))
    h10, h01, h11 = tau**3 - 2 * tau**2 + tau, -2 * tau**3 + 3 * tau**2, tau**3 - tau**2
    dpos = h10 * h * s0.v + h01 * delta + h11 * h * s1.v
    vel = ((3 * tau**2 - 4 * tau + 1) * h * s0.v + (-6 * tau**2 + 6 * tau) * delta
           + (3 * tau**2 - 2 * tau) * h * s1.v) / h
    return np.concatenate([increment(sys, s0.q, dpos), vel])


def _dense(sys, s0, s1, t, rows, sf):
    """Consistent state at t in [s0.t, s1.t] from the Hermite interpolant, projected and completed."""
    return consistent_state(sys, _hermite_y(sys, s0, s1, t), t, rows, sf)


def _dense_qv(sys, s0, s1, t, rows, sf, project=None):
    """(q, v) of `_dense` (projected, by `project(t, y)` when given; accelerations and multipliers left
    to the caller)."""
    y = _hermite_y(sys, s0, s1, t)
    if project is not None:
        return project(t, y)
    q, _, _ = project_positions(sys, normalize(sys, y[:sys.nq]), t, rows)
    return q, project_velocities(sys, q, y[sys.nq:], t, rows)


def _log_increment(sys, q0, q1, pred=None):
    """Increment dx with q0 (+) dx = q1 (translation difference; body-axes rotation vector).

    A rotation vector is defined up to whole turns: with `pred` (nv,), a predicted increment (the
    trapezoidal one of a step), each body's is the equivalent (|r| + 2 pi k) r / |r| nearest to it, so a
    step turning a body by more than pi is interpolated the way it turned."""
    from ..math.rotation import quat_mul
    from scipy.spatial.transform import Rotation
    dx = np.zeros(sys.nv)
    dx[sys.rd_idx] = q1[sys.r_idx] - q0[sys.r_idx]
    dx[sys.aux_v_idx] = q1[sys.aux_q_idx] - q0[sys.aux_q_idx]   # auxiliary coordinates (path constraints)
    if len(sys.p_idx):
        p0, p1 = q0[sys.p_idx], q1[sys.p_idx]
        conj = p0 * np.array([1, -1, -1, -1])
        rel = quat_mul(conj, p1)
        dx[sys.w_idx] = Rotation.from_quat(np.concatenate([rel[:, 1:], rel[:, :1]], 1)).as_rotvec()
        if pred is not None:
            r, p = dx[sys.w_idx], pred[sys.w_idx]
            n = np.linalg.norm(r, axis=1)
            u = np.where(n[:, None] > 1e-12, r / np.maximum(n, 1e-300)[:, None], p / np.maximum(
                np.linalg.norm(p, axis=1), 1e-300)[:, None])
            k = np.round(((p * u).sum(1) - n) / (2 * np.pi))
            dx[sys.w_idx] = (n + 2 * np.pi * k)[:, None] * u
    return dx


def _names(sys, rows):
    return list(dict.fromkeys(sys.row_owner[r] for r in rows))[:6]
