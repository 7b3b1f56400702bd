"""Static equilibrium: Q(q) - phi_q^T lambda_ = 0 with phi(q) = 0 and zero velocities.

Newton iteration on (dx, lambda_) with the stiffness d(Q)/dx by central differences on the
configuration manifold (dx: CM translations [m] and body-axes rotations [rad]); a backtracking line
search on the residual norm keeps it robust from far-off starts.
"""
from __future__ import annotations

import numpy as np

from ..errors import SolverError
from ..results.result import Result
from ..system.assemble import assemble_system
from ..system.dynamics import applied_forces
from ..system.equations import constraint_terms
from ..system.frames import body_frames
from .assembly import assemble_state
from .common import increment
from .state import state_factory


def equilibrium(model, t=0.0, tol=1e-10, maxit=100) -> Result:
    """Static equilibrium at time t [s]: a single-time Result (velocities and accelerations zero)."""
    from .kinematic import check_model
    check_model(model)
    sys = assemble_system(model)
    rep = assemble_state(sys, sys.q0, np.zeros(sys.nv), t)
    rows, sf = rep.rows, state_factory(sys)
    zero = np.zeros(sys.nv)

    def residual(q, lam):
        Q = applied_forces(sys, body_frames(sys, q, zero), t, sf(t, q, zero) if sf else None)
        phi, J, _, _ = constraint_terms(sys, q, zero, t)
        return np.concatenate([Q - J[rows].T @ lam, phi[rows]]), J[rows]

    q, lam = rep.q, np.zeros(len(rows))
    r, J = residual(q, lam)
    scale = max(1.0, float(np.max(np.abs(sys.M))) * 10)
    for it in range(maxit):
        if np.max(np.abs(r)) < tol * scale:
            break
        K = _stiffness(sys, q, lam, t, residual)
        n = sys.nv
        A = np.zeros((n + len(rows), n + len(rows)))
        A[:n, :n] = K
        A[:n, n:] = -J.T
        A[n:, :n] = J
        step = np.linalg.lstsq(A, -r, rcond=None)[0]
        alpha, r_norm = 1.0, np.linalg.norm(r)
        while alpha > 1e-4:
            _follow_angles(sys, q, alpha * step[:n], t)
            q_try, lam_try = increment(sys, q, alpha * step[:n]), lam + alpha * step[n:]
            r_try, J_try = residual(q_try, lam_try)
            if np.linalg.norm(r_try) < r_norm * (1 - 1e-4 * alpha) or alpha <= 1.5e-4:
                break
            alpha *= 0.5
        q, lam, r, J = q_try, lam_try, r_try, J_try
    else:
        raise SolverError(f"static equilibrium not found in {maxit} iterations (residual {np.max(np.abs(r)):.3g})",
                          time=t, state=q)
    lam_full = np.zeros(sys.nc)
    lam_full[rows] = lam
    return Result(sys, [t], q[None], zero[None], zero[None], lam_full[None], None, True, 0,
                  f"equilibrium in {it} iterations")


def _follow_angles(sys, q, dx, t):
    """Anchor the continued joint angles of torsion springs and rotational stops at their linear prediction
    for the Newton update q (+) dx, so that equilibria beyond +-pi (a wound-up spring) are found."""
    from ..model.element_specs import Stop, TorsionSpring
    from ..system.force_elements._common import element_state, joint_coordinate, load_from_rows
    fr = None
    for e in sys.model.forces.values():
        if isinstance(e, TorsionSpring) or (isinstance(e, Stop) and e.dof == "rotation"):
            fr = body_frames(sys, q, np.zeros(sys.nv)) if fr is None else fr
            x, _, rows = joint_coordinate(sys, fr, e.joint, "rotation", e.name, t)
            pred = float(x[0] + load_from_rows(sys, fr, rows, 1.0) @ dx)
            element_state(sys, e.name)["angle_ref"] = [(float(t), pred)]


def _stiffness(sys, q, lam, t, residual, h=1e-7):
    """d(Q - J^T lambda)/dx by central differences, shape (nv, nv)."""
    n = sys.nv
    K = np.zeros((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        rp = residual(increment(sys, q, e), lam)[0][:n]
        rm = residual(increment(sys, q, -e), lam)[0][:n]
        K[:, k] = (rp - rm) / (2 * h)
    return K
