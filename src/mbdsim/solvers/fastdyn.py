"""Compiled equations of motion: right-hand side, projections and accelerations at one state (numba).

State y = [q, v] (system layout, docs/theory.md section 1). Every kernel takes the immutable compiled
model `cm` (`system.compiled.CompiledModel.arrays()`) and the per-run work arrays `wk`
(`system.compiled.Work.arrays()`), each a `mbdsim._slots.Slots`: one pointer, read as a tuple (``cm[9]``,
``wk[44][2]``, constant indices); see those for the slot order. Loads and solves use six slots per
frame: CM translation in ground axes [N, m/s^2], rotation in body axes [N m, rad/s^2]. `rhs`,
`accelerations` and `project` are wrapperless kernels (mbdsim._jit): a call from Python goes to their
Python-callable twins.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)

try:   # the expression VM (system.exprvm) compiles drivers; without it drivers stay in Python
    from ..system.exprvm import eval_program
    HAVE_VM = True
except ImportError:   # pragma: no cover - transitional, until system.exprvm lands
    HAVE_VM = False

    @kernel(_nrt=False)
    def eval_program(code, consts, tables, start, end, x, stack):
        return 0.0
from ..system.exprloads_kernel import accept_angles, expr_loads, wrapped_angles
from ..system.kernels import frames_into, quat_step, rows_kernel
from .fastcontact import shape_contacts
from .fastloads import bushings_kernel, contacts_kernel, loads_kernel
from .kkt_tree import _row_dot
from . import fastenergy, fastfriction, fasttree, loopcoord, pathcoord, treecoord
from .fastsolve import _factor, _factor_rows, _kkt, _reselect, _solve, _solve_rows, loop_ratio, rows_dropped  # noqa: F401
from .pycall import call_address

OK, SINGULAR, PROJECTION, NONFINITE, TINY_STEP, MAX_STEPS, STIFF, INTERRUPTED = 0, 1, 2, 3, 4, 5, 6, 7
CALLBACK_FAILED = 11   # a Python-callable load raised (solvers.pyloads keeps the error); 8-10: fastdop
FRICTION_FAILED = 12   # the coupled joint-friction solve did not converge (element in wk[50][15]); 13: fastdop


@kernel(_nrt=False)
def drivers_at(cm, wk, t):
    """Driver values f, f', f'' at time t [s] from the compiled expression programs, then those of the drivers
    written as Python callables (the callback of solvers.pyloads writes them into wk[34:37])."""
    code, consts, tables, start, end = cm[16], cm[17], cm[18], cm[19], cm[20]
    fv, x, stack = (wk[34], wk[35], wk[36]), wk[23], wk[24]
    nd = start.shape[0] // 3
    x[0] = t
    for d in range(nd):
        for k in range(3):
            p = 3 * d + k
            fv[k][d] = eval_program(code, consts, tables, start[p], end[p], x, stack)
    if wk[48][1][2] != 0:   # drivers written as Python callables (solvers.pyloads)
        _python_drivers(wk[48][1], t)


@kernel(_nrt=False, inline="never")
def _python_drivers(ctl, t):
    """Call the driver callback (address ctl[2]), which writes the callable drivers' values into the
    driver arrays; ctl[1] = 1 when it failed."""
    if call_address(ctl[2], t) != 0:
        ctl[1] = 1


@kernel(_nrt=False)
def loads_into(cm, wk, t, y, r, A, rd, w, F):
    """Gravity, gyroscopic torques, constant point forces/torques, linear spring-dampers, bushings, the
    loads written as expressions (system.exprloads_kernel; at time t [s], y: the joint-coordinate state on
    the tree path), contacts, shape contacts (solvers.fastcontact) and the loads written as Python callables (the callback of solvers.pyloads,
    reading the frames r, A, rd, w, which must be the work arrays wk[0:4]) into F. When the run keeps the
    energy bookkeeping (wk[53], solvers.fastenergy), the dissipation power and the applied loads' power of
    this state go to wk[53][0] (the shape contacts' points recorded into wk[53][9] for it)."""
    en = wk[53]
    pw = en[0]
    fastenergy.reset(pw)
    loads_kernel(cm[9], cm[10], cm[8], cm[6], cm[21], cm[22], cm[23], cm[24], cm[25], cm[26], cm[27], cm[28],
                 cm[29], r, A, rd, w, F, pw)
    if cm[36].shape[0]:
        bushings_kernel(cm[36], cm[37], cm[38], cm[39], cm[40], cm[41], r, A, rd, w, cm[6], F, wk[42][0],
                        wk[42][1], pw)
    if cm[43][7].shape[0]:
        expr_loads(cm[43], wk[44], t, y, r, A, rd, w, cm[6], F, pw)
    if cm[44][0].shape[0]:
        ct = cm[44]
        contacts_kernel(ct[0], ct[1], ct[2], ct[3], ct[4], r, A, rd, w, cm[6], F, pw)
    if cm[46][10].shape[0]:   # shape contacts (issue 30)
        sc = cm[46]
        on = pw[0] != 0.0   # then the touching points are recorded, for their dissipation power
        rec, nrec = (en[9], en[10]) if on else (sc[12], sc[13])
        nrec[0] = 0
        shape_contacts(sc, r, A, rd, w, cm[6], F, rec, nrec)
        if on:
            fastenergy.contact_power(sc[11], rec, nrec, pw, en[1])
    if wk[48][1][0] != 0:   # loads written as Python callables (solvers.pyloads), from the frames in wk
        _python_loads(wk[48][0], wk[48][1], t, F)
        if wk[48][1][3] != 0 and pw[0] != 0.0:   # their power Q . v [W], which the callback writes into the
            pw[2] += wk[48][0][0, 0]              # ground row: applied loads' work (solvers.fastenergy)


@kernel(_nrt=False, inline="never")
def _python_loads(F_ext, ctl, t, F):
    """Call the load callback (address ctl[0]; ctl[1] = 1 when it failed) and add its loads F_ext to F.
    Kept out of `loads_into` (never inlined, small arguments) so that the loads of every other model stay
    as cheap as before: with the call inline, a one-body tree's right-hand side took 0.3 us more."""
    if call_address(ctl[0], t) != 0:
        ctl[1] = 1
    for f in range(1, F.shape[0]):
        for k in range(6):
            F[f, k] += F_ext[f, k]


@kernel(_nrt=False)
def accept_state(cm, wk):
    """After an accepted step, with the frames of its state in wk[0:4] (the evaluation there): the joint
    angles that loads and sensors read from the frames (absolute coordinates) take their continued values
    there as their references (system.exprloads_kernel.accept_angles), so that they continue beyond +-pi."""
    if cm[43][0].shape[0]:
        accept_angles(cm[43], wk[44], wk[0], wk[1], wk[2], wk[3])


@entry(_nrt=False)
def angle_rows(cm, wk, Y, out):
    """The joint angles [rad] in (-pi, pi] that loads and sensors read from the frames (absolute
    coordinates) at each row Y[k] = [q, v] into out[k] (one column per measure of cm[43], 0 for the
    others): what `solvers.compiled_run` continues over a run's steps for the outputs' references."""
    nq = cm[31][0]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    for k in range(Y.shape[0]):
        frames_into(Y[k, :nq], Y[k, nq:], cm[0], cm[1], cm[2], cm[3], cm[4], r, A, rd, w)
        wrapped_angles(cm[43], r, A, rd, w, out[k])


@kernel(_nrt=False)
def _constraints(cm, wk, t, q, v):
    """Frames, driver values and constraint rows at (q, v, t) into the work arrays."""
    r_idx, p_idx, rd_idx, w_idx, rigid_fid, rigid = cm[0], cm[1], cm[2], cm[3], cm[4], cm[6]
    r, A, rd, w, phi, Jc, nu, gamma = wk[0], wk[1], wk[2], wk[3], wk[4], wk[5], wk[6], wk[7]
    frames_into(q, v, r_idx, p_idx, rd_idx, w_idx, rigid_fid, r, A, rd, w)
    if cm[19].shape[0] > 0:
        drivers_at(cm, wk, t)
    rows_kernel(r, A, rd, w, cm[11], cm[12], cm[13], cm[33], cm[34], cm[15],
                wk[34], wk[35], wk[36], rigid, phi, Jc, nu, gamma)
    if cm[50][0].shape[0]:   # coordinate constraints in closed loops (solvers.loopcoord)
        loopcoord.coord_rows(cm[50], wk[52], t, q, r, A, rd, w, rigid, phi, Jc, nu, gamma)
    if cm[49][0].shape[0]:   # point-on-curve constraints (solvers.pathcoord)
        pathcoord.path_rows(cm[49], wk[51], q, r, A, rd, w, rigid, phi, Jc, nu, gamma)


@entry(_nrt=False)
def residuals(cm, wk, times, Y, idx, rows, val, arg):
    """Run monitor: the largest |phi| [m or rad] over the constraint rows `rows` at the output rows
    Y[idx] = [q, v] (absolute coordinates, times [s]) into val, and the row where it occurs into arg
    (NaN wins); one call for all the samples checked."""
    nq = cm[31][0]
    phi = wk[4]
    for k in range(idx.shape[0]):
        i = idx[k]
        _constraints(cm, wk, times[i], Y[i, :nq], Y[i, nq:])
        best, at = 0.0, 0
        for a in range(rows.shape[0]):
            x = abs(phi[rows[a]])
            if not x <= best:
                best, at = x, rows[a]
                if not np.isfinite(x):
                    break
        val[k], arg[k] = best, at


@kernel(_nrt=False)
def accelerations(cm, wk, t, q, v, y, vd, lam, refactor=True):
    """vd (nv) and lam (nc, zero at inactive rows) from the equations of motion at (q, v, t); status.
    y: the state the loads read (`loads_into`): q itself on the absolute path, the joint-coordinate state
    [theta, theta_dot] (continuous angles) on the tree path. refactor=False reuses the factorisation in
    wk, valid when it was made at these positions q (the factorisation depends on q only), e.g. right
    after `project`. A tree with coordinate constraints (solvers.treecoord) solves them in joint coordinates
    first; their loads then act on the bodies, and their rows' multipliers and the auxiliary coordinates'
    accelerations are written from that solve."""
    coupled = cm[31][5] == 1 and cm[47][3].shape[0] > 1
    if coupled:
        st = tree_rhs(cm, wk, t, y, wk[49][12])
        if st != OK:
            return st
    _constraints(cm, wk, t, q, v)
    F = wk[8]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    loads_into(cm, wk, t, y, r, A, rd, w, F)
    if coupled:
        treecoord.add_loads(cm[47], wk[49], cm[42], r, A, F)
    if refactor and not _factor(cm, wk):
        return SINGULAR
    x6 = wk[25]
    for i in range(lam.shape[0]):
        lam[i] = 0.0
    _solve(cm, wk, F, wk[7], x6, lam)
    if cm[48][0].shape[0]:
        if not _friction(cm, wk, x6, lam):
            return FRICTION_FAILED
        if wk[53][0][0] != 0.0:   # joint friction's dissipation power (solvers.fastenergy)
            fastenergy.friction_power(cm[48][0], wk[5], cm[12], cm[13], cm[5], cm[6], v, lam, wk[53][0])
    _from6(cm, x6, vd)
    if cm[50][0].shape[0]:   # loop couplers: the auxiliary angles' accelerations, the link rows' multipliers
        loopcoord.aux_rates(cm[50], wk[52], x6, vd, lam)
    if cm[49][0].shape[0]:   # paths: the curve parameters' accelerations, the rows' ground-axes multipliers
        pathcoord.aux_rates(cm[49], wk[51], x6, vd, lam)
    if coupled:
        treecoord.fill_outputs(cm[47], wk[49], y.shape[0] // 2, wk[49][12], vd, lam)
    for i in range(vd.shape[0]):
        if not np.isfinite(vd[i]):
            return NONFINITE
    return OK


@kernel(_nrt=False)
def _friction(cm, wk, x6, lam):
    """Joint friction (solvers.fastfriction): the unit solutions of the loads -J_lock^T of the elements with a
    mode (the factorisation in wk, zero row right-hand side), then the coupled loads, into x6 and lam;
    False when their iteration fails."""
    fc, fw = cm[48], wk[50]
    if _unit_solutions(cm, wk) == 0:
        for e in range(fw[0].shape[0]):
            lam[fc[0][e]] = 0.0
        return True
    return fastfriction.couple(fc, fw, wk[5], cm[12], cm[13], wk[1], wk[7], x6, lam)


@kernel(_nrt=False)
def _unit_solutions(cm, wk):
    """Accelerations and multipliers (wk[50][3], [4]) of the unit loads -J_lock^T of the friction elements
    with a mode, with the factorisation in wk and a zero row right-hand side; their number."""
    fw = wk[50]
    mode, E6, EL, F6, zc = fw[0], fw[3], fw[4], fw[5], fw[6]
    Jc, bi, bj = wk[5], cm[12], cm[13]
    lock = cm[48][0]
    n = 0
    for e in range(mode.shape[0]):
        if mode[e] == 0:
            continue
        n += 1
        r = lock[e]
        for f in range(F6.shape[0]):
            for c in range(6):
                F6[f, c] = 0.0
        for side in range(2):
            b = bi[r] if side == 0 else bj[r]
            if b != 0:
                for c in range(6):
                    F6[b, c] -= Jc[r, side, c]
        for i in range(EL.shape[1]):
            EL[e, i] = 0.0
        _solve(cm, wk, F6, zc, E6[e], EL[e])
    return n


@entry(_nrt=False)
def stick_velocities(cm, wk, t, y):
    """The velocities of the state y = [q, v] at t [s] (absolute coordinates) corrected in place so that
    the joints of the sticking friction elements (wk[50]) are at rest: the mass-weighted minimum-norm
    correction that keeps the other constraints' rates (`fastfriction.stick_rates`); status."""
    nq = cm[31][0]
    q, v = y[:nq], y[nq:]
    _constraints(cm, wk, t, q, v)
    if not _factor(cm, wk):
        return SINGULAR
    _unit_solutions(cm, wk)
    v6 = wk[50][14]
    _to6(cm, v, v6)
    if not fastfriction.stick_rates(cm[48], wk[50], wk[5], cm[12], cm[13], v6):
        return SINGULAR
    _from6(cm, v6, v)
    return OK


@kernel(_nrt=False)
def _from6(cm, x6, x):
    """Six slots per frame -> system velocity layout."""
    vadr, rigid = cm[5], cm[6]
    for f in range(1, x6.shape[0]):
        n = 6 if rigid[f] else 3
        for k in range(n):
            x[vadr[f] + k] = x6[f, k]


@kernel(_nrt=False)
def _to6(cm, x, x6):
    vadr, rigid = cm[5], cm[6]
    for f in range(x6.shape[0]):
        for k in range(6):
            x6[f, k] = 0.0
        if f == 0:
            continue
        n = 6 if rigid[f] else 3
        for k in range(n):
            x6[f, k] = x[vadr[f] + k]


@kernel(_nrt=False)
def qdot_into(cm, q, v, qd):
    """dq/dt: CM velocities and Euler-parameter rates 1/2 p (x) (0, w_B)."""
    qdot_kernel(cm[0], cm[1], cm[2], cm[3], q, v, qd)


@kernel(_nrt=False)
def qdot_kernel(r_idx, p_idx, rd_idx, w_idx, q, v, qd):
    """`qdot_into` with explicit index arrays."""
    for k in range(r_idx.shape[0]):
        for c in range(3):
            qd[r_idx[k, c]] = v[rd_idx[k, c]]
    for k in range(p_idx.shape[0]):
        e0, e1, e2, e3 = q[p_idx[k, 0]], q[p_idx[k, 1]], q[p_idx[k, 2]], q[p_idx[k, 3]]
        x, y, z = v[w_idx[k, 0]], v[w_idx[k, 1]], v[w_idx[k, 2]]
        qd[p_idx[k, 0]] = 0.5 * (-e1 * x - e2 * y - e3 * z)
        qd[p_idx[k, 1]] = 0.5 * (e0 * x + e2 * z - e3 * y)
        qd[p_idx[k, 2]] = 0.5 * (e0 * y - e1 * z + e3 * x)
        qd[p_idx[k, 3]] = 0.5 * (e0 * z + e1 * y - e2 * x)


@kernel(_nrt=False)
def rhs(cm, wk, t, y, ydot, refactor=True):
    """ydot = [qdot, vd] at (t, y); returns a status code (OK when the solve succeeded). refactor=False:
    as in `accelerations`. Kernels pass their flags as `bool(True)` / `bool(False)`, never a bare constant
    or the default: numba compiles a callee once per literal (Literal[bool](True), Literal[bool](False),
    omitted), and with this tuple of arrays each such copy of rhs, accelerations and project cost ~8-20 s
    of a cold compile (issue 32; bench/RESULTS.md, Start-up). A joint-coordinate tree (dims[5] == 1) has y = [theta, theta_dot] and
    ydot = [theta_dot, theta_ddot] from the articulated-body algorithm (solvers.fasttree)."""
    if cm[31][5] == 1:
        return tree_rhs(cm, wk, t, y, ydot)
    nq = cm[31][0]
    q = y[:nq]
    v = y[nq:]
    st = accelerations(cm, wk, t, q, v, q, ydot[nq:], wk[26], refactor)
    qdot_into(cm, q, v, ydot[:nq])
    if cm[50][0].shape[0]:
        loopcoord.aux_qdot(cm[50], wk[52], ydot)
    if cm[49][0].shape[0]:
        pathcoord.aux_qdot(cm[49], wk[51], ydot)
    return st


@kernel(_nrt=False)
def tree_rhs(cm, wk, t, y, ydot):
    """Joint-coordinate right-hand side: frames by forward kinematics, loads, articulated-body solve."""
    tw = wk[43]
    nj = y.shape[0] // 2
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    fasttree.kinematics(cm[42], y, nj, r, A, rd, w, tw[10], tw[11])
    F = wk[8]
    loads_into(cm, wk, t, y, r, A, rd, w, F)
    if not fasttree.aba(cm[42], y, nj, r, A, rd, w, tw[10], F, cm[9], cm[10], tw, ydot):
        return SINGULAR
    if cm[47][3].shape[0] > 1:   # coordinate constraints (couplers, gears, user constraints) and motions
        _tree_drivers(cm, wk, t)
        if not treecoord.constrain(cm[47], wk[49], cm[42], tw, t, y, r, ydot):
            return SINGULAR
    for i in range(ydot.shape[0]):
        if not np.isfinite(ydot[i]):
            return NONFINITE
    return OK


@kernel(_nrt=False)
def _tree_drivers(cm, wk, t):
    """The motion drivers' values at t [s] for the tree's rows (solvers.treecoord.take_drivers)."""
    if cm[19].shape[0] > 0:
        drivers_at(cm, wk, t)
        treecoord.take_drivers(cm[47], wk[49], wk[34], wk[35], wk[36])


@kernel(_nrt=False)
def tree_project(cm, wk, t, y, tol):
    """`treecoord.project` of the joint state y at t [s] (drivers evaluated first): (status, moved)."""
    _tree_drivers(cm, wk, t)
    return treecoord.project(cm, wk, t, y, tol)


@entry(_nrt=False)
def write_state(cm, wk, y, yout, prev):
    """The output row (absolute coordinates and velocities, system layout) of the integrator's state y:
    a copy, or for a joint-coordinate tree the forward kinematics (Euler parameters continuous with prev,
    the previous output row, when it has the same size)."""
    if cm[31][5] != 1:
        for i in range(y.shape[0]):
            yout[i] = y[i]
        return
    tw = wk[43]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    fasttree.kinematics(cm[42], y, y.shape[0] // 2, r, A, rd, w, tw[10], tw[11])
    fasttree.to_maximal(cm[42], cm[1], cm[0], cm[2], cm[3], cm[4], r, A, rd, w, yout, prev)
    treecoord.write_aux(cm[47], y, cm[31][0], yout)


@entry(_nrt=False)
def read_state(cm, wk, yrow, y):
    """The integrator's state y of an output row (inverse of `write_state`)."""
    if cm[31][5] != 1:
        for i in range(y.shape[0]):
            y[i] = yrow[i]
        return
    nq = cm[31][0]
    r, A, rd, w = wk[0], wk[1], wk[2], wk[3]
    frames_into(yrow[:nq], yrow[nq:], cm[0], cm[1], cm[2], cm[3], cm[4], r, A, rd, w)
    fasttree.from_maximal(cm[42], y.shape[0] // 2, r, A, rd, w, y)
    treecoord.read_aux(cm[47], yrow, y)   # coupled angles: continuous, from their auxiliary coordinates


@entry(_nrt=False)
def joint_rows(cm, wk, Y, Yref, YJ):
    """Tree path: the joint state YJ[k] of each output row Y[k] (`read_state`), every angle continued to
    within pi of the reference joint state Yref[k] (Yref[-1] past its rows; e.g. the run's own state at a
    nearby step), so that loads of joint angles see the run's continuous angles beyond +-pi."""
    jtype, qadr = cm[42][1], cm[42][7]
    for k in range(Y.shape[0]):
        read_state(cm, wk, Y[k], YJ[k])
        kr = min(k, Yref.shape[0] - 1)   # one reference row serves all rows
        for c in range(qadr.shape[0]):
            if qadr[c] >= 0 and jtype[c] == 1:
                ref = Yref[kr, qadr[c]]
                d = YJ[k, qadr[c]] - ref
                YJ[k, qadr[c]] = ref + (d - 2.0 * np.pi * np.floor((d + np.pi) / (2.0 * np.pi)))


@kernel(_nrt=False)
def increment_into(cm, q, dx6):
    """q (+) dx: CM translations plus p <- p (x) exp(dx_w / 2) (body-axes rotation vectors), in place."""
    increment_kernel6(cm[0], cm[1], cm[4], q, dx6)


@kernel(_nrt=False)
def increment_kernel6(r_idx, p_idx, rigid_fid, q, dx6):
    """`increment_into` with explicit index arrays; dx6 (nf, 6) six slots per frame."""
    for k in range(r_idx.shape[0]):
        for c in range(3):
            q[r_idx[k, c]] += dx6[k + 1, c]
    for k in range(p_idx.shape[0]):
        f = rigid_fid[k]
        quat_step(q, p_idx, k, dx6[f, 3], dx6[f, 4], dx6[f, 5])


@kernel(_nrt=False)
def normalize_into(cm, q):
    normalize_kernel(cm[1], q)


@kernel(_nrt=False)
def normalize_kernel(p_idx, q):
    """Unit-normalise the Euler parameters in q."""
    for k in range(p_idx.shape[0]):
        n = 0.0
        for c in range(4):
            n += q[p_idx[k, c]] ** 2
        n = np.sqrt(n)
        for c in range(4):
            q[p_idx[k, c]] /= n


@kernel(_nrt=False)
def newton_positions(cm, wk, t, q, v, tol):
    """Newton on phi(q, t) = 0 from q, in place (Euler parameters normalised first; mass-weighted
    minimum-norm steps through the KKT factorisation in wk, at most 12), the rows in wk evaluated at the
    q returned. Returns (status: OK, NONFINITE (a residual not finite), SINGULAR (a factorisation
    failed) or PROJECTION (no convergence); the sum over the steps of the largest six-slot component
    [m or rad]; the number of factorisations)."""
    active, sel = cm[32], wk[46]
    x6, zero6, lam, c = wk[25], wk[27], wk[26], wk[29]
    normalize_into(cm, q)
    for f in range(zero6.shape[0]):
        for k in range(6):
            zero6[f, k] = 0.0
    size, nfactor = 0.0, 0
    for it in range(12):
        _constraints(cm, wk, t, q, v)   # phi and the Jacobian do not depend on v; nu, gamma are at (q, v)
        res = 0.0
        for i in range(active.shape[0] + sel.shape[0]):   # the rows solved for (loop rows re-selected)
            r = abs(wk[4][active[i]] if i < active.shape[0] else wk[4][sel[i - active.shape[0]]])
            if not np.isfinite(r):
                return NONFINITE, size, nfactor
            res = max(res, r)
        if cm[50][17].shape[0]:   # wide coupler rows (bordered on the others)
            r = loopcoord.wide_residual(cm[50], wk[4])
            if not np.isfinite(r):
                return NONFINITE, size, nfactor
            res = max(res, r)
        if res <= tol:
            if cm[50][0].shape[0]:   # loop couplers: psi <- the continued angles at the converged q
                loopcoord.sync_q(cm[50], wk[52], q)
            if cm[49][0].shape[0]:   # paths: s <- the foot points at the converged q
                pathcoord.sync_q(cm[49], wk[51], q)
            return OK, size, nfactor
        if not _factor(cm, wk):
            return SINGULAR, size, nfactor
        nfactor += 1
        for i in range(c.shape[0]):
            c[i] = -wk[4][i]
        _solve(cm, wk, zero6, c, x6, lam)
        step = 0.0
        for f in range(1, x6.shape[0]):
            for k in range(6):
                step = max(step, abs(x6[f, k]))
        size += step
        increment_into(cm, q, x6)
    return PROJECTION, size, nfactor


@kernel(_nrt=False)
def project(cm, wk, t, q, v, tol, exact_factor=True):
    """Project q onto phi(q, t) = 0 (`newton_positions`) and v onto phi_q v = nu.
    Leaves in wk the factorisation at the projected q (see `accelerations(refactor=False)`); with
    exact_factor=False the velocity step reuses the last Newton step's factorisation (positions a
    Newton step apart: the velocity residual is of the order of that step times the correction, far
    below round-off of the constraints), for outputs, after which the factorisation is not reused.
    A joint-coordinate tree satisfies its constraints by construction: nothing to do."""
    if cm[31][5] == 1:
        return OK
    status, _, nfactor = newton_positions(cm, wk, t, q, v, tol)
    if status != OK:
        return status
    return project_velocities(cm, wk, v, exact_factor or nfactor == 0)


@kernel(_nrt=False)
def project_velocities(cm, wk, v, refactor=True):
    """v onto phi_q v = nu (mass-weighted minimum-norm correction dv: M dv + J^T mu = 0, J dv = nu - J v)
    in place, with wk holding the constraint rows at the current positions (`_constraints`, after a
    converged position Newton); refactor=False reuses the factorisation in wk. Leaves in wk the
    factorisation used (at these positions when refactor). Returns OK or SINGULAR."""
    if refactor and not _factor(cm, wk):
        return SINGULAR
    active = cm[32]
    x6, zero6, lam, c = wk[25], wk[27], wk[26], wk[29]
    for f in range(zero6.shape[0]):
        for k in range(6):
            zero6[f, k] = 0.0
    v6 = wk[30]
    _to6(cm, v, v6)
    Jc, bi, bj, nu = wk[5], cm[12], cm[13], wk[6]
    sel = wk[46]
    for i in range(active.shape[0] + sel.shape[0]):   # the rows solved for (loop rows re-selected)
        row = active[i] if i < active.shape[0] else sel[i - active.shape[0]]
        c[row] = nu[row] - _row_dot(Jc, bi, bj, row, v6)
    if cm[50][17].shape[0]:   # wide coupler rows
        loopcoord.wide_velocity_rhs(cm[50], wk[52], nu, v6, c)
    _solve(cm, wk, zero6, c, x6, lam)
    vadr, rigid = cm[5], cm[6]
    for f in range(1, x6.shape[0]):
        n = 6 if rigid[f] else 3
        for k in range(n):
            v[vadr[f] + k] += x6[f, k]
    if cm[50][0].shape[0] or cm[49][0].shape[0]:   # psi', s' <- their rates at the projected velocities
        for f in range(1, x6.shape[0]):
            for k in range(6):
                v6[f, k] += x6[f, k]
        if cm[50][0].shape[0]:
            loopcoord.sync_v(cm[50], wk[52], v6, v)
        if cm[49][0].shape[0]:
            pathcoord.sync_v(cm[49], wk[51], v6, v)
    return OK
