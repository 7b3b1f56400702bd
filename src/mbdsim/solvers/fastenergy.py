"""Energy bookkeeping inside the compiled step loop (issue 29): the power of the loads at one state (numba).

When a run's monitor checks the energy balance (`simulate(monitor=True)`), each evaluation of the loads
(`fastdyn.loads_into`) also sums, into the work slot wk[53][0] = pw:
  pw[1]  the dissipation power P [W] >= 0: damping of spring-dampers (c L_dot^2) and bushings
         (x_dot.C x_dot + w.C w, `fastloads`), sphere contacts and shape contacts ((Fn - k delta^e) (-g_dot)
         + friction force . slip velocity, `contact_power` from the points the contact kernel records),
         torsion springs and stops (the dissipation program of their joint load, `system.exprloads_kernel`)
         and joint friction (lambda_f x_dot, `friction_power`);
  pw[2]  the power of the applied loads [W]: constant and expression point forces (F . v of the point) and
         torques (T . w), and those written as Python callables (Q . v, from their callback: solvers.pyloads,
         fastdyn.loads_into);
the same laws as the `dissipation` evaluators of system.force_elements (the independent reference,
results/energy.py). pw[0] is 1.0 when this is on, 0.0 otherwise (then nothing is summed or recorded:
runs with monitor=False pay one comparison per kernel). The step loop (`solvers.fastdopstep`: stage
powers, the quadrature state z = [D, W] integrated with DOP853's own weights and dense output) keeps the
rest of slot 53 (system.compiled.energy_work).
"""
from __future__ import annotations

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel


@kernel(_nrt=False)
def reset(pw):
    """Start the sums of one loads evaluation (pw[1], pw[2] = 0 when on)."""
    if pw[0] != 0.0:
        pw[1] = 0.0
        pw[2] = 0.0


@kernel(_nrt=False)
def contact_power(pp, rec, nrec, pw, flags):
    """Dissipation power of the shape-contact points recorded in rec[:nrec[0]] (fastcontact.REC_FIELDS) with
    the pair laws pp (fastcontact.PAR_FIELDS) into pw[1]; flags[0] = 1 when the buffer was full (points may
    be missing: the run's D is then not served)."""
    n = nrec[0]
    if n >= rec.shape[0]:
        flags[0] = 1
    for k in range(n):
        pair = int(rec[k, 0])
        delta, Fn, s, gd = rec[k, 7], rec[k, 8], rec[k, 12], rec[k, 13]
        ft = (rec[k, 9] * rec[k, 9] + rec[k, 10] * rec[k, 10] + rec[k, 11] * rec[k, 11]) ** 0.5
        pw[1] += (Fn - pp[pair, 0] * delta ** pp[pair, 1]) * (-gd) + ft * s
    nrec[0] = 0


@kernel(_nrt=False)
def friction_power(lock, Jc, bi, bj, vadr, rigid, v, lam, pw):
    """Joint friction's dissipation power sum_e lambda_f,e x_dot_e [W] (x_dot_e = J_lock,e v, the joint
    coordinate's rate) into pw[1], from the multipliers lam of the coupled solve and the velocities v
    (system layout)."""
    for e in range(lock.shape[0]):
        r = lock[e]
        xd = 0.0
        for side in range(2):
            f = bi[r] if side == 0 else bj[r]
            if f == 0:
                continue
            m = 6 if rigid[f] else 3
            for k in range(m):
                xd += Jc[r, side, k] * v[vadr[f] + k]
        pw[1] += lam[r] * xd


@kernel(_nrt=False, inline="always")
def stage_power(wk, s):
    """The power of the loads evaluation just made (wk[53][0][1:3]) as stage s's (wk[53][3][s]), when the
    run keeps the energy bookkeeping."""
    en = wk[53]
    pw = en[0]
    if pw[0] != 0.0:
        en[3][s, 0] = pw[1]
        en[3][s, 1] = pw[2]
