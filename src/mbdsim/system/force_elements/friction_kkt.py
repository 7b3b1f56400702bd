"""Joint friction loads: the normal load N(lambda_) and the KKT solve with slip friction coupled to lambda_.

See force_elements.friction for the model.  N = preload + sum_k w_k |L_k lambda_j| with L_k linear
maps of the joint's multipliers lambda_j (reaction force / moment components on body_j at the joint
point).  N is homogeneous of degree one in lambda_j, so with the direction u_k = L_k lambda_j / |.|
frozen, N = preload + g . lambda_j is linear: `friction_kkt` solves the augmented system with that
linearisation, refreshes the directions from the new multipliers and repeats until the solution is
stationary (1-3 solves; exact in one when the reaction direction does not depend on the friction).
"""
from __future__ import annotations

import warnings

import numpy as np

from ..._blas import scipy_linalg
from ...math.rotation import skew

from ...solvers.fastfriction import MAXIT   # iterations of the coupled friction KKT solve (one definition)


def load_maps(sys, fr, J, elem):
    """[(weight, L)]: N = preload + sum weight |L lambda_joint|, L linear maps of the joint's multipliers."""
    g = sys.geoms[elem.joint.name]
    jr = sys.owner_rows[elem.joint.name]
    b, s_b = (g.bj, g.s_j) if g.bj != 0 else (g.bi, g.s_i)
    a = sys.frame_v_adr[b]
    LF = -J[jr, a:a + 3].T
    h = fr.A[g.bi] @ g.h_i
    P = np.eye(3) - np.outer(h, h)
    LT = None
    if sys.frame_rigid[b]:
        A = fr.A[b]
        LT = A @ (-J[jr, a + 3:a + 6].T) - skew(A @ s_b) @ LF
    TP, TA = (None, None) if LT is None else (P @ LT, h[None] @ LT)   # bending / torsional moment maps
    terms = zip(term_weights(elem), (P @ LF, h[None] @ LF, TP, TA))
    return jr, [(w, L) for w, L in terms if w and L is not None]


def term_weights(elem):
    """Weights (w_PF, w_hF, w_PT, w_hT) of the normal-load terms |P F|, |h.F|, |P T|, |h.T| (0: omitted), see
    force_elements.friction: revolute (pin_radius, friction_arm, pin_radius / bending_arm, 0), translational
    (1, 0, 1 / effective_length, 1 / reaction_arm)."""
    e = elem
    inv = lambda x: 1.0 / x if x else 0.0  # noqa: E731
    if e.joint.kind == "revolute":
        return (e.pin_radius, e.friction_arm or 0.0, e.pin_radius * inv(e.bending_arm), 0.0)
    return (1.0, 0.0, inv(e.effective_length), inv(e.reaction_arm))


def normal_load(elem, maps, lam_j):
    """N (see module docstring) from the joint's multipliers lam_j."""
    return elem.preload + sum(w * float(np.linalg.norm(L @ lam_j)) for w, L in maps)


def _gradient(maps, lam_j):
    g = np.zeros(len(lam_j))
    for w, L in maps:
        y = L @ lam_j
        n = np.linalg.norm(y)
        if n > 0:
            g += w * (L.T @ y) / n
    return g


# ----------------------------------------------------------------------------- coupled KKT solve
def friction_kkt(sys, fr, J, gamma, Q, rows, t):
    """vd and full lambda_ (lock entries = friction multipliers) with slip friction loads coupled to lambda_.

    rows: the active rows (independent joint rows + active lock rows)."""
    sla = scipy_linalg()   # imported on first use: ~0.3 s at start-up, needed only with friction
    nv, nr = sys.nv, len(rows)
    K = np.zeros((nv + nr, nv + nr))
    K[:nv, :nv] = sys.M
    K[:nv, nv:] = J[rows].T
    K[nv:, :nv] = J[rows]
    b = np.concatenate([Q, gamma[rows]])
    pos = np.full(sys.nc, -1)
    pos[rows] = np.arange(nr)
    slips = []
    for name, st in sys.switched.items():
        m = st.at(t)
        if m is None or m[0] != "slip":
            continue
        elem = sys.model.forces[name]
        jr, maps = load_maps(sys, fr, J, elem)
        keep = pos[jr] >= 0
        maps = [(w, L[:, keep]) for w, L in maps]
        slips.append((elem, elem.mu_dynamic * m[1], J[sys.owner_rows[name][0]], maps, pos[jr][keep],
                      sys.owner_rows[name][0]))
    if not slips:
        x = _solve(K, b)
    else:   # K + U V(x)^T: one factorisation, then k x k solves per iteration (Woodbury)
        with warnings.catch_warnings():   # an exactly singular K: inf / nan, reported by _checked
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu = sla.lu_factor(K, check_finite=False)
        U = np.zeros((nv + nr, len(slips)))
        b2 = b.copy()
        for k, (elem, c, Jl, _, _, _) in enumerate(slips):
            U[:nv, k] = c * Jl
            b2[:nv] -= c * elem.preload * Jl
        x0 = _checked(sla.lu_solve(lu, b2, check_finite=False), b2)
        Z = sla.lu_solve(lu, U, check_finite=False)
        x = _checked(sla.lu_solve(lu, b, check_finite=False), b)
        for _ in range(MAXIT):
            lam = x[nv:]
            V = np.zeros((nv + nr, len(slips)))
            for k, (_, _, _, maps, idx, _) in enumerate(slips):
                V[nv + idx, k] = _gradient(maps, lam[idx])
            S = np.eye(len(slips)) + V.T @ Z
            x_new = _checked(x0 - Z @ np.linalg.solve(S, V.T @ x0), b2)
            done = np.linalg.norm(x_new - x) <= 1e-14 * (1.0 + np.linalg.norm(x))
            x = x_new
            if done:
                break
    vd, lam = x[:nv], np.zeros(sys.nc)
    lam[rows] = x[nv:]
    Qf = np.zeros(nv)
    for elem, c, Jl, maps, idx, lock in slips:
        lam[lock] = c * normal_load(elem, maps, x[nv:][idx])
        Qf -= Jl * lam[lock]
    cand = np.union1d(sys.fixed_rows, np.intersect1d(rows, sys.lock_rows)).astype(int)
    if len(cand) > nr:   # redundant rows dropped: minimum-norm distribution like the frictionless path
        lam[cand] = np.linalg.lstsq(J[cand].T, Q + Qf - sys.M @ vd, rcond=None)[0]
    return vd, lam


def _solve(K, b):
    return _checked(np.linalg.solve(K, b), b)   # LinAlgError when exactly singular (solvers.common)


def _checked(x, b):
    if not np.all(np.isfinite(x)) or np.max(np.abs(x), initial=0.0) > 1e13 * (1.0 + np.max(np.abs(b), initial=0.0)):
        raise np.linalg.LinAlgError("augmented matrix with friction is numerically singular")
    return x
