"""Joint reaction loads from the Lagrange multipliers.

The constraint load on body b is Q_c = -phi_q[:, b]^T lambda_ (translation part = force in ground axes,
rotation part = torque about the CM in body axes); it is reduced to the joint point P on that body:
T_P = T_CM + (r_CM - r_P) x F.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .equations import constraint_terms
from .frames import body_frames


def joint_reaction(sys, q, lambda_, joint, on=None):
    """Force [N] and torque [N m] (N, 3), ground axes, that `joint` (a Joint or motion name) exerts on `on`."""
    name = joint if isinstance(joint, str) else joint.name
    rows = sys.owner_rows.get(name)
    if rows is None:
        raise ModelError(f"joint '{name}'", "joint", "has no constraint rows in the analysed model")
    # a motion acting on the joint is part of the joint's load (as in Adams)
    for m in sys.model.motions.values():
        if m.joint.name == name and m.name in sys.owner_rows:
            rows = np.concatenate([rows, sys.owner_rows[m.name]])
    geom = sys.geoms.get(name) or sys.geoms[sys.model.motions[name].joint.name]
    body = on if on is not None else (joint.body_j if not isinstance(joint, str) else None)
    fid = geom.bj if body is None else sys.fid.get(body, -1)
    if fid not in (geom.bi, geom.bj):
        raise ModelError(f"joint '{name}'", "on", f"{body!r} is not one of the joint's bodies")
    s_B = geom.s_j if fid == geom.bj else geom.s_i
    N = len(q)
    F, T = np.zeros((N, 3)), np.zeros((N, 3))
    if fid == 0:  # ground: the opposite of the load on the other body, reduced to the same point
        other = geom.bi if geom.bj == 0 else geom.bj
        return _negated(sys, q, lambda_, rows, other, geom, N)
    a = sys.frame_v_adr[fid]
    for n in range(N):
        J = constraint_terms(sys, q[n], np.zeros(sys.nv), 0.0)[1][rows]
        lam = lambda_[n, rows]
        F[n] = -J[:, a:a + 3].T @ lam
        fr = body_frames(sys, q[n])
        if sys.frame_rigid[fid]:
            T_cm = fr.A[fid] @ (-J[:, a + 3:a + 6].T @ lam)
            T[n] = T_cm + np.cross(-(fr.A[fid] @ s_B), F[n])
    return F, T


def _negated(sys, q, lambda_, rows, other, geom, N):
    s_B = geom.s_j if other == geom.bj else geom.s_i
    a = sys.frame_v_adr[other]
    F, T = np.zeros((N, 3)), np.zeros((N, 3))
    for n in range(N):
        J = constraint_terms(sys, q[n], np.zeros(sys.nv), 0.0)[1][rows]
        lam = lambda_[n, rows]
        F[n] = J[:, a:a + 3].T @ lam
        if sys.frame_rigid[other]:
            fr = body_frames(sys, q[n])
            T_cm = fr.A[other] @ (J[:, a + 3:a + 6].T @ lam)
            T[n] = T_cm + np.cross(-(fr.A[other] @ s_B), F[n])
    return F, T
