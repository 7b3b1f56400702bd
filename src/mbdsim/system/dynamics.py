"""Generalized applied forces Q (nv,) and the augmented (KKT) solve of the equations of motion.

Equations (velocity variables v = [rd, w_B] per body): M vd + phi_q^T lambda_ = Q, phi_q vd = gamma,
with Q = gravity + applied loads + force elements - w_B x (J w_B) (gyroscopic, body axes).
"""
from __future__ import annotations

import numpy as np

from . import kernels
from .force_elements import evaluator
from .force_elements import loads  # noqa: F401  (registers the built-in evaluators)
from .frames import Frames


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
