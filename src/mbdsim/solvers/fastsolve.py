"""The augmented solve of the absolute-coordinate core at one configuration (numba): factor and solve
M x + J^T lambda = F, J x = c over the rows in the work arrays, six slots per frame (CM translation in
ground axes, rotation in body axes; loads [N, N m], accelerations [m/s^2, rad/s^2]).

`_factor_rows` / `_solve_rows`: the rows of the compact Jacobian (two blocks each) by the dense LU (singular
body masses), the square Jacobian's LU (zero-DOF models, solvers.kkt_square) or the tree elimination with
the loop rows' Schur complement (solvers.kkt_tree), re-selecting the loop rows in use when they turn
dependent. `_factor` / `_solve`: the same, with the wide coupler rows (terms moving three or more bodies,
solvers.loopcoord) bordered on it. Split out of solvers.fastdyn, which re-exports these names.
"""
from __future__ import annotations

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from . import loopcoord
from .kkt_square import square_factor, square_solve
from .kkt_tree import dense_factor, dense_solve, kkt_factor, kkt_solve

@kernel(_nrt=False)
def _factor(cm, wk):
    """`_factor_rows`, then the wide coupler rows bordered on it (solvers.loopcoord: the solve of each one's
    load with the other rows and their Schur complement). False if singular."""
    if not _factor_rows(cm, wk):
        return False
    lc, lw = cm[50], wk[52]
    if lc[17].shape[0] == 0:
        return True
    for a in range(lc[17].shape[0]):
        loopcoord.wide_unit_load(lc, lw, a)
        _solve_rows(cm, wk, lw[13], lw[14], lw[7][a], lw[8][a])
    return loopcoord.wide_schur(lc, lw)


@kernel(_nrt=False)
def _factor_rows(cm, wk):
    """Factor the augmented matrix at the rows in wk: dense LU (dims[4] = 1, singular body masses), the
    square Jacobian's LU (dims[4] = 2, zero-DOF models, `kkt_square`; the tree instead where it declines)
    or the tree elimination of `kkt_tree` over the loop rows in use (wk[46]), re-selected (`_reselect`)
    when they have turned (nearly) dependent. False if singular."""
    if cm[31][4] == 1:
        return dense_factor(wk[5], cm[12], cm[13], cm[7], cm[32], wk[32], wk[33])
    if cm[31][4] == 2 and square_factor(wk[5], cm[12], cm[13], cm[5], cm[6], cm[32], wk[32], wk[33]):
        return True
    sel, lim = wk[46], wk[47]
    if not _kkt(cm, wk, sel):
        return False
    if cm[45].shape[0] <= sel.shape[0]:
        return True
    ratio = loop_ratio(wk, sel.shape[0])
    if ratio >= lim[1]:
        lim[0] = lim[1]
        return True
    if ratio >= lim[0]:
        return True
    return _reselect(cm, wk)


@kernel(_nrt=False)
def _kkt(cm, wk, loop_rows):
    t = cm[30]
    return kkt_factor(wk[5], cm[12], cm[13], cm[7], t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], loop_rows,
                      wk[9], wk[10], wk[11], wk[12], wk[13], wk[14], wk[15], wk[16], wk[17], wk[18],
                      wk[20], wk[21], wk[37], wk[38], wk[40], wk[41])


@kernel(_nrt=False)
def loop_ratio(wk, n):
    """Smallest over largest pivot of the loop rows' Schur complement in the factorisation in wk (n loop
    rows; `kkt_tree.pivoted_chol`, whose pivots do not increase): 0 when rows were left out, 1 for none."""
    if n == 0:
        return 1.0
    if wk[41][0] < n:
        return 0.0
    LK = wk[18]
    return (LK[0, 0, 0] / LK[0, n - 1, n - 1]) ** 2


@kernel(_nrt=False)
def _reselect(cm, wk):
    """Choose the loop rows in use (wk[46]) anew among all loop rows of the tree (cm[45]) at the current
    positions: the first pivots of the pivoted Cholesky factorisation of all their Schur complement (the
    best conditioned independent subset, greedily), then factor with them. A loop carried on a turning
    body needs this: which of its rows are dependent changes with the turn (a four-bar's out-of-plane
    rows in ground axes). Where all loop rows lose rank (a change point of the mechanism) the rows in use
    are kept; where even the best subset stays nearly dependent, the re-selection threshold wk[47][0]
    drops below its ratio, so that the factorisations near it are not re-selected again; it returns to
    nominal once the ratio has recovered."""
    cand, sel, lim = cm[45], wk[46], wk[47]
    n = sel.shape[0]
    if not _kkt(cm, wk, cand):
        return False
    perm = wk[41]
    if perm[0] >= n:   # (all loop rows losing rank too is a change point: the rows in use are kept)
        for k in range(n):
            sel[k] = cand[perm[1 + k]]
    if not _kkt(cm, wk, sel):
        return False
    ratio = loop_ratio(wk, n)
    lim[0] = lim[1] if ratio >= lim[1] else 1e-2 * ratio
    return True


@kernel(_nrt=False)
def _solve(cm, wk, F, c_rows, x6, lam):
    """Accelerations x6 (six slots per frame) and multipliers lam (at the rows solved for) of loads F (nf, 6)
    and row right-hand sides c_rows (nc,) with the factorisation of `_factor`: `_solve_rows`, then the
    wide coupler rows' bordered correction (solvers.loopcoord.wide_correct)."""
    _solve_rows(cm, wk, F, c_rows, x6, lam)
    if cm[50][17].shape[0]:
        loopcoord.wide_correct(cm[50], wk[52], c_rows, x6, lam)


@kernel(_nrt=False)
def _solve_rows(cm, wk, F, c_rows, x6, lam):
    if cm[31][4] == 1:
        dense_solve(cm[32], wk[32], wk[33], F, c_rows, x6, lam, wk[39])
        return
    if cm[31][4] == 2 and wk[33][cm[32].shape[0]] == 1:
        square_solve(cm[32], cm[5], cm[6], cm[7], wk[32], wk[33], F, c_rows, x6, lam, wk[39])
        return
    t = cm[30]
    kkt_solve(wk[5], cm[12], cm[13], t[0], t[1], t[3], t[4], t[5], wk[46], wk[9], wk[10], wk[11], wk[12],
              wk[13], wk[14], wk[15], wk[16], wk[18], wk[19], wk[21], F, c_rows, x6, lam, wk[38], wk[41])


@kernel(_nrt=False)
def rows_dropped(cm, wk):
    """True when the factorisation in wk left dependent loop rows out of the solve (the tree's pivoted
    Cholesky at a change point, where the constraints do not determine the rates)."""
    if cm[31][4] == 1 or (cm[31][4] == 2 and wk[33][cm[32].shape[0]] == 1):
        return False
    return wk[41][0] < wk[46].shape[0]
