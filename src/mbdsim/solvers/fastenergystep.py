"""The energy bookkeeping's part of the compiled DOP853 step (solvers.fastdop.run; issue 29): the
quadrature state z = [D, W] [J] (dissipated energy, applied loads' work since the run's start) integrated
with the step's own stage powers (solvers.fastenergy sums them in the loads), its dense output, and the
adaptive quadrature of the power on the step's dense output where the stage powers do not resolve it.
Split from fastdopstep (one module a concern).
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .fastdopstep import N_STAGES, _dense, _dense_rows
from .fastdyn import rhs

# ---------------------------------------------------------------- energy bookkeeping (solvers.fastenergy)
# wk[53] (system.compiled.energy_work): 0 pw [on, P, P_applied] of the last loads evaluation, 1 flags
# [record overflow, this step refined, its pieces], 2 the powers at the state of f (the next step's first
# stage), 3 the stage powers (16, 2), 4 z = [D, W] [J] at the step's start, 5 z at its end, 6 z's dense output
# coefficients (7, 2), 7 scratch (2,), 8 z at the outputs (nout, 2), 9-10 the shape contacts' point records,
# 11 the refinement's pieces (system.compiled.REFINE_PIECES, 23): [lo, hi, P at the nine nodes of its two
# halves' Gauss-Lobatto rules (lo, three inner, the middle, three inner, hi), the same for P_applied, the
# error estimate |halves - whole| [J], the halves' integrals of P and P_applied [J]], 12 its scratch
# (3, 2, 9): two pieces' own nodes, a piece's nine, 13 [the largest kinetic energy at a step's end so
# far [J]] (the energy scale of z's tolerance, as the monitor's). z' = [P, P_applied] is a quadrature state of
# the step: integrated with DOP853's weights and dense output from the stage powers, not in the error norm
# (the steps are the same with and without it). Where P is not smooth over a step (contact onset and
# separation, a clipped damping force, a mesh facet's edge: the state's error control does not see what
# the power does there) z's own embedded error estimate flags the step, and its increments come from an
# adaptive Gauss-Legendre quadrature of the power on the step's dense output instead (`energy_refine`),
# as the post-run reference does (results/energy.py).

# 5-point Gauss-Lobatto (exact to degree 7): its end points see a power that is nonzero only near an end of
# the step (a contact that separates just after the step's start), where Gauss points may all miss it
GL_X = np.array([-1.0, -np.sqrt(3.0 / 7.0), 0.0, np.sqrt(3.0 / 7.0), 1.0])
GL_W = np.array([0.1, 49.0 / 90.0, 32.0 / 45.0, 49.0 / 90.0, 0.1])
# the monomial coefficients of the Lagrange basis on those nodes: L_g(x) = sum_p LAGRANGE[g, p] x^p
LAGRANGE = np.ascontiguousarray(np.linalg.inv(np.vander(GL_X, 5, increasing=True)).T)
REFINE_SPLIT = 4      # a refined integral starts from this many equal pieces
REFINE_EVALS = 4000   # power evaluations one refined integral takes at most


@kernel(_nrt=False, inline="always")
def energy_first(wk, src):
    """The step's first stage power (wk[53][3][0]) from `src` (2,): the powers at the state of f."""
    en = wk[53]
    en[3][0, 0] = src[0]
    en[3][0, 1] = src[1]


@kernel(_nrt=False)
def energy_step(co, wk, h):
    """z at the end of the accepted step of size h [s]: z + h sum_j b_j P_j (wk[53][5])."""
    B = co[1]
    en = wk[53]
    PK, z, zn = en[3], en[4], en[5]
    for i in range(2):
        acc = 0.0
        for j in range(N_STAGES):
            acc += B[j] * PK[j, i]
        zn[i] = z[i] + h * acc


@kernel(_nrt=False)
def energy_dense(co, wk, h):
    """z's dense output coefficients over the step (its 16 stage powers: after `_dense_coeffs`)."""
    en = wk[53]
    _dense_rows(co[5], h, en[4], en[5], en[3], en[6])


@kernel(_nrt=False)
def energy_at(wk, t0, h, t, out):
    """z at t [s] inside the step (t0, h) into out (2,) (after `energy_dense`)."""
    en = wk[53]
    _dense(en[6], en[4], t0, h, t, out)


@kernel(_nrt=False)
def energy_event(co, wk, t0, h, t_ev):
    """z at an event t_ev [s] inside the step (t0, h) where the run ends or restarts (its dense output
    computed: after `_dense_coeffs`; `energy_output`)."""
    en = wk[53]
    energy_dense(co, wk, h)
    energy_output(wk, t0, h, t_ev, en[7])
    en[4][0] = en[7][0]
    en[4][1] = en[7][1]


@kernel(_nrt=False, inline="always")
def _power_at(cm, wk, F, y, t0, h, x, yq, yd, v, j):
    """The powers [P, P_applied] [W] at x [s] on the step's dense output (F, y) into v[0, j], v[1, j] (rhs
    there; yq, yd: scratch of the state's size)."""
    pw = wk[53][0]
    _dense(F, y, t0, h, x, yq)
    rhs(cm, wk, x, yq, yd, bool(True))
    v[0, j] = pw[1]
    v[1, j] = pw[2]


@kernel(_nrt=False)
def _pair(cm, wk, F, y, t0, h, lo, hi, P5, row, yq, yd):
    """Piece [lo, hi] of the refinement into the record `row` of wk[53][11] (module comment): from the powers
    P5 (2, 5) at its own Gauss-Lobatto nodes, the powers at its halves' six interior nodes (evaluated here),
    the halves' integral and its error estimate |halves - whole| [J] (zero at round-off)."""
    R = wk[53][11][row]
    R[0], R[1] = lo, hi
    hw = 0.25 * (hi - lo)
    V = wk[53][12][2]
    for c in range(2):
        V[c, 0], V[c, 4], V[c, 8] = P5[c, 0], P5[c, 2], P5[c, 4]
    for k in range(2):
        centre = lo + (2 * k + 1) * hw
        for g in range(1, 4):
            _power_at(cm, wk, F, y, t0, h, centre + hw * GL_X[g], yq, yd, V, 4 * k + g)
    err, big = 0.0, 0.0
    for c in range(2):
        whole, halves = 0.0, 0.0
        for g in range(5):
            whole += GL_W[g] * P5[c, g]
            halves += GL_W[g] * (V[c, g] + V[c, 4 + g])
            big = max(big, abs(P5[c, g]))
        for j in range(9):
            R[2 + 9 * c + j] = V[c, j]
            big = max(big, abs(V[c, j]))
        R[21 + c] = hw * halves
        err += abs(hw * halves - 2.0 * hw * whole)
    R[20] = err if err > 1e-13 * (hi - lo) * big else 0.0


@kernel(_nrt=False)
def _power_integral(cm, wk, F, y, t0, h, tol, yq, yd, out):
    """The integral of the powers over the step (t0, h) on its dense output into out (2,) [J]: an adaptive
    Gauss-Lobatto quadrature with a global error criterion (QUADPACK's): from REFINE_SPLIT pieces, the piece
    whose halves disagree most with it is split (its halves' nodes reused: 6 evaluations a split) until the
    estimates sum to at most tol [J], the records are full or REFINE_EVALS evaluations are spent (a kink is
    resolved to what tol needs, not to its length's share). The pieces stay in wk[53][11] (their count in
    wk[53][1][2]) for the partial integrals at the step's outputs (`_partial`); returns the evaluations."""
    en = wk[53]
    R, G = en[11], en[12]
    P5 = G[0]
    nev = 0
    for k in range(REFINE_SPLIT):
        lo, hi = t0 + h * k / REFINE_SPLIT, (t0 + h) if k == REFINE_SPLIT - 1 else t0 + h * (k + 1) / REFINE_SPLIT
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        for g in range(5):
            if g == 0 and k > 0:   # the previous piece's end
                P5[0, 0], P5[1, 0] = R[k - 1, 10], R[k - 1, 19]
                continue
            _power_at(cm, wk, F, y, t0, h, mid + half * GL_X[g], yq, yd, P5, g)
            nev += 1
        _pair(cm, wk, F, y, t0, h, lo, hi, P5, k, yq, yd)
        nev += 6
    n = REFINE_SPLIT
    while True:
        total, worst, j = 0.0, 0.0, -1
        for i in range(n):
            total += R[i, 20]
            if R[i, 20] > worst:
                worst, j = R[i, 20], i
        if total <= tol or j < 0 or n >= R.shape[0] or nev + 12 > REFINE_EVALS:
            break
        lo, hi = R[j, 0], R[j, 1]
        if hi - lo <= 1e-9 * h:   # not to be split further: its estimate no longer counts
            R[j, 20] = 0.0
            continue
        mid = 0.5 * (lo + hi)
        for c in range(2):   # its halves' nodes: the new pieces' own
            for g in range(5):
                G[0, c, g] = R[j, 2 + 9 * c + g]
                G[1, c, g] = R[j, 2 + 9 * c + 4 + g]
        _pair(cm, wk, F, y, t0, h, lo, mid, G[0], j, yq, yd)
        _pair(cm, wk, F, y, t0, h, mid, hi, G[1], n, yq, yd)
        n += 1
        nev += 12
    out[0] = 0.0
    out[1] = 0.0
    for i in range(n):
        out[0] += R[i, 21]
        out[1] += R[i, 22]
    en[1][2] = n
    return nev


@kernel(_nrt=False)
def _partial(wk, t, out):
    """The integral of the powers from the refined step's start to t [s] inside it into out (2,) [J]: the
    pieces before t whole, the one holding t through the quartic interpolant of its half's five nodes."""
    en = wk[53]
    R = en[11]
    out[0] = 0.0
    out[1] = 0.0
    for i in range(en[1][2]):
        lo, hi = R[i, 0], R[i, 1]
        if hi <= t:
            out[0] += R[i, 21]
            out[1] += R[i, 22]
            continue
        if lo >= t:
            continue
        hw = 0.25 * (hi - lo)
        k = 0 if t <= lo + 2.0 * hw else 1
        X = (t - (lo + (2 * k + 1) * hw)) / hw   # local coordinate of t in its half, [-1, 1]
        for c in range(2):
            acc = 0.0
            if k == 1:   # the left half whole
                for g in range(5):
                    acc += GL_W[g] * R[i, 2 + 9 * c + g]
            for g in range(5):
                q, xp, mp = 0.0, X, -1.0
                for p in range(5):
                    q += LAGRANGE[g, p] * (xp - mp) / (p + 1)
                    xp *= X
                    mp *= -1.0
                acc += q * R[i, 2 + 9 * c + 4 * k + g]
            out[c] += hw * acc


@kernel(_nrt=False)
def energy_kinetic(cm, wk):
    """The kinetic energy [J] of the frames in wk (those of the last evaluation: the step's end after
    `_stages`) into the running maximum wk[53][13][0]: z's energy scale (the state is accurate to rtol of
    it, so D and W need not be more)."""
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    mass, inertia, rigid = cm[9], cm[10], cm[6]
    T = 0.0
    for f in range(1, r.shape[0]):
        T += 0.5 * mass[f] * (rd[f, 0] * rd[f, 0] + rd[f, 1] * rd[f, 1] + rd[f, 2] * rd[f, 2])
        if rigid[f]:
            b0 = A[f, 0, 0] * w[f, 0] + A[f, 1, 0] * w[f, 1] + A[f, 2, 0] * w[f, 2]   # body axes
            b1 = A[f, 0, 1] * w[f, 0] + A[f, 1, 1] * w[f, 1] + A[f, 2, 1] * w[f, 2]
            b2 = A[f, 0, 2] * w[f, 0] + A[f, 1, 2] * w[f, 1] + A[f, 2, 2] * w[f, 2]
            I = inertia[f]
            T += 0.5 * (b0 * (I[0, 0] * b0 + I[0, 1] * b1 + I[0, 2] * b2) + b1 * (I[1, 0] * b0 + I[1, 1] * b1
                        + I[1, 2] * b2) + b2 * (I[2, 0] * b0 + I[2, 1] * b1 + I[2, 2] * b2))
    sc = wk[53][13]
    if T > sc[0]:
        sc[0] = T


@kernel(_nrt=False)
def _energy_tol(wk, rtol, est0, est1):
    """The refinement's tolerance [J]: 0.1 rtol (at least 1e-12) of |z|, the estimate of the increment and
    the energy scale (`energy_kinetic`)."""
    en = wk[53]
    z = en[4]
    return 0.1 * max(rtol, 1e-12) * (abs(z[0]) + abs(z[1]) + abs(est0) + abs(est1) + en[13][0]) + 1e-300


@kernel(_nrt=False)
def energy_flag(co, wk, h, rtol):
    """Whether z's embedded error estimate over the accepted step of size h (from the stage powers, the norm
    of the state's: scipy's DOP853) exceeds rtol of |z| or of the energy scale (`energy_kinetic`): its stage
    powers do not resolve the power there."""
    E3, E5 = co[3], co[4]
    en = wk[53]
    PK, z, zn = en[3], en[4], en[5]
    for i in range(2):
        a5, a3 = 0.0, 0.0
        for j in range(N_STAGES + 1):
            a5 += E5[j] * PK[j, i]
            a3 += E3[j] * PK[j, i]
        if a5 == 0.0 and a3 == 0.0:
            continue
        scale = max(rtol, 1e-12) * max(abs(z[i]), abs(zn[i]), abs(zn[i] - z[i]), en[13][0]) + 1e-300
        if h * a5 * a5 / np.sqrt(a5 * a5 + 0.01 * a3 * a3) > scale:
            return True
    return False


@kernel(_nrt=False)
def energy_refine(cm, wk, F, y, t0, h, rtol, yq, yd):
    """z at the end of a flagged step (t0, h) from the adaptive quadrature of the powers on its dense output
    (F computed); marks the step refined (wk[53][1][1] = 1: its outputs and events read the quadrature's
    pieces); returns the power evaluations made."""
    en = wk[53]
    z, zn, out = en[4], en[5], en[7]
    tol = _energy_tol(wk, rtol, zn[0] - z[0], zn[1] - z[1])
    nev = _power_integral(cm, wk, F, y, t0, h, tol, yq, yd, out)
    zn[0], zn[1] = z[0] + out[0], z[1] + out[1]
    en[1][1] = 1
    return nev


@kernel(_nrt=False)
def energy_output(wk, t0, h, t, out):
    """z at t [s] inside the step (t0, h) into out (2,): its dense output (after `energy_dense`), or in a
    refined step the quadrature's pieces up to t (`_partial`)."""
    en = wk[53]
    if en[1][1] == 0:
        energy_at(wk, t0, h, t, out)
        return
    _partial(wk, t, out)
    out[0] += en[4][0]
    out[1] += en[4][1]
