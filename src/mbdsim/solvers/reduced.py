"""Independent coordinates on the constraint manifold, shared by statics and linearization.

At a configuration q0 (on phi(q, t) = 0) the admissible increments are the null space of phi_q. With a
basis N (nv x d) of it, independent coordinates z (d,) describe nearby configurations through the chart

    q(z) = project(q0 (+) N z)        ((+): `common.increment`; project: minimum-norm Newton onto phi = 0)

Units: the columns of N may be scaled, `scale` (nv,) multiplying the velocity variables: translations by
a length L [m] and rotations by 1 [rad] make z dimensionless (radian-equivalent), which statics uses for
its trust region; the linearization uses the plain orthonormal basis (scale 1).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._blas import scipy_linalg
from ..errors import SolverError
from ..system.equations import constraint_terms
from .common import increment


def length_scale(sys, q) -> float:
    """Characteristic length [m] of the model: the extent of ground's origin and every CM (1 m if none)."""
    pts = np.vstack([np.zeros(3)] + [q[sys.r_idx[k]] for k in range(sys.nbody)])
    L = float(np.max(np.ptp(pts, axis=0)))
    return L if L > 1e-9 else 1.0


def velocity_scale(sys, length: float) -> np.ndarray:
    """(nv,) scale of each velocity variable: `length` for CM translations, 1 for rotations and others."""
    s = np.ones(sys.nv)
    s[np.asarray(sys.rd_idx, dtype=int).reshape(-1)] = length
    return s


def tangent_basis(sys, q, t, rows, scale=None) -> np.ndarray:
    """N (nv, d): columns scale * (orthonormal basis of the null space of phi_q[rows] * scale), where
    d = nv - rank; an orthonormal basis of the admissible increments when scale is None."""
    s = np.ones(sys.nv) if scale is None else np.asarray(scale, dtype=float)
    J = constraint_terms(sys, q, np.zeros(sys.nv), t)[1][rows] if len(rows) else np.zeros((0, sys.nv))
    return null_basis(J, s)


def null_basis(J, s) -> np.ndarray:
    """N (nv, d): s * (orthonormal basis of the null space of J * s), J (rows, nv) the rows' Jacobian and
    s (nv,) the scale of each velocity variable; d = nv - rank (rank: singular values above 1e-9 of the
    largest, or of 1)."""
    s = np.asarray(s, dtype=float)
    if J.shape[0] == 0:
        return np.diag(s)
    _, sv, vt = np.linalg.svd(J * s, full_matrices=True)
    rank = int(np.sum(sv > 1e-9 * max(1.0, sv[0])))
    return s[:, None] * vt[rank:].T


@dataclass
class Chart:
    """q(z) = project(q0 (+) N z) at time t [s] on the constraint rows `rows`."""

    sys: object
    q0: np.ndarray
    t: float
    rows: np.ndarray
    N: np.ndarray

    @property
    def dim(self) -> int:
        return self.N.shape[1]

    def q(self, z, tol=1e-13, offset=None) -> np.ndarray:
        """Configuration at independent coordinates z (on phi = offset, nc, when given: motion inputs);
        SolverError when the projection fails."""
        x = increment(self.sys, self.q0, self.N @ z) if len(z) else self.q0.copy()
        q, res = _project_offset(self.sys, x, self.t, self.rows, np.zeros(self.sys.nc) if offset is None else offset, tol)
        if res > 1e-9:
            raise SolverError(f"the constraints cannot be satisfied at this configuration (residual {res:.3g})",
                              time=self.t, state=q)
        return q


def _project_offset(sys, q, t, rows, offset, tol, maxit=30):
    """Newton (minimum-norm steps) onto phi(q, t) = offset on the rows; returns (q, residual)."""
    zero = np.zeros(sys.nv)
    res = np.inf
    for _ in range(maxit):
        phi, J, _, _ = constraint_terms(sys, q, zero, t)
        r = (phi - offset)[rows]
        res = float(np.max(np.abs(r), initial=0.0))
        if res <= tol:
            break
        q = increment(sys, q, -min_norm(J[rows], r))
    return q, res


def min_norm(J, r):
    """Minimum-norm x with J x = r for independent rows J (Cholesky of J J^T; least squares if that fails)."""
    sla = scipy_linalg()   # imported on first use: ~0.3 s at start-up
    if J.shape[0] == 0:
        return np.zeros(J.shape[1])
    try:
        return J.T @ sla.cho_solve(sla.cho_factor(J @ J.T), r)
    except (np.linalg.LinAlgError, ValueError):
        return np.linalg.lstsq(J, r, rcond=None)[0]


def tangent_residual(sys, q, t, rows, Q):
    """(r, lambda_): r = Q - phi_q^T lambda_ with lambda_ the least-squares multipliers of the rows, i.e. the
    part of the generalized load Q (nv) that no constraint reaction can balance (zero at equilibrium)."""
    sla = scipy_linalg()   # imported on first use: ~0.3 s at start-up
    if not len(rows):
        return Q.copy(), np.zeros(0)
    J = constraint_terms(sys, q, np.zeros(sys.nv), t)[1][rows]
    try:
        lam = sla.cho_solve(sla.cho_factor(J @ J.T), J @ Q)
    except (np.linalg.LinAlgError, ValueError):
        lam = np.linalg.lstsq(J.T, Q, rcond=None)[0]
    return Q - J.T @ lam, lam


def describe_direction(sys, q, dx, length=1.0, t=0.0) -> str:
    """Human-readable motion of increment dx (nv): the bodies that move (CM direction in ground, rotation
    axis in ground) and the one-DOF joints whose coordinate changes, largest first."""
    from ..results.result import Result
    from ..system.frames import body_frames
    fr = body_frames(sys, q, np.zeros(sys.nv))
    parts = []
    for k, b in enumerate(sys.bodies):
        dr = dx[sys.rd_idx[k]] / length
        dw = np.zeros(3)
        if not b.is_particle:
            pi = list(sys.rigid_fid).index(k + 1)
            dw = fr.A[k + 1] @ dx[sys.w_idx[pi]]
        parts.append((max(np.linalg.norm(dr), np.linalg.norm(dw)), b.name, dr, dw))
    big = max((p[0] for p in parts), default=0.0)
    words = []
    for mag, name, dr, dw in sorted(parts, key=lambda p: -p[0]):
        if mag < 0.1 * big or big == 0.0:
            continue
        what = []
        if np.linalg.norm(dw) > 0.1 * mag:
            what.append("rotating about " + _fmt(dw / np.linalg.norm(dw)))
        if np.linalg.norm(dr) > 0.1 * mag:
            what.append("CM moving along " + _fmt(dr / np.linalg.norm(dr)))
        words.append(f"body '{name}' " + " and ".join(what))
    res = Result(sys, [t], q[None], np.asarray(dx, dtype=float)[None], None, None)
    joints = []
    for jt in sys.model.joints.values():
        if jt.kind in ("revolute", "translational"):
            try:
                rate = float(np.ravel(res.joint_velocity(jt))[0])
            except Exception:   # noqa: BLE001  (a description must never fail)
                continue
            joints.append((abs(rate), jt.name))
    jbig = max((j[0] for j in joints), default=0.0)
    named = [n for a, n in sorted(joints, reverse=True) if jbig > 0 and a > 0.1 * jbig]
    text = "; ".join(words) if words else "no body motion"
    return text + (f" (joint coordinates: {', '.join(named)})" if named else "")


def _fmt(u) -> str:
    return "(" + ", ".join(f"{x:.3g}" if abs(x) > 5e-4 else "0" for x in u) + ")"
