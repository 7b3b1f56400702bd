"""Compiled kinematic sweep of a zero-degree-of-freedom model (numba): no integration.

When the joints and motion drivers fix every degree of freedom, the state at each time t is solved
from the constraints alone (docs/theory.md section 6b, "Zero-DOF models"):

    phi(q, t) = 0                       positions (Newton, from a Taylor prediction)
    phi_q v = nu                        velocities
    M vd + phi_q^T lambda_ = Q,  phi_q vd = gamma    accelerations and multipliers (reactions)

State layout as in `fastdyn` (y = [q, v]: CM positions [m] and Euler parameters; CM velocities [m/s] in
ground axes and angular velocities [rad/s] in body axes); the predictions use the six-slot increment of
`fastdyn.increment_into` (translation [m] in ground axes, rotation vector [rad] in body axes). Each
time is reached from the previous solved state by sub-steps: q + h qdot + h^2/2 qddot + h^3/6 qdddot
predicted (the third derivative from the accelerations at the start and end of the previous sub-step),
Newton on the positions (`fastdyn.newton_positions`, as the projection of the dynamics),
`fastdyn.project_velocities` for the velocities, `fastdyn.accelerations` for vd and the multipliers
(at each output the minimum-norm multipliers of all rows when the factorisation held is the square
Jacobian's LU, `min_norm_at`: small zero-DOF models, `kkt_square`).
A sub-step is retried at half length when the Newton iteration fails, when it turns any body by more
than MAX_TURN, or when its correction is large against the predicted motion (a guard against
converging to another assembly branch); below a step of HMIN_REL |t| the failure is returned (lock-up:
no configuration satisfies the constraints, or a singular one), and so it is after MAX_FORCED sub-steps
in a row accepted at that length only (no progress) or MAX_SUBSTEPS in one `advance` (every loop bounded).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)
from .fastdyn import (OK, PROJECTION, SINGULAR, _to6, accelerations, accept_state, increment_into, newton_positions,
                      project_velocities, rows_dropped)
from .kkt_square import square_min_norm

MAX_TURN = 0.1        # rad: largest predicted rotation of a body in one sub-step
CORR_REL = 0.25       # a Newton correction above CORR_REL x the predicted increment (+ CORR_ABS) ...
CORR_ABS = 1e-6       # ... [m or rad, largest slot] halves the sub-step (branch guard)
HMIN_REL = 1e-12      # smallest sub-step [s] relative to max(1, |t|)
MAX_FORCED = 64       # sub-steps in a row accepted only because they are at HMIN_REL: no progress, PROJECTION
MAX_SUBSTEPS = 1_000_000   # sub-steps (retries included) of one `advance`: beyond, PROJECTION (bounded)
# stats (int64): 0 outputs solved, 1 sub-steps accepted, 2 sub-steps retried, 3 projections,
# 4 factorisations, 5 solved configurations where the factorisation dropped dependent loop rows
# (`kkt_tree.pivoted_chol`: a change point or a lock-up, where the constraints do not determine the
# rates; those come from the prediction)


@kernel(_nrt=False)
def advance(cm, wk, st, t1, q, v, vd, lam, tol, stats, S, dx6, a6, p6):
    """Carry the solved state (q, v, vd, lam) at time st[0] [s] to t1 [s] in place; st = [t, h, hp] with
    h the sub-step [s] to try first (np.inf: the whole span) and hp > 0 the length [s] of the previous
    sub-step, whose starting accelerations p6 (nf, 6; six slots) hold (hp = 0: none); all updated.
    Returns a status of `fastdyn` (OK, or the last failure when the sub-step fell below HMIN_REL); on
    failure (q, v, vd) are the last solved state, at st[0]. S (3, max(nq, nv)), dx6, a6 (nf, 6): scratch."""
    nq, nv = q.shape[0], v.shape[0]
    rigid = cm[6]
    t, h, hp = st[0], st[1], st[2]
    status = OK
    forced, tries = 0, 0
    while t1 - t > 1e-14 * max(1.0, abs(t1)):
        tries += 1
        if tries > MAX_SUBSTEPS or forced > MAX_FORCED or not h > 0.0:
            st[0], st[1], st[2] = t, h, hp
            return PROJECTION
        hmin = HMIN_REL * max(1.0, abs(t))
        h = min(h, t1 - t)
        if t1 - t - h <= 1e-14 * max(1.0, abs(t1)):
            h = t1 - t
        _to6(cm, v, dx6)
        _to6(cm, vd, a6)
        turn, inc = 0.0, 0.0
        c3 = h * h * h / (6.0 * hp) if hp > 0.0 else 0.0   # h^3/6 x (a - a_prev) / hp
        for f in range(1, dx6.shape[0]):
            for k in range(6):
                dx6[f, k] = h * dx6[f, k] + 0.5 * h * h * a6[f, k]
                if hp > 0.0:
                    dx6[f, k] += c3 * (a6[f, k] - p6[f, k])
                inc = max(inc, abs(dx6[f, k]))
            if rigid[f]:
                turn = max(turn, np.sqrt(dx6[f, 3] ** 2 + dx6[f, 4] ** 2 + dx6[f, 5] ** 2))
        if turn > MAX_TURN and h > hmin:
            h = max(h * 0.9 * MAX_TURN / turn, hmin)
            continue
        for i in range(nq):
            S[0, i] = q[i]
        for i in range(nv):
            S[1, i] = v[i]
            S[2, i] = vd[i]
            v[i] += h * vd[i]   # (the projection makes v exact: a prediction only)
        increment_into(cm, q, dx6)
        status, size, nfactor = newton_positions(cm, wk, t + h, q, v, tol)
        stats[4] += nfactor
        if status == SINGULAR:   # a singular Jacobian on the way: reported as a failed solve
            status = PROJECTION
        if status == OK:   # the rows in wk are at the converged q: the velocities directly
            status = project_velocities(cm, wk, v, bool(True))
            stats[3] += 1
            stats[4] += 1
        if status == OK and rows_dropped(cm, wk):
            stats[5] += 1
        if status == OK:
            status = accelerations(cm, wk, t + h, q, v, q, vd, lam, bool(False))
        if status == OK and (size <= CORR_REL * inc + CORR_ABS or h <= hmin):
            forced = 0 if size <= CORR_REL * inc + CORR_ABS else forced + 1
            accept_state(cm, wk)   # joint angles read from the frames: continued from this state on
            t += h
            stats[1] += 1
            for f in range(a6.shape[0]):
                for k in range(6):
                    p6[f, k] = a6[f, k]
            hp = h
            h = 2.0 * h
            continue
        for i in range(nq):   # retry at half length from the last solved state
            q[i] = S[0, i]
        for i in range(nv):
            v[i] = S[1, i]
            vd[i] = S[2, i]
        stats[2] += 1
        if h <= hmin:
            st[0], st[1], st[2] = t, h, hp
            return status if status != OK else PROJECTION
        h = max(0.5 * h, hmin)
    st[0], st[1], st[2] = t1, h, hp
    return OK


@entry(_nrt=False)
def min_norm_at(cm, wk, lam):
    """Turn the multipliers lam just solved (`fastdyn.accelerations`, rows and factorisation in wk at
    the same state) into the minimum-norm multipliers of all rows when the square LU is in wk
    (`kkt_square.square_min_norm`; nothing to do without dependent rows). True when lam now holds them,
    False when they are still the independent rows' (the caller's `compiled_run._full_multipliers`)."""
    if cm[31][4] != 2:
        return cm[32].shape[0] == cm[31][2]
    mn = wk[45]
    return square_min_norm(wk[5], cm[12], cm[13], cm[5], cm[6], cm[32], wk[32], wk[33], lam, mn[0], mn[1],
                           mn[2])


@kernel(_nrt=False)
def _solved_at(cm, wk, st, t1, q, v, vd, lam, tol, stats, S, dx6, a6, p6):
    """`advance` to t1 [s], then the minimum-norm multipliers (`min_norm_at`); when no sub-step was
    needed (t1 at the state's time to round-off) the equations are solved again there first, so that the
    rows and the factorisation in wk are those of the returned state. Returns (status, min-norm)."""
    before = stats[1]
    status = advance(cm, wk, st, t1, q, v, vd, lam, tol, stats, S, dx6, a6, p6)
    if status == OK and stats[1] == before:
        status = accelerations(cm, wk, st[0], q, v, q, vd, lam, bool(True))
        stats[4] += 1
    if status != OK:
        return status, False
    return OK, min_norm_at(cm, wk, lam)


@kernel(_nrt=False)
def _store(q, v, vd, lam, Y, VD, LAM, row):
    """Row `row` of the outputs: [q, v] into Y, vd into VD, the multipliers into LAM."""
    nq = q.shape[0]
    for i in range(nq):
        Y[row, i] = q[i]
    for i in range(v.shape[0]):
        Y[row, nq + i] = v[i]
        VD[row, i] = vd[i]
    for i in range(lam.shape[0]):
        LAM[row, i] = lam[i]


@entry(_nrt=False)
def sweep(cm, wk, st, tout, iout, Y, VD, LAM, MN, REF, q, v, vd, lam, tol, chunk, stats, S, dx6, a6, p6):
    """Solve the outputs tout[iout:] [s] in turn from the solved state (q, v, vd, lam) at st[0], writing
    [q, v] rows into Y, vd into VD and the multipliers into LAM: the minimum-norm ones of all rows where
    MN is set (`min_norm_at`), else those of the independent rows (zero at the others), and into REF
    (nout, len(wk[44][7])) the references [rad] of the joint angles continued in the kernel (torsion
    springs, stops, expressions on a loop joint's angle: `accept_state`) at each output, from which
    `states_at` restarts; stops after `chunk` outputs; st and p6 as in `advance`. Returns (status, next
    iout); on failure st[0] and (q, v) are the last solved state."""
    written = 0
    ref = wk[44][7]
    while iout < tout.shape[0]:
        status, MN[iout] = _solved_at(cm, wk, st, tout[iout], q, v, vd, lam, tol, stats, S, dx6, a6, p6)
        if status != OK:
            return status, iout
        _store(q, v, vd, lam, Y, VD, LAM, iout)
        for m in range(REF.shape[1]):
            REF[iout, m] = ref[m]
        iout += 1
        written += 1
        stats[0] += 1
        if written >= chunk and iout < tout.shape[0]:
            break
    return OK, iout


@entry(_nrt=False)
def states_at(cm, wk, times, Y, VD, LAM, MN, REF, ts, Yo, VDo, LAMo, MNo, tol, stats, S, dx6, a6, p6, q, v, vd,
              lam, st):
    """States, accelerations and multipliers at the times ts [s] (inside the run) into Yo, VDo, LAMo
    (MNo: minimum-norm multipliers, as MN of `sweep`): the same solve as `sweep`, from the output at or
    before each t (times, Y, VD, LAM, MN, REF: the run's outputs; the continued joint angles restart from
    that output's references REF, which leaves wk[44][7] changed; an output time gives its row as stored).
    Returns the number of times done (< len(ts) on failure)."""
    nq, n = q.shape[0], times.shape[0]
    ref = wk[44][7]
    for j in range(ts.shape[0]):
        lo, hi = 0, n   # k: the last output with times[k] <= ts[j] (0 before the first)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if times[mid] <= ts[j]:
                lo = mid
            else:
                hi = mid
        k = lo
        for i in range(nq):
            q[i] = Y[k, i]
        for i in range(v.shape[0]):
            v[i] = Y[k, nq + i]
            vd[i] = VD[k, i]
        for i in range(lam.shape[0]):
            lam[i] = LAM[k, i]
        st[0], st[1], st[2] = times[k], np.inf, 0.0
        if k > 0:   # the third derivative from the accelerations at the two outputs before t
            _to6(cm, VD[k - 1], p6)
            st[2] = times[k] - times[k - 1]
        MNo[j] = MN[k]
        for m in range(REF.shape[1]):
            ref[m] = REF[k, m]
        if ts[j] > times[k]:
            status, MNo[j] = _solved_at(cm, wk, st, ts[j], q, v, vd, lam, tol, stats, S, dx6, a6, p6)
            if status != OK:
                return j
        _store(q, v, vd, lam, Yo, VDo, LAMo, j)
    return ts.shape[0]
