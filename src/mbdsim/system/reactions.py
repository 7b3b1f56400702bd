"""Joint reaction loads from the Lagrange multipliers.

The constraint load on body b is Q_c = -phi_q[:, b]^T lambda_ (translation part = force in ground axes,
rotation part = torque about the CM in body axes); it is reduced to the joint point P on that body:
T_P = T_CM + (r_CM - r_P) x F.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .equations import _packed, jacobian_blocks, jacobians
from .frames import body_frames


JACOBIAN_KEEP = 2**23   # bytes: Jacobians of recent multipliers are kept up to this size in all
KEEP_LAST = 3           # ... for at most this many multiplier arrays (a run's samples, dense-output grids)


def keep_jacobians(sys, lambda_, J) -> None:
    """Keep the constraint Jacobians J (N, nc, nv) at the samples of the multipliers `lambda_` (N, nc), for
    the reactions read from those multipliers (run state): the last KEEP_LAST arrays given, up to
    JACOBIAN_KEEP bytes in all, so that the reactions of a run's samples keep theirs while dense-output
    grids come and go."""
    kept = [e for e in sys.run_state.get("jacobians of multipliers", []) if e[0] is not lambda_]
    kept.append((lambda_, J))
    while kept and (len(kept) > KEEP_LAST or sum(e[1].nbytes for e in kept) > JACOBIAN_KEEP):
        kept.pop(0)
    sys.run_state["jacobians of multipliers"] = kept


def jacobians_of(sys, lambda_):
    """The constraint Jacobians (N, nc, nv) at the samples of `lambda_` when that array (the object
    itself, not equal values) was given to `keep_jacobians` lately, else None."""
    for lam, J in sys.run_state.get("jacobians of multipliers", []):
        if lam is lambda_:
            return J
    return None


def joint_reaction(sys, q, lambda_, joint, on=None, A=None, J=None, fr=None):
    """Force [N] and torque [N m] (N, 3), ground axes, that `joint` (a Joint or motion name) exerts on `on`.

    Optional precomputed geometry of the samples q (N, nq): A (N, nbody + 1, 3, 3) body rotation
    matrices (Frames.A), J (N, nc, nv) constraint Jacobians, fr the samples' Frames. Without J (nor
    Jacobians kept for this `lambda_` array, `keep_jacobians`) only the joint's own rows are evaluated
    at the frames (`equations.jacobian_blocks`): O(N) per joint, so the reactions of every joint of an
    N-body chain cost O(N^2) no longer O(N^3); the dense Jacobians remain for rows the kernels lack."""
    name = joint if isinstance(joint, str) else joint.name
    rows, geom = _rows_and_geometry(sys, name)
    body = on if on is not None else (joint.body_j if not isinstance(joint, str) else None)
    fid = geom.bj if body is None else sys.fid.get(body, -1)
    if fid not in (geom.bi, geom.bj):
        raise ModelError(f"joint '{name}'", "on", f"{body!r} is not one of the joint's bodies")
    if A is None and fr is not None:
        A = fr.A
    if J is None:
        J = jacobians_of(sys, lambda_)
    blocks = None
    if J is None:
        fr = body_frames(sys, np.atleast_2d(q)) if fr is None else fr
        blocks = jacobian_blocks(sys, fr, rows)
        A = fr.A if A is None else A   # (fr made here when none was given)
        if blocks is None:
            J = jacobians(sys, q)
            keep_jacobians(sys, lambda_, J)
    if fid == 0:  # ground: the opposite of the load on the other body, reduced to the same point
        other = geom.bi if geom.bj == 0 else geom.bj
        F, T = _load_on(sys, q, lambda_, rows, other, geom, A, J, blocks)
        return -F, -T
    return _load_on(sys, q, lambda_, rows, fid, geom, A, J, blocks)


def _rows_and_geometry(sys, name):
    """(constraint rows, joint geometry) of the joint or motion `name`: the joint's rows followed by those
    of the motions acting on it (a motion is part of the joint's load, as in Adams); cached in
    sys.derived (they depend on the model only)."""
    key = ("reaction rows", name)
    found = sys.derived.get(key)
    if found is None:
        rows = sys.owner_rows.get(name)
        if rows is None:
            raise ModelError(f"joint '{name}'", "joint", "has no constraint rows in the analysed model")
        for m in sys.model.motions.values():
            if m.joint.name == name and m.name in sys.owner_rows:
                rows = np.concatenate([rows, sys.owner_rows[m.name]])
        geom = sys.geoms.get(name) or sys.geoms[sys.model.motions[name].joint.name]
        found = sys.derived[key] = (np.asarray(rows, dtype=np.int64), geom)
    return found


def _load_on(sys, q, lambda_, rows, fid, geom, A=None, J=None, blocks=None):
    """Constraint force [N] and torque about the joint point [N m] (N, 3), ground axes, of `rows` on frame
    fid, for all samples at once; `blocks`: the rows' compact Jacobians (equations.jacobian_blocks),
    else the dense J (computed when None)."""
    s_B = geom.s_j if fid == geom.bj else geom.s_i
    a = int(sys.frame_v_adr[fid])
    q = np.atleast_2d(q)
    rigid = bool(sys.frame_rigid[fid])
    width = 6 if rigid else 3
    lam = np.asarray(lambda_)[:, rows]                        # (N, nr)
    if blocks is not None:                                     # (N, nr, 2, 6): the row's side on fid
        _, bi, bj = _packed(sys)[:3]
        Jb = np.zeros((len(q), len(rows), width))
        for side, b in ((0, bi), (1, bj)):
            on = b[rows] == fid
            Jb[:, on, :] = blocks[:, on, side, :width]
    else:
        J = jacobians(sys, q) if J is None else J
        Jb = J[:, rows, a:a + width]                           # (N, nr, 3 or 6): the body's columns
    Q = -np.einsum("nri,nr->ni", Jb, lam)                      # force (ground), torque about CM (body axes)
    F = Q[:, :3]
    if not rigid:
        return F, np.zeros_like(F)
    A = (body_frames(sys, q).A if A is None else A)[:, fid]
    T_cm = np.einsum("nij,nj->ni", A, Q[:, 3:])
    s = A @ -np.asarray(s_B, dtype=float)                      # r_CM - r_P (N, 3), ground axes
    s0, s1, s2, F0, F1, F2 = s[:, 0], s[:, 1], s[:, 2], F[:, 0], F[:, 1], F[:, 2]
    T = np.empty_like(F)                                       # T_cm + s x F
    T[:, 0] = T_cm[:, 0] + (s1 * F2 - s2 * F1)
    T[:, 1] = T_cm[:, 1] + (s2 * F0 - s0 * F2)
    T[:, 2] = T_cm[:, 2] + (s0 * F1 - s1 * F0)
    return np.ascontiguousarray(F), T
