"""Constraint and held rows of any System in sparse form, for the sparse assembly (issue 35).

- `sparse_terms_all`: phi, phi_q (CSR), nu, gamma and the compact rows of every row of a System: the
  rows the compiled kernel evaluates (`assembly_large.sparse_terms`), point-on-curve rows (the kernel's
  spherical rows at the curve point c(s), plus their column -A_i c'(s) on the curve parameter s and the
  parameter-rate part of gamma, as `system.equations`' mixed route), and coupler, gear and user
  coordinate rows (`constraints.coupler.CoordEval`, each row O(nv), scattered sparse); friction lock
  rows are the kernel's angle and slide rows.  No dense (nc, nv) matrix.
- `rotvec_rows`: the held coordinates of spherical, universal and constant-velocity joints (relative
  rotation vector [rad] of body_j w.r.t. its drawn attitude on body_i, in body_i axes) with their
  position rows J_l(th)^-1 W and rate rows W (relative angular velocity [rad/s], body_i axes) as compact
  rows on the joint's two bodies: the values and rows of `held.joint_values`, for all such joints at
  once, O(joints).
"""
from __future__ import annotations

import numpy as np

from .._blas import lazy_import
from ..system.equations import _mixed_plan, _packed, driver_values
from ..system.frames import body_frames
from ..system import kernels
from .assembly_large import compact_to_csr, sparse_terms


class _RowSink:
    """Stands for phi_q in `CoordEval.evaluate`: keeps the rows written to it, {row: dense row (nv,)}."""

    def __init__(self):
        self.rows: dict = {}

    def __setitem__(self, r, row):
        self.rows[int(r)] = np.asarray(row, dtype=float)


def sparse_terms_all(sys, q, v, t):
    """(phi (nc,), phi_q CSR (nc, nv), nu (nc,), gamma (nc,), compact rows (nc, 2, 6)) at (q, v, t) of any
    System (see the module docstring); the compact rows of coupler rows are zero and those of curve rows
    leave out the curve parameter's column (the CSR matrix has all)."""
    if sys.kernel_rows:
        return sparse_terms(sys, q, v, t)
    from ..system.constraints.path import curve_extra_quad, curve_locals
    from ..system.constraints.coupler import coord_terms
    kind, bi, bj, V, par, drv, fns = _packed(sys)
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    fr = body_frames(sys, q, v)
    fr.t = t
    fr.aux_q, fr.aux_v = q[sys.aux_q_idx], v[sys.aux_v_idx]
    curve_groups, rest = _mixed_plan(sys)
    curves = [(g, idx, curve_locals(fr, g)) for g, idx in curve_groups]
    if curves:
        V = V.copy()
        for g, idx, (_, _, c, _, _) in curves:
            V[idx, 0] = np.repeat(c, 3, axis=0)
    f, fd, fdd = driver_values(fns, t)
    nc = sys.nc
    phi, nu, gamma, Jc = np.zeros(nc), np.zeros(nc), np.zeros(nc), np.zeros((nc, 2, 6))
    kernels.rows_kernel(fr.r, fr.A, fr.rd, fr.w, kind, bi, bj, V, par, drv, f, fd, fdd, sys.frame_rigid,
                        phi, Jc, nu, gamma)
    er, ec, ev = [], [], []   # entries beyond the compact rows: curve parameters, coupler rows
    for g, idx, (aux, sd, _, t1, t2) in curves:
        gamma[idx] += curve_extra_quad(fr, g, sd, t1, t2)
        er.append(idx)
        ec.append(np.repeat(sys.aux_v_idx[aux], 3))
        ev.append(-t1.reshape(-1))
    sink = _RowSink()
    for g in rest:
        if g.kind != "coord":  # pragma: no cover - the packed kinds are all the kernel's but these
            raise ValueError(f"constraint rows of kind {g.kind!r} have no sparse form")
        coord_terms(sys, g, fr, q, v, t, phi, sink, nu, gamma)
    for r, row in sink.rows.items():
        nz = np.flatnonzero(row)
        er.append(np.full(len(nz), r))
        ec.append(nz)
        ev.append(row[nz])
    J = compact_to_csr(sys, Jc, bi, bj)
    if er:
        sparse = lazy_import("scipy.sparse")
        J = (J + sparse.csr_matrix((np.concatenate(ev), (np.concatenate(er), np.concatenate(ec))),
                                   shape=(nc, sys.nv))).tocsr()
    return phi, J, nu, gamma, Jc


def rotvec_rows(sys, joints, q, rates):
    """(values th (n, 3) [rad], compact rows (n, 3, 2, 6) on the frames (bi, bj) of each joint) of the
    rotation-vector joints `joints` at q: the position rows J_l(th)^-1 W of th (per body-axes rotation
    increment), or with `rates` the rows W of the relative angular velocity [rad/s] (body_i axes)."""
    from scipy.spatial.transform import Rotation
    from ..results.joints import rotvec_rate
    n = len(joints)
    if not n:
        return np.zeros((0, 3)), np.zeros((0, 3, 2, 6))
    fr = body_frames(sys, q)
    geoms = [sys.geoms[jt.name] for jt in joints]
    bi = np.array([g.bi for g in geoms], dtype=np.int64)
    bj = np.array([g.bj for g in geoms], dtype=np.int64)
    R0 = np.array([jt.body_i.orientation.T @ jt.body_j.orientation for jt in joints])
    Ai, Aj = fr.A[bi], fr.A[bj]
    AiAj = np.einsum("nji,njk->nik", Ai, Aj)
    th = Rotation.from_matrix(AiAj @ np.transpose(R0, (0, 2, 1))).as_rotvec().reshape(n, 3)
    W = np.zeros((n, 3, 2, 6))
    W[:, :, 0, 3:] = -np.eye(3)   # w_rel = A_i^T (A_j w_j - A_i w_i), w body axes
    W[:, :, 1, 3:] = AiAj
    if rates:
        return th, W
    E = np.broadcast_to(np.eye(3), (n, 3, 3)).reshape(-1, 3)
    Jinv = rotvec_rate(np.repeat(th, 3, axis=0), E).reshape(n, 3, 3).transpose(0, 2, 1)   # columns: e_k
    return th, np.einsum("nij,njsk->nisk", Jinv, W)
