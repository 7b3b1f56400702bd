"""Generalized applied forces Q (nv,) and the augmented (KKT) solve of the equations of motion.

Equations (velocity variables v = [rd, w_B] per body): M vd + phi_q^T lambda_ = Q, phi_q vd = gamma,
with Q = gravity + applied loads + force elements - w_B x (J w_B) (gyroscopic, body axes).
"""
from __future__ import annotations

import numpy as np

from ..errors import SolverError
from . import kernels
from .equations import constraint_terms
from .force_elements import evaluator
from .force_elements import loads  # noqa: F401  (registers the built-in evaluators)
from .frames import Frames, body_frames
from .rows import active_rows


def applied_forces(sys, fr: Frames, t, state=None) -> np.ndarray:
    """Q (nv,): gravity, gyroscopic terms and every force element at one state (frames without time axis)."""
    Q = inertial_forces(sys, fr)
    for elem in sys.model.forces.values():
        Q += evaluator(elem).generalized(sys, fr, elem, t, state)
    return Q


def inertial_forces(sys, fr: Frames) -> np.ndarray:
    """Q (nv,) of gravity on every CM [N] and the gyroscopic torques -w_B x (J w_B) [N m, body axes]."""
    return kernels.inertial_forces_kernel(fr.A, fr.w, sys.mass, sys.inertia_B, sys.rd_idx, sys.w_idx,
                                          sys.rigid_fid, sys.model.gravity, sys.nv)


def solve_kkt(M, J, Q, gamma):
    """Solve [[M, J^T], [J, 0]] [vd, lambda_] = [Q, gamma]; returns (vd, lambda_)."""
    nv, nc = M.shape[0], J.shape[0]
    K = np.zeros((nv + nc, nv + nc))
    K[:nv, :nv] = M
    K[:nv, nv:] = J.T
    K[nv:, :nv] = J
    rhs = np.concatenate([Q, gamma])
    x = np.linalg.solve(K, rhs)  # raises LinAlgError when exactly singular
    if not np.all(np.isfinite(x)) or np.max(np.abs(x), initial=0.0) > 1e13 * (1.0 + np.max(np.abs(rhs), initial=0.0)):
        raise np.linalg.LinAlgError("augmented matrix is numerically singular")
    return x[:nv], x[nv:]


def accelerations(sys, q, v, t, rows, state_factory=None):
    """vd and lambda_ (full nc, minimum-norm where redundant) from the equations of motion at (q, v, t)."""
    rows = active_rows(sys, rows, t)
    fr = body_frames(sys, q, v)
    state = state_factory(t, q, v) if state_factory else None
    Q = applied_forces(sys, fr, t, state)
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    try:
        if len(sys.lock_rows):   # joint friction: slip loads depend on lambda_ (coupled KKT solve)
            from .force_elements.friction_kkt import friction_kkt
            return friction_kkt(sys, fr, J, gamma, Q, rows, t)
        vd, lam_i = solve_kkt(sys.M, J[rows], Q, gamma[rows])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"singular equations of motion (lock-up or singular configuration{massless_note(sys)}): "
                          f"{exc}", time=t, joints=_worst_joints(sys, J, rows)) from None
    lam = np.zeros(sys.nc)
    if len(rows) == sys.nc:
        lam = lam_i
    else:
        lam = np.linalg.lstsq(J.T, Q - sys.M @ vd, rcond=None)[0]
    return vd, lam


def _worst_joints(sys, J, rows):
    """Joints whose rows are (nearly) dependent at this configuration."""
    Jr = J[rows]
    if Jr.shape[0] == 0:
        return []
    u, s, vt = np.linalg.svd(Jr.T, full_matrices=False)
    weak = vt[-1]
    names = []
    for k in np.argsort(-np.abs(weak)):
        if abs(weak[k]) > 1e-3 and sys.row_owner[rows[k]] not in names:
            names.append(sys.row_owner[rows[k]])
    return names


def massless_note(sys) -> str:
    """"; zero mass: body 'a', body 'b'" naming the bodies of mass 0 kg (a singular mass matrix unless the
    joints and drivers fix their motion: the usual cause of singular equations of motion), else ""."""
    names = [f"'{b.name}'" for b in sys.bodies if not b.is_ground and b.mass == 0.0]
    return f"; zero mass: {'body' if len(names) == 1 else 'bodies'} {', '.join(names)}" if names else ""
