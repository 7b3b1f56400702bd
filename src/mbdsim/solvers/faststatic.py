"""Compiled evaluations of the static equilibrium solve (solvers.static, issue 29): the chart, the loads and
the unbalanced load of a batch of configurations in one call (numba).

For each row z of Z (independent coordinates, scaled as `reduced.tangent_basis` scales N), at time t [s]:

    x = project(q0 (+) N z)              `fastdyn.newton_positions` (mass-weighted minimum-norm Newton)
    Q = the applied loads at (x, v = 0)  `fastdyn.loads_into`: gravity, constant loads, springs,
                                         bushings, expression loads (torsion springs, stops), contacts,
                                         Python callables (called back)
    r = Q - phi_q^T lambda_              lambda_ the least-squares multipliers of the rows solved for
    f = N^T r                            the reduced (unbalanced) load, -dV/dz for loads with a potential

Layouts as in `fastdyn`: q holds CM positions [m] and Euler parameters; velocity-like vectors (N's rows, Q,
r) CM translations [m, N] in ground axes and rotations [rad, N m] in body axes. The joint angles that loads
read from the frames are continued within pi of their references (wk[44][7]); with `accept`, the state of
the first row becomes their reference (its angles continued), as an accepted step of a run does.
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel
from ..system.kernels import scatter_dense
from .fastdyn import OK, _from6, _to6, accept_state, increment_into, loads_into, newton_positions
from .loopcoord import wide_unit_load
from .minnorm import _chol_solve, _cholesky


@entry(_nrt=True)
def reduced_forces(cm, wk, t, q0, N, Z, tol, accept, F, R, X, Q0, J0, r0):
    """The batch of the module docstring: F[k] = N^T r (d,), R[k] = max |r| and X[k] the configuration x
    of row k of Z (m, d); Q0 (nv,), J0 (rows solved for: the independent rows, the re-selected loop rows
    and the wide coupler rows, nv) and r0 (nv,) the loads, the rows' Jacobian
    and the unbalanced load at the first row's x. Returns the number of rows done: < m when the projection of row k failed (no
    configuration on the constraints there) or a Python-callable load failed there."""
    nq, nv, d = q0.shape[0], N.shape[0], N.shape[1]
    nf = cm[5].shape[0]
    active, sel, wide = cm[32], wk[46], cm[50][17]
    na = active.shape[0]
    nr = na + sel.shape[0] + wide.shape[0]   # (wide coupler rows last: their Jacobian from loopcoord)
    wrow = np.zeros(nv)
    dz, dx6, F6 = np.zeros(nv), np.zeros((nf, 6)), np.zeros((nf, 6))
    v0, Q, r = np.zeros(nv), np.zeros(nv), np.zeros(nv)
    Jall = np.zeros((wk[5].shape[0], nv))
    Jd = np.zeros((nr, nv))
    G, lam = np.zeros((nr, nr)), np.zeros(nr)
    for k in range(Z.shape[0]):
        x = X[k]
        for i in range(nq):
            x[i] = q0[i]
        for i in range(nv):
            s = 0.0
            for j in range(d):
                s += N[i, j] * Z[k, j]
            dz[i] = s
        _to6(cm, dz, dx6)
        increment_into(cm, x, dx6)
        status, size, nfac = newton_positions(cm, wk, t, x, v0, tol)
        if status != OK:
            return k
        # the frames and rows in wk are those of the converged x
        if accept and k == 0:
            accept_state(cm, wk)
        loads_into(cm, wk, t, x, wk[0], wk[1], wk[2], wk[3], F6)
        if wk[48][1][1] != 0:   # a Python-callable load failed (its error kept by solvers.pyloads)
            wk[48][1][1] = 0
            return k
        for i in range(nv):
            Q[i] = 0.0
        _from6(cm, F6, Q)
        Jall[:, :] = 0.0
        scatter_dense(wk[5], cm[12], cm[13], cm[5], cm[6], Jall)
        nsel = na + sel.shape[0]
        for i in range(nsel):
            row = active[i] if i < na else sel[i - na]
            for c in range(nv):
                Jd[i, c] = Jall[row, c]
        for a in range(wide.shape[0]):   # G_a of each wide row (terms on three bodies or more)
            wide_unit_load(cm[50], wk[52], a)
            for c in range(nv):
                wrow[c] = 0.0
            _from6(cm, wk[52][13], wrow)
            for c in range(nv):
                Jd[nsel + a, c] = wrow[c]
        for i in range(nv):
            r[i] = Q[i]
        if nr > 0:
            if not _normal_solve(Jd, Q, G, lam):   # (dependent rows: least squares)
                lam[:] = np.linalg.lstsq(Jd.T, Q)[0]
            for c in range(nv):
                s = 0.0
                for i in range(nr):
                    s += Jd[i, c] * lam[i]
                r[c] -= s
        big = 0.0
        for c in range(nv):
            big = max(big, abs(r[c]))
        R[k] = big
        for j in range(d):
            s = 0.0
            for i in range(nv):
                s += N[i, j] * r[i]
            F[k, j] = s
        if k == 0:
            for i in range(nv):
                Q0[i] = Q[i]
                r0[i] = r[i]
            for i in range(nr):
                for c in range(nv):
                    J0[i, c] = Jd[i, c]
    return Z.shape[0]


@kernel(_nrt=False)
def _normal_solve(J, Q, G, lam):
    """lam (nr,) = (J J^T)^-1 J Q, the least-squares multipliers of independent rows J (nr, nv), by the
    Cholesky factorisation of G = J J^T (nr, nr, overwritten; minnorm's factor and solve); False when it is
    not positive definite (dependent rows: the caller solves by least squares)."""
    nr, nv = J.shape[0], J.shape[1]
    for i in range(nr):
        for k in range(i + 1):
            s = 0.0
            for c in range(nv):
                s += J[i, c] * J[k, c]
            G[i, k] = s
        s = 0.0
        for c in range(nv):
            s += J[i, c] * Q[c]
        lam[i] = s
    if not _cholesky(G, nr):
        return False
    _chol_solve(G, nr, lam)
    return True
