"""Joint friction with stick/slip on the compiled core (issue 29): the coupled friction loads of one
right-hand side and the switching functions (numba kernels; docs/theory.md 12a, 12c).

Each friction element e acts on its joint coordinate x through the multiplier lambda_f of its lock row
(load -J_lock^T lambda_f on the bodies; friction force -lambda_f). With the frictionless solution
(vd0, lambda0) of the step loop's KKT solve and the unit solutions (vd_e, lambda_e) of the loads
-J_lock,e^T (zero row right-hand side; `fastdyn._friction`), the solution is vd0 + sum f_e vd_e, and
the loads f solve the k x k system
    stick (mode 2):  J_lock,e vd = gamma_lock,e                          (the joint does not accelerate)
    slip  (mode 1):  f_e = mu_dynamic s_e N_e(lambda0 + sum f_m lambda_m)   (s_e the slip direction)
    none  (mode 0):  f_e = 0                                              (held, undecided)
N_e = preload + sum_t w_t |y_t| with y_t the four reaction terms P F, h.F, P T, h.T of the joint's
reaction (force F, moment T about the joint point, ground axes, on body_j or body_i when body_j is
ground; h the joint axis, P = I - h h^T): homogeneous of degree one in the joint's multipliers, so
with the term directions u_t = y_t / |y_t| frozen N is linear and the system is solved exactly; the
directions are refreshed from the new multipliers and the solve repeated until the loads are stationary
(1-3 solves; MAXIT at most, else failure naming the element). One factorisation serves all: the unit
solutions are k more solves with it, the iteration works on k x k matrices only (the Woodbury form of
`force_elements.friction_kkt`, which is the independent reference).

Switching functions (`switching`, located on the step's dense output by `fastdop`): slip: s xd + V_TOL/2
(zero when the joint has come to rest); stick: C - |lambda_f| + STICK_TOL (1 + C) with the static
capacity C = mu_static N (zero when static friction cannot hold it); 1 otherwise.  A held group (joints
of a loop stopped together whose lock rows depend on each other, `friction_run`): only the sticking
elements' locks act; the held members h (mode 0, fw[20][h] = the group's id, as for its sticking
members) share the capacity through their lock rows in the sticking ones', c_h = fw[21][h] (on the
motions the other rows allow): the group holds while the sticking locks' multipliers lie in the
zonotope of the members' capacities (`group_margin`, the closed form of the reference's least-load
distribution `force_elements.friction_lcp.group_load`; one sticking member: C = mu_s N_a +
sum_h |c_h| mu_s,h N_h). Its tolerance is n_g STICK_TOL (1 + C) for a group of n_g joints, so that at
its zero the reference's per-member margins reject sticking (the decision at the event is the
reference's).

cm[48] (system.compiled._friction), per element e of k:
  0 lock (k,) int64: its lock row;  1 jrows (k, R) int64: the joint's rows (-1 padding);
  2 fid (k, 2) int64: frame b whose reaction is read, frame of the axis (body_i);
  3 vec (k, 2, 3): axis h_i (axis frame's body axes), joint point s_b [m] (b's body axes);
  4 par (k, 8): mu_static, mu_dynamic, preload [N or N m], weights w_t of |P F|, |h.F|, |P T|, |h.T|
    (0: term omitted), 1.0 when b is rigid (else no moment terms).
wk[50] (system.compiled._friction_work): 0 mode (k,) int64, 1 direction s (k,), 2 switching values at
the last accepted step (k,), 3 unit accelerations (k, nf, 6), 4 unit multipliers (k, nc), 5 load
scratch (nf, 6), 6 zeros (nc), 7 S (k, k), 8 right-hand side (k,), 9 f (k,), 10 previous f (k,),
11 frozen term directions (k, 4, 3), 12 vd (nv), 13 lambda (nc) and 14 v (nf, 6) of the switching
functions, 15 [failed element + 1, iterations] int64, 16 new switching values (k,), 17 reaction
scratch (3, 3), 18 switching scratch (k,), 19 the stick rows' right-hand sides (k,), 20 held group (k,) int64 (the
group's id, its first sticking element, for its sticking and held members; -1: none), 21 the held
members' lock rows in the sticking ones' c_h (k, k) (row h, column a), 22 static capacities (k,),
23 generators (k, k), 24 orthonormal basis (k, k), 25 members (k,) int64, 26 subset indices (k,) int64,
27 the LU row swaps of S (k,) int64, 28 the slip elements' reactions (`reaction`) of lam and of each unit
solution (k, k + 1, 3, 3), 29 the stick rows of S (k, k).
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from .kkt_tree import _row_dot, lu_factor, lu_solve

V_TOL = 1e-9        # |xd| [m/s or rad/s] below which a joint counts as at rest at an event
STICK_TOL = 1e-10   # relative tolerance on the static friction limit
MAXIT = 50          # iterations of the coupled friction solve (directions of the normal-load terms)


@kernel(_nrt=False)
def reaction(fc, e, Jc, bi, bj, A, y, R):
    """Reaction of element e's joint on frame b from the multipliers y (nc): force R[0] [N] and moment
    R[1] [N m] about the joint point (ground axes); R[2]: scratch (body-axes torque)."""
    b = fc[2][e, 0]
    jr = fc[1][e]
    for c in range(3):
        R[0, c] = 0.0
        R[2, c] = 0.0
    for a in range(jr.shape[0]):
        r = jr[a]
        if r < 0:
            break
        if bj[r] == b:
            side = 1
        elif bi[r] == b:
            side = 0
        else:
            continue
        for c in range(3):
            R[0, c] -= Jc[r, side, c] * y[r]
            R[2, c] -= Jc[r, side, 3 + c] * y[r]
    s = fc[3][e, 1]
    p0 = A[b, 0, 0] * s[0] + A[b, 0, 1] * s[1] + A[b, 0, 2] * s[2]
    p1 = A[b, 1, 0] * s[0] + A[b, 1, 1] * s[1] + A[b, 1, 2] * s[2]
    p2 = A[b, 2, 0] * s[0] + A[b, 2, 1] * s[1] + A[b, 2, 2] * s[2]
    t0 = A[b, 0, 0] * R[2, 0] + A[b, 0, 1] * R[2, 1] + A[b, 0, 2] * R[2, 2]
    t1 = A[b, 1, 0] * R[2, 0] + A[b, 1, 1] * R[2, 1] + A[b, 1, 2] * R[2, 2]
    t2 = A[b, 2, 0] * R[2, 0] + A[b, 2, 1] * R[2, 1] + A[b, 2, 2] * R[2, 2]
    F0, F1, F2 = R[0, 0], R[0, 1], R[0, 2]
    R[1, 0] = t0 - (p1 * F2 - p2 * F1)
    R[1, 1] = t1 - (p2 * F0 - p0 * F2)
    R[1, 2] = t2 - (p0 * F1 - p1 * F0)


@kernel(_nrt=False)
def normal_load(fc, e, A, R, U, freeze, linear):
    """Normal load N of element e from its reaction R (`reaction`): preload + sum_t w_t |y_t|; with
    `freeze` the unit directions of the terms go to U[e]; with `linear` the terms are instead projected
    on the frozen directions (preload + sum_t w_t U[e, t] . y_t, the linearisation exact at U's state)
    and, as R is then a unit solution's reaction, the preload is left out."""
    par = fc[4][e]
    ba = fc[2][e, 1]
    hi = fc[3][e, 0]
    h0 = A[ba, 0, 0] * hi[0] + A[ba, 0, 1] * hi[1] + A[ba, 0, 2] * hi[2]
    h1 = A[ba, 1, 0] * hi[0] + A[ba, 1, 1] * hi[1] + A[ba, 1, 2] * hi[2]
    h2 = A[ba, 2, 0] * hi[0] + A[ba, 2, 1] * hi[1] + A[ba, 2, 2] * hi[2]
    N = 0.0 if linear else par[2]
    for t in range(4):
        w = par[3 + t]
        if w == 0.0 or (t >= 2 and par[7] == 0.0):
            if freeze:
                for c in range(3):
                    U[e, t, c] = 0.0
            continue
        X = R[0] if t < 2 else R[1]
        hx = h0 * X[0] + h1 * X[1] + h2 * X[2]
        if t % 2 == 0:   # perpendicular part
            y0, y1, y2 = X[0] - hx * h0, X[1] - hx * h1, X[2] - hx * h2
        else:            # axial part
            y0, y1, y2 = hx, 0.0, 0.0
        if linear:
            N += w * (U[e, t, 0] * y0 + U[e, t, 1] * y1 + U[e, t, 2] * y2)
            continue
        n = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
        N += w * n
        if freeze:
            inv = 1.0 / n if n > 0.0 else 0.0
            U[e, t, 0], U[e, t, 1], U[e, t, 2] = y0 * inv, y1 * inv, y2 * inv
    return N


@kernel(_nrt=False)
def _small_solve(fw, S, b, x):
    """x = S^-1 b (k x k) by `kkt_tree.lu_factor` (partial pivoting, the row swaps in fw[27]; S
    overwritten); False if singular."""
    k = b.shape[0]
    if not lu_factor(S, k, fw[27], 1e-14):
        return False
    for i in range(k):
        x[i] = b[i]
    lu_solve(S, fw[27], k, x)
    return True


@kernel(_nrt=False)
def couple(fc, fw, Jc, bi, bj, A, gamma, x6, lam):
    """The friction loads f of the elements with a mode (module docstring) from the frictionless solution
    x6 (nf, 6), lam (nc) and the unit solutions in fw; x6 and lam become the coupled solution, with
    lam[lock] = f. The stick rows and the slip elements' reactions of lam and of each unit solution are
    the same in every iteration (computed once: the reaction at the current loads is their combination,
    `reaction` being linear in the multipliers). Returns True, or False with fw[15][0] = element + 1 when
    the iteration does not converge in MAXIT solves or the k x k system is singular (fw[15][1]: solves
    done)."""
    mode, sdir, E6, EL = fw[0], fw[1], fw[3], fw[4]
    S, rhs, f, fp, U, info, Rc = fw[7], fw[8], fw[9], fw[10], fw[11], fw[15], fw[17]
    b0, RR, S0 = fw[19], fw[28], fw[29]
    lock = fc[0]
    k = mode.shape[0]
    for e in range(k):   # the iteration's constants
        f[e] = 0.0
        b0[e] = 0.0
        for m in range(k):
            S0[e, m] = 0.0
        if mode[e] == 2:
            r = lock[e]
            for m in range(k):
                if mode[m] != 0:
                    S0[e, m] = _row_dot(Jc, bi, bj, r, E6[m])
            b0[e] = gamma[r] - _row_dot(Jc, bi, bj, r, x6)
        elif mode[e] == 1:
            reaction(fc, e, Jc, bi, bj, A, lam, RR[e, 0])
            for m in range(k):
                if mode[m] != 0:
                    reaction(fc, e, Jc, bi, bj, A, EL[m], RR[e, 1 + m])
    done = False
    worst = 0
    for it in range(MAXIT):
        for e in range(k):
            for m in range(k):
                S[e, m] = S0[e, m]
            rhs[e] = b0[e]
            if mode[e] == 0:
                S[e, e] = 1.0
            elif mode[e] == 1:
                c = fc[4][e, 1] * sdir[e]
                for a in range(2):   # the reaction at the current loads: the terms' directions
                    for d in range(3):
                        x = RR[e, 0, a, d]
                        for m in range(k):
                            if mode[m] != 0:
                                x += f[m] * RR[e, 1 + m, a, d]
                        Rc[a, d] = x
                normal_load(fc, e, A, Rc, U, True, False)
                rhs[e] = c * (fc[4][e, 2] + normal_load(fc, e, A, RR[e, 0], U, False, True))
                S[e, e] = 1.0
                for m in range(k):
                    if mode[m] != 0:
                        S[e, m] -= c * normal_load(fc, e, A, RR[e, 1 + m], U, False, True)
        for e in range(k):
            fp[e] = f[e]
        if not _small_solve(fw, S, rhs, f):
            info[0], info[1] = 1, it + 1
            return False
        big, change, worst = 0.0, 0.0, 0
        for e in range(k):
            big = max(big, abs(f[e]))
            d = abs(f[e] - fp[e])
            if not d <= change:
                change, worst = d, e
        if change <= 1e-13 * (1.0 + big):
            done = True
            info[1] = it + 1
            break
    if not done:
        info[0], info[1] = worst + 1, MAXIT
        return False
    for m in range(k):
        if mode[m] == 0:
            continue
        for fr in range(x6.shape[0]):
            for c in range(6):
                x6[fr, c] += f[m] * E6[m, fr, c]
        for i in range(lam.shape[0]):
            lam[i] += f[m] * EL[m, i]
    for e in range(k):
        lam[lock[e]] = f[e] if mode[e] != 0 else 0.0
    return True


@kernel(_nrt=False)
def switching(fc, fw, Jc, bi, bj, A, lam, v6, g):
    """Switching function of each element (module docstring) into g, from the rows Jc, orientations A,
    multipliers lam (the coupled solve's) and velocities v6 (nf, 6) at one state."""
    mode, sdir, R, cap = fw[0], fw[1], fw[17], fw[22]
    lock = fc[0]
    k = mode.shape[0]
    for e in range(k):   # the static capacities mu_s N of the stuck elements (sticking, or held in a group)
        cap[e] = 0.0
        if mode[e] == 2 or (mode[e] == 0 and fw[20][e] >= 0):
            reaction(fc, e, Jc, bi, bj, A, lam, R)
            cap[e] = fc[4][e, 0] * normal_load(fc, e, A, R, fw[11], False, False)
    for e in range(k):
        if mode[e] == 1:
            g[e] = sdir[e] * _row_dot(Jc, bi, bj, lock[e], v6) + 0.5 * V_TOL
        elif mode[e] == 2 and fw[20][e] < 0:   # a lone stick
            g[e] = cap[e] - abs(lam[lock[e]]) + STICK_TOL * (1.0 + cap[e])
        elif mode[e] == 2 and fw[20][e] == e:   # the group's first sticking member: its value
            g[e] = group_margin(fw, lock, lam, e)
        elif mode[e] == 2:   # the others share it (the group's id is its first member: computed above)
            g[e] = g[fw[20][e]]
        else:
            g[e] = 1.0


@kernel(_nrt=False)
def group_margin(fw, lock, lam, e):
    """Switching function of the held group of sticking element e (fw[20] = its id): the group holds while
    its sticking locks' multipliers x = lam[lock[a]] (a in the group's n_a sticking elements) lie in the
    zonotope of its generators cap_a e_a (sticking a) and cap_h c_h (held h, c_h = fw[21][h]: its lock row
    in the sticking ones', on the null space of the other rows), the set of the loads the group's
    capacities can carry (every distribution |lambda_k| <= mu_s N_k of the least-load programme
    `friction_lcp.group_load`). The zonotope's facets are normal to n_a - 1 independent generators; with
    the unit normal n of each, H(n) = sum_i |n . gen_i| (its support), the value is
    min over facets of H(n) - |n . x| + n_g STICK_TOL (1 + H(n)) (n_g the group's joints): zero where
    the group's least load beta reaches 1 (just past it), for n_a = 1 the closed form C - |lambda_a| +
    n_g eps with C = cap_a + sum_h |c_h| cap_h. fw[22]: the capacities (`switching`); scratch fw[23]
    generators (k, k), fw[24] orthonormal basis (k, k), fw[25] members and fw[26] subset indices (k,)."""
    mode, grp, C, cap = fw[0], fw[20], fw[21], fw[22]
    G, Q, mem, idx = fw[23], fw[24], fw[25], fw[26]
    k = mode.shape[0]
    gid = grp[e]
    na = 0
    for a in range(k):   # the sticking members: the coordinates of x
        if mode[a] == 2 and grp[a] == gid:
            mem[na] = a
            na += 1
    ng = 0
    for i in range(k):   # the generators, rows of G (n_a columns)
        if grp[i] != gid or not (mode[i] == 2 or mode[i] == 0):
            continue
        for p in range(na):
            a = mem[p]
            G[ng, p] = (cap[i] if a == i else 0.0) if mode[i] == 2 else cap[i] * C[i, a]
        ng += 1
    r = na - 1   # generators spanning a facet
    best = np.inf
    for p in range(r):
        idx[p] = p
    while True:
        ok = True   # the unit normal n (into Q[r]) to the generators idx[:r]: Gram-Schmidt
        for p in range(r):
            nrm0 = 0.0
            for c in range(na):
                Q[p, c] = G[idx[p], c]
                nrm0 += Q[p, c] * Q[p, c]
            for m in range(p):
                d = 0.0
                for c in range(na):
                    d += Q[m, c] * Q[p, c]
                for c in range(na):
                    Q[p, c] -= d * Q[m, c]
            nrm = 0.0
            for c in range(na):
                nrm += Q[p, c] * Q[p, c]
            if not nrm > 1e-20 * nrm0 or nrm0 == 0.0:
                ok = False
                break
            nrm = np.sqrt(nrm)
            for c in range(na):
                Q[p, c] /= nrm
        if ok:
            big, jb = -1.0, 0
            for j in range(na):   # the unit vector least in their span, less its projection
                s = 1.0
                for m in range(r):
                    s -= Q[m, j] * Q[m, j]
                if s > big:
                    big, jb = s, j
            for c in range(na):
                Q[r, c] = 1.0 if c == jb else 0.0
            for m in range(r):
                d = Q[m, jb]
                for c in range(na):
                    Q[r, c] -= d * Q[m, c]
            nrm = 0.0
            for c in range(na):
                nrm += Q[r, c] * Q[r, c]
            nrm = np.sqrt(nrm)
            H, nx = 0.0, 0.0
            for c in range(na):
                Q[r, c] /= nrm
                nx += Q[r, c] * lam[lock[mem[c]]]
            for i in range(ng):
                d = 0.0
                for c in range(na):
                    d += Q[r, c] * G[i, c]
                H += abs(d)
            best = min(best, H - abs(nx) + ng * STICK_TOL * (1.0 + H))
        p = r - 1   # the next subset of r generators (lexicographic)
        while p >= 0 and idx[p] == ng - r + p:
            p -= 1
        if p < 0:
            break
        idx[p] += 1
        for m in range(p + 1, r):
            idx[m] = idx[m - 1] + 1
    return best


@kernel(_nrt=False)
def stick_rates(fc, fw, Jc, bi, bj, v6):
    """v6 (nf, 6) plus the combination sum f_m vd_m of the sticking elements' unit solutions (fw[3]) that
    brings their joint rates J_lock v to zero (the other rows' rates are kept: the unit solutions have a
    zero row right-hand side); False if their k x k system is singular."""
    mode, E6, S, rhs, f = fw[0], fw[3], fw[7], fw[8], fw[9]
    lock = fc[0]
    k = mode.shape[0]
    for e in range(k):
        for m in range(k):
            S[e, m] = 0.0
        rhs[e] = 0.0
        if mode[e] != 2:
            S[e, e] = 1.0
            continue
        for m in range(k):
            if mode[m] == 2:
                S[e, m] = _row_dot(Jc, bi, bj, lock[e], E6[m])
        rhs[e] = -_row_dot(Jc, bi, bj, lock[e], v6)
    if not _small_solve(fw, S, rhs, f):
        return False
    for m in range(k):
        if mode[m] == 2:
            for fr in range(v6.shape[0]):
                for c in range(6):
                    v6[fr, c] += f[m] * E6[m, fr, c]
    return True
