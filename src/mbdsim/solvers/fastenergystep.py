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
# [record overflow, this step refined], 2 the powers at the state of f (the next step's first stage), 3 the
# stage powers (16, 2), 4 z = [D, W] [J] at the step's start, 5 z at its end, 6 z's dense output coefficients
# (7, 2), 7 scratch (2,), 8 z at the outputs (nout, 2), 9-10 the shape contacts' point records, 11 the
# refinement's interval stack (64, 4), 12 its scratch (3, 2), 13 [the largest kinetic energy at a step's end so
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
def energy_event(cm, wk, co, F, y, t0, h, t_ev, rtol, yq, yd):
    """z at an event t_ev [s] inside the step (t0, h) where the run ends or restarts (its dense output
    computed: after `_dense_coeffs`; `energy_output`)."""
    en = wk[53]
    energy_dense(co, wk, h)
    energy_output(cm, wk, F, y, t0, h, t_ev, rtol, yq, yd, en[7])
    en[4][0] = en[7][0]
    en[4][1] = en[7][1]


@kernel(_nrt=False)
def _power_gl(cm, wk, F, y, t0, h, a, b, yq, yd, out):
    """5-point Gauss-Lobatto of the powers [P, P_applied] over [a, b] inside the step (t0, h) on its dense
    output (F, y) into out (2,) [J]; rhs at each point (yq, yd: scratch of the state's size)."""
    pw = wk[53][0]
    out[0] = 0.0
    out[1] = 0.0
    half, mid = 0.5 * (b - a), 0.5 * (a + b)
    for g in range(5):
        x = mid + half * GL_X[g]
        _dense(F, y, t0, h, x, yq)
        rhs(cm, wk, x, yq, yd, bool(True))
        out[0] += GL_W[g] * half * pw[1]
        out[1] += GL_W[g] * half * pw[2]


@kernel(_nrt=False)
def _power_integral(cm, wk, F, y, t0, h, a, b, tol, yq, yd, out):
    """The integral of the powers over [a, b] inside the step (t0, h) on its dense output into out (2,) [J],
    by adaptive bisection of `_power_gl` from REFINE_SPLIT pieces until halves agree to tol [J] (its share
    (b - a) / span of it, at least 1e-3 of it: a kink is resolved to tol / 1000); returns the power
    evaluations made."""
    en = wk[53]
    S, g = en[11], en[12]
    span = b - a
    for k in range(REFINE_SPLIT):   # pushed last piece first: the first is integrated first
        lo = a + span * (REFINE_SPLIT - 1 - k) / REFINE_SPLIT
        hi = b if k == 0 else a + span * (REFINE_SPLIT - k) / REFINE_SPLIT
        _power_gl(cm, wk, F, y, t0, h, lo, hi, yq, yd, g[0])
        S[k, 0], S[k, 1], S[k, 2], S[k, 3] = lo, hi, g[0, 0], g[0, 1]
    top, nev = REFINE_SPLIT, 5 * REFINE_SPLIT
    out[0] = 0.0
    out[1] = 0.0
    while top > 0:
        top -= 1
        lo, hi, c0, c1 = S[top, 0], S[top, 1], S[top, 2], S[top, 3]
        mid = 0.5 * (lo + hi)
        _power_gl(cm, wk, F, y, t0, h, lo, mid, yq, yd, g[1])
        _power_gl(cm, wk, F, y, t0, h, mid, hi, yq, yd, g[2])
        nev += 10
        f0, f1 = g[1, 0] + g[2, 0], g[1, 1] + g[2, 1]
        share = max((hi - lo) / span, 1e-3) if span > 0.0 else 1.0
        if abs(f0 - c0) + abs(f1 - c1) <= tol * share or top + 2 > S.shape[0] or nev >= REFINE_EVALS \
                or hi - lo <= 1e-9 * h:
            out[0] += f0
            out[1] += f1
            continue
        S[top, 0], S[top, 1], S[top, 2], S[top, 3] = mid, hi, g[2, 0], g[2, 1]
        S[top + 1, 0], S[top + 1, 1], S[top + 1, 2], S[top + 1, 3] = lo, mid, g[1, 0], g[1, 1]
        top += 2
    return nev


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
    (F computed); marks the step refined (wk[53][1][1] = 1: its outputs and events integrate too); returns
    the power evaluations made."""
    en = wk[53]
    z, zn, out = en[4], en[5], en[7]
    tol = _energy_tol(wk, rtol, zn[0] - z[0], zn[1] - z[1])
    nev = _power_integral(cm, wk, F, y, t0, h, t0, t0 + h, tol, yq, yd, out)
    zn[0], zn[1] = z[0] + out[0], z[1] + out[1]
    en[1][1] = 1
    return nev


@kernel(_nrt=False)
def energy_output(cm, wk, F, y, t0, h, t, rtol, yq, yd, out):
    """z at t [s] inside the step (t0, h) into out (2,): its dense output (after `energy_dense`), or in a
    refined step the adaptive quadrature from t0; returns the power evaluations made."""
    en = wk[53]
    if en[1][1] == 0:
        energy_at(wk, t0, h, t, out)
        return 0
    z, zn = en[4], en[5]
    tol = _energy_tol(wk, rtol, zn[0] - z[0], zn[1] - z[1])
    nev = _power_integral(cm, wk, F, y, t0, h, t0, t, tol, yq, yd, out)
    out[0] += z[0]
    out[1] += z[1]
    return nev
