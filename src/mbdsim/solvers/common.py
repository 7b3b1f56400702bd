"""Shared numerical kernels of the solvers: manifold increments, projections, accelerations."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..errors import SolverError
from ..system.dynamics import applied_forces, solve_kkt
from ..system import kernels
from ..system.equations import constraint_terms
from ..system.frames import body_frames


def increment(sys, q, dx):
    """q (+) dx: translate CMs by dx [m], rotate bodies by the body-axes rotation vector dx [rad]."""
    q = kernels.increment_kernel(np.asarray(q, dtype=float), np.asarray(dx, dtype=float), sys.r_idx,
                                 sys.rd_idx, sys.p_idx, sys.w_idx)
    q[sys.aux_q_idx] += dx[sys.aux_v_idx]   # auxiliary coordinates (curve parameters): plain sums
    return q


def normalize(sys, q):
    """Unit-normalise the Euler parameters of q (copy)."""
    q = q.copy()
    if len(sys.p_idx):
        p = q[sys.p_idx]
        q[sys.p_idx] = p / np.linalg.norm(p, axis=-1, keepdims=True)
    return q


def qdot(sys, q, v):
    """dq/dt from velocity variables: rd for positions, 1/2 p (x) (0, w_B) for Euler parameters."""
    qd = kernels.qdot_kernel(np.asarray(q, dtype=float), np.asarray(v, dtype=float), sys.r_idx,
                             sys.rd_idx, sys.p_idx, sys.w_idx, sys.nq)
    qd[sys.aux_q_idx] = v[sys.aux_v_idx]
    return qd


DENSE_LIMIT = 600   # velocity variables; larger systems use sparse factorisations (O(N) for chains, trees)


def independent_rows(J, tol=1e-9, sys=None):
    """Indices of a maximal independent subset of the rows of J: rank-revealing pivoted QR, or for a
    large System (sys given) its spanning-tree rows plus the loop rows that are independent of them."""
    if J.shape[0] == 0:
        return np.arange(0)
    if sys is not None and J.shape[1] > DENSE_LIMIT:
        rows = _independent_rows_sparse(sys, J, tol)
        if rows is not None:
            return rows
    _, R, piv = sla.qr(J.T, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tol * max(1.0, d[0] if len(d) else 1.0)))
    return np.sort(piv[:rank])


def _independent_rows_sparse(sys, J, tol):
    """Tree rows (independent by construction, checked by the sparse factorisation of J_T J_T^T) plus
    the loop rows whose projection on the tree rows' null space is independent (pivoted QR of the small
    projected block); None when the tree rows turn out dependent (then the dense QR decides)."""
    from scipy import sparse
    from scipy.sparse.linalg import splu
    from ..system.topology import system_topology
    topo = system_topology(sys, np.arange(J.shape[0]))
    tree = np.sort(topo.blk_rows)
    loop = np.asarray(topo.loop_rows)
    JT = sparse.csr_matrix(J[tree])
    try:
        lu = splu((JT @ JT.T).tocsc())
    except RuntimeError:          # singular: dependent rows inside the tree
        return None
    d = np.abs(lu.U.diagonal())
    if d.min() <= 1e-13 * d.max():
        return None
    if len(loop) == 0:
        return tree
    K = J[loop]
    X = lu.solve(np.asarray(JT @ K.T))
    P = K - (JT.T @ X).T          # loop rows projected onto null(J_T)
    _, R, piv = sla.qr(P.T, mode="economic", pivoting=True)
    dd = np.abs(np.diag(R))
    rank = int(np.sum(dd > tol * max(1.0, dd[0] if len(dd) else 1.0)))
    return np.sort(np.concatenate([tree, loop[piv[:rank]]]))


def min_norm_solve(J, r):
    """Minimum-norm x with J x = r (least squares when inconsistent): dense lstsq for small systems,
    else the sparse normal equations (J J^T + eps I) y = r, x = J^T y (eps: 1e-14 of the largest diagonal)."""
    if J.shape[1] <= DENSE_LIMIT or J.shape[0] == 0:
        return np.linalg.lstsq(J, r, rcond=None)[0]
    from scipy import sparse
    from scipy.sparse.linalg import splu
    Js = sparse.csr_matrix(J)
    S = (Js @ Js.T).tocsc()
    S = S + 1e-14 * max(float(S.diagonal().max()), 1e-300) * sparse.identity(S.shape[0], format="csc")
    return Js.T @ splu(S).solve(np.asarray(r, dtype=float))


def dependent_owners(sys, J, rows):
    """Names of the joints/motions whose rows take part in the dependencies of J."""
    removed = np.setdiff1d(np.arange(J.shape[0]), rows)
    if len(removed) == 0:
        return []
    ns = sla.null_space(J.T)
    involved = np.where(np.any(np.abs(ns) > 1e-8, axis=1))[0]
    names = []
    for r in np.concatenate([involved, removed]):
        if sys.row_owner[r] not in names:
            names.append(sys.row_owner[r])
    return names


def active_rows(sys, rows, t):
    """rows plus the switched rows in force at t (stick locks of joint friction, force_elements.friction)."""
    if not len(sys.lock_rows):
        return rows
    from ..system.force_elements.friction import locks_at
    locks = locks_at(sys, t)
    return np.union1d(rows, locks).astype(int) if locks else rows


def project_positions(sys, q, t, rows, tol=1e-12, maxit=25):
    """Newton (minimum-norm steps) onto phi(q, t) = 0 for the given rows; returns (q, residual, iterations)."""
    rows = active_rows(sys, rows, t)
    zero = np.zeros(sys.nv)
    res = np.inf
    for it in range(maxit):
        phi, J, _, _ = constraint_terms(sys, q, zero, t)
        phi, J = phi[rows], J[rows]
        res = float(np.max(np.abs(phi))) if len(phi) else 0.0
        if res <= tol:
            return q, res, it
        dx = -min_norm_solve(J, phi)
        q = increment(sys, q, dx)
        if it > 3 and float(np.max(np.abs(dx))) < 1e-15:
            break
    return q, res, maxit


def project_velocities(sys, q, v, t, rows):
    """Minimum-norm correction of v so that phi_q v = nu on the given rows."""
    rows = active_rows(sys, rows, t)
    _, J, nu, _ = constraint_terms(sys, q, v, t)
    J, nu = J[rows], nu[rows]
    if len(nu) == 0:
        return v
    return v - min_norm_solve(J, J @ v - nu)


def accelerations(sys, q, v, t, rows, state_factory=None):
    """vd and lambda_ (full nc, minimum-norm where redundant) from the equations of motion at (q, v, t)."""
    rows = active_rows(sys, rows, t)
    fr = body_frames(sys, q, v)
    state = state_factory(t, q, v) if state_factory else None
    Q = applied_forces(sys, fr, t, state)
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    try:
        if len(sys.lock_rows):   # joint friction: slip loads depend on lambda_ (coupled KKT solve)
            from ..system.force_elements.friction_kkt import friction_kkt
            return friction_kkt(sys, fr, J, gamma, Q, rows, t)
        vd, lam_i = solve_kkt(sys.M, J[rows], Q, gamma[rows])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"singular equations of motion (lock-up or singular configuration): {exc}",
                          time=t, joints=_worst_joints(sys, J, rows)) from None
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


def analysis_error(exc: BaseException, t) -> Exception:
    """The mbdsim error that ends an analysis for exception `exc` caught at about time t [s]: mbdsim errors
    as they are, KeyboardInterrupt as AnalysisInterrupted, anything else (numpy/LAPACK failures, a bug
    in a user function not caught by system.guard) as a SolverError naming its type and the time."""
    from ..errors import AnalysisInterrupted, MbdsimError
    if isinstance(exc, MbdsimError):
        return exc
    t = None if t is None else float(t)
    if isinstance(exc, KeyboardInterrupt):
        return AnalysisInterrupted("interrupted (KeyboardInterrupt)", time=t)
    return SolverError(f"{type(exc).__name__}: {exc}", time=t)
