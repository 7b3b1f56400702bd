"""Joint reaction loads from the Lagrange multipliers.

The constraint load on body b is Q_c = -phi_q[:, b]^T lambda_ (translation part = force in ground axes,
rotation part = torque about the CM in body axes); it is reduced to the joint point P on that body:
T_P = T_CM + (r_CM - r_P) x F.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .equations import jacobians
from .frames import body_frames


def joint_reaction(sys, q, lambda_, joint, on=None, A=None, J=None):
    """Force [N] and torque [N m] (N, 3), ground axes, that `joint` (a Joint or motion name) exerts on `on`.

    Optional precomputed geometry of the samples q (N, nq): A (N, nbody + 1, 3, 3) body rotation
    matrices (Frames.A), J (N, nc, nv) constraint Jacobians; computed here when not given."""
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
    if fid == 0:  # ground: the opposite of the load on the other body, reduced to the same point
        other = geom.bi if geom.bj == 0 else geom.bj
        F, T = _load_on(sys, q, lambda_, rows, other, geom, A, J)
        return -F, -T
    return _load_on(sys, q, lambda_, rows, fid, geom, A, J)


def _load_on(sys, q, lambda_, rows, fid, geom, A=None, J=None):
    """Constraint force [N] and torque about the joint point [N m] (N, 3), ground axes, of `rows` on frame
    fid, for all samples at once."""
    s_B = geom.s_j if fid == geom.bj else geom.s_i
    a = sys.frame_v_adr[fid]
    q = np.atleast_2d(q)
    J = (jacobians(sys, q) if J is None else J)[:, rows]   # (N, nr, nv)
    lam = np.asarray(lambda_)[:, rows]
    F = -np.einsum("nri,nr->ni", J[:, :, a:a + 3], lam)
    T = np.zeros_like(F)
    if sys.frame_rigid[fid]:
        A = (body_frames(sys, q).A if A is None else A)[:, fid]
        T_cm = np.einsum("nij,nj->ni", A, -np.einsum("nri,nr->ni", J[:, :, a + 3:a + 6], lam))
        T = T_cm + np.cross(-(A @ s_B), F)
    return F, T
