"""Stick/slip decisions of joint friction taken together (issue 14), see force_elements.friction.

At an event (and at the start) every friction element whose joint is at rest (|xd| <= V_TOL) is
decided in one step:

1. Joints carried by the loop.  The lock row L (x = x_stick) of such a joint is tested against the
   always-active rows J_a (joints, drivers): its constrained mobility
       rho = S / S0,   S = L N (N^T M N)^-1 N^T L^T,   S0 = L M^-1 L^T,   N = null(J_a)
   (the inverse effective mass of the joint coordinate with and without the other constraints, in the
   kinetic-energy metric; 0 <= rho <= 1) is ~0 when the lock row is dependent on J_a, i.e. when the
   other constraints and drivers decide the joint's rate at that instant (a dead centre, a rocker's
   extreme, a toggle, every joint of a 0-DOF driven mechanism).  Such a joint is never locked: it goes
   on slipping, in the direction of its (kinematically determined) acceleration xdd = L vd - gamma_L,
   i.e. the friction force follows the direction of motion after the reversal.
2. The other joints at rest are decided together, as the mixed complementarity problem of Coulomb
   friction at the acceleration level (a box-LCP in the friction forces when N is frozen, the
   formulation of Chrono's and Drake's stick/slip): every assignment of {stick, slip +, slip -} is
   solved with the coupled KKT system (`friction_kkt`: N follows the reactions) and checked -
   a slipping joint must accelerate in its direction (s xdd >= 0), a sticking set must hold within
   the static capacities.  Assignments are tried with the most joints sticking first, so static
   friction holds whenever it can (mu_static > mu_dynamic leaves stick and slip both consistent);
   among as many sticks, the slips in the directions of the joints' frictionless accelerations
   first.  An assignment that makes a joint slip which the stuck ones lock kinematically (its
   constrained mobility with their lock rows added is ~0: a loop stuck at one joint cannot slip at
   another) is not a solution and is not tried.
   Sticking joints whose lock rows depend on each other (a 1-DOF loop stopped with friction in every
   pin: one lock stops them all) are "held": only an independent subset of the locks is active, and
   the group's capacity is the sum of its members': the static friction needed is distributed over the
   group with the least max_k |lambda_k| / (mu_s N_k) (a small linear programme, `group_load`), so the
   group breaks away when no distribution within the capacities exists.
"""
from __future__ import annotations

import itertools

import numpy as np

from ..._blas import scipy_linalg
RHO_TOL = 1e-10     # constrained mobility below which a lock row counts as dependent on the others
MAX_JOINT = 7       # joints decided by enumeration together (3^7 assignments); beyond: one by one


def null_basis(J, nv):
    """Orthonormal basis of the null space of J (nv, k)."""
    sla = scipy_linalg()   # imported on first use: ~0.3 s at start-up, needed only with friction
    return sla.null_space(J, rcond=1e-11) if J.shape[0] else np.eye(nv)


def mobility(M, N, L):
    """Constrained over unconstrained inverse effective mass of the coordinate with row L (0..1)."""
    S0 = float(L @ np.linalg.solve(M, L))
    if S0 <= 0 or N.shape[1] == 0:
        return 0.0
    y = N.T @ L
    S = float(y @ np.linalg.solve(N.T @ M @ N, y))
    return S / S0


def independent_locks(J_active, locks, J, tol=1e-9):
    """Subset of lock rows `locks` that are independent of J_active and of each other (greedy, in order)."""
    keep = []
    base = J_active
    for r in locks:
        trial = np.vstack([base, J[r]])
        if np.linalg.matrix_rank(trial, tol=tol * max(1.0, np.abs(trial).max())) > base.shape[0]:
            keep.append(r)
            base = trial
    return keep


def group_load(G, r, cap):
    """Least beta with G lam = r, |lam_k| <= beta cap_k (k stuck joints of a held group): the LP
    min beta over (lam, beta).  Returns (beta, lam); beta = inf when G lam = r has no solution."""
    from scipy.optimize import linprog
    k = G.shape[1]
    c = np.zeros(k + 1)
    c[-1] = 1.0
    A_ub = np.zeros((2 * k, k + 1))
    A_ub[:k, :k], A_ub[k:, :k] = np.eye(k), -np.eye(k)
    A_ub[:k, -1] = A_ub[k:, -1] = -np.asarray(cap, float)
    A_eq = np.hstack([G, np.zeros((G.shape[0], 1))])
    out = linprog(c, A_ub=A_ub, b_ub=np.zeros(2 * k), A_eq=A_eq, b_eq=r, bounds=[(None, None)] * k + [(0, None)],
                  method="highs")
    if out.status != 0:
        return np.inf, np.zeros(k)
    return float(out.x[-1]), out.x[:k]


def assignments(n):
    """All {stick, +1, -1} assignments of n joints, most sticks first."""
    combos = list(itertools.product((0.0, 1.0, -1.0), repeat=n))
    return sorted(combos, key=lambda c: sum(1 for x in c if x != 0.0))


# ----------------------------------------------------------------------------- the decision
STUCK = ("stick", "held")


def _lock(sys, name):
    return int(sys.owner_rows[name][0])


def _joint_acc(J, gamma, vd, r):
    """Second derivative of the joint coordinate of lock row r: L vd - gamma_L."""
    return float(J[r] @ vd - gamma[r])


def decide_all(sys, t, q, v):
    """Modes of every friction element at an event or at the start (see the module docstring)."""
    from ..metrics import kinetic_metric
    from ..equations import constraint_terms
    from ..frames import body_frames
    from .friction import V_TOL, _base_rows, _coordinate, _rate, _timed
    key = (float(t), np.asarray(q).tobytes(), np.asarray(v).tobytes())
    if sys.run_state.get("friction_decided") == key:
        return
    sys.run_state["friction_decided"] = key
    fr = _timed(body_frames(sys, q, v))
    elems = {n: sys.model.forces[n] for n in sys.switched}
    rest, prev = [], {}
    for n, st in sys.switched.items():
        m = st.at(t)
        m = None if m is None or m[0] == "free" else m
        xd = float(_rate(sys, fr, elems[n])[0])
        if m is not None and m[0] == "slip" and m[1] * xd > V_TOL:
            continue                                   # slipping on
        if abs(xd) > V_TOL:
            st.record(t, "slip", np.sign(xd))
            continue
        rest.append(n)
        prev[n] = m
    if not rest:
        return
    for n in rest:                                     # undecided: frictionless meanwhile
        sys.switched[n].record(t, "free")
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    base = _base_rows(sys, q, v, t)
    Nb = null_basis(J[base], sys.nv)
    Mk = kinetic_metric(sys)
    carried = [n for n in rest if mobility(Mk, Nb, J[_lock(sys, n)]) < RHO_TOL]
    if carried:
        vd = _solve(sys, q, v, t, base)[0]
        for n in carried:
            a = _joint_acc(J, gamma, vd, _lock(sys, n))
            if abs(a) > 1e-12:
                s = float(np.sign(a))
            elif prev[n] is not None and prev[n][0] == "slip":
                s = -prev[n][1]                        # an odd-order zero of the rate: a reversal
            else:
                s = 1.0
            sys.switched[n].record(t, "slip", s)
    others = [n for n in rest if n not in carried]
    if not others:
        return
    target = {n: float(_coordinate(sys, fr, elems[n])[0]) for n in others}
    groups = [others] if len(others) <= MAX_JOINT else [[n] for n in others]
    locked = {}
    for group in groups:
        best, best_viol = None, np.inf
        for combo in _ordered(sys, q, v, t, base, J, gamma, group):
            if _locked_slip(sys, Mk, J, base, group, combo, t, locked):
                continue
            _apply(sys, t, J, base, group, combo, target)
            try:
                viol = _violation(sys, q, v, t, base, J, gamma, group, combo)
            except Exception:   # noqa: BLE001  (a singular trial: not a solution)
                viol = np.inf
            if viol <= 0.0:
                best = combo
                break
            if viol < best_viol:
                best, best_viol = combo, viol
        _apply(sys, t, J, base, group, best if best is not None else (0.0,) * len(group), target)


def _ordered(sys, q, v, t, base, J, gamma, group):
    """`assignments` of the group, most sticks first as there; among those with as many sticks, the slips
    in the directions of the joints' accelerations with the group frictionless (the likely solution) first."""
    vd = _solve(sys, q, v, t, base)[0]
    natural = [float(np.sign(_joint_acc(J, gamma, vd, _lock(sys, n)))) for n in group]
    return sorted(assignments(len(group)), key=lambda c: (sum(1 for x in c if x != 0.0),
                                                         sum(1 for x, s in zip(c, natural) if x != 0.0 and x != s)))


def _locked_slip(sys, Mk, J, base, group, combo, t, cache):
    """Whether a joint that `combo` makes slip is kinematically locked by the stuck ones (its constrained
    mobility with their lock rows added is ~0): it cannot move, so it is not slipping (Coulomb's slip needs
    a relative motion); such assignments are not solutions (a loop stuck at one joint is stuck at all)."""
    stuck = tuple(i for i, x in enumerate(combo) if x == 0.0)
    if not stuck or len(stuck) == len(combo):
        return False
    if stuck not in cache:
        others = [n for n, st in sys.switched.items() if n not in group and st.at(t) is not None
                  and st.at(t)[0] in STUCK]
        rows = np.concatenate([base, [_lock(sys, n) for n in others], [_lock(sys, group[i]) for i in stuck]])
        Nb = null_basis(J[rows.astype(int)], sys.nv)
        cache[stuck] = [i for i in range(len(combo)) if i not in stuck
                        and mobility(Mk, Nb, J[_lock(sys, group[i])]) < RHO_TOL]
    return bool(cache[stuck])


def _apply(sys, t, J, base, group, combo, target):
    """Record the trial modes of `group`: slips, and stuck joints as stick (independent lock) or held."""
    stuck = [n for n, s in zip(group, combo) if s == 0.0]
    others_stuck = [n for n, st in sys.switched.items() if n not in group and st.at(t) is not None
                    and st.at(t)[0] == "stick"]
    active = J[np.concatenate([base, [_lock(sys, n) for n in others_stuck]]).astype(int)]
    keep = set(independent_locks(active, [_lock(sys, n) for n in stuck], J))
    for n, s in zip(group, combo):
        st = sys.switched[n]
        if s != 0.0:
            st.record(t, "slip", s)
        else:
            st.record(t, "stick" if _lock(sys, n) in keep else "held", 0.0, target[n])


def _solve(sys, q, v, t, base):
    from ..dynamics import accelerations
    return accelerations(sys, q, v, t, base, sys.run_state.get("state_factory"))


def _violation(sys, q, v, t, base, J, gamma, group, combo):
    """0 when the trial modes are consistent, else a positive measure of the worst inconsistency."""
    from ..frames import body_frames
    vd, lam = _solve(sys, q, v, t, base)
    viol = 0.0
    for n, s in zip(group, combo):
        if s != 0.0:
            a = _joint_acc(J, gamma, vd, _lock(sys, n))
            viol = max(viol, -s * a / (1.0 + abs(a)) - 1e-12)
    if any(s == 0.0 for s in combo):
        fr = body_frames(sys, q, v)
        fr.q, fr.v, fr.lambda_ = q, v, lam
        for n, s in zip(group, combo):
            if s == 0.0:
                margin, eps = stuck_margin(sys, fr, J, lam, sys.model.forces[n], t)
                viol = max(viol, (eps / 2 - margin) / (1.0 + abs(margin)))
    return viol


def stuck_margin(sys, fr, J, lam, elem, t):
    """(margin, eps) of a stuck element: mu_s N - |lambda_f| + eps for a lone stick, (1 - beta) mu_s N + eps
    in a group with held members (see `group_load`)."""
    from .friction import STICK_TOL, _stick_margin
    from .friction_kkt import load_maps, normal_load
    stuck = [n for n, st in sys.switched.items() if st.at(t) is not None and st.at(t)[0] in STUCK]
    held = [n for n in stuck if sys.switched[n].at(t)[0] == "held"]
    if not held:
        margin, _, eps = _stick_margin(sys, fr, J, lam, elem)
        return margin, eps
    cache = fr.__dict__.setdefault("_friction_group", {})
    if t not in cache:
        caps = []
        for n in stuck:
            e = sys.model.forces[n]
            jr, maps = load_maps(sys, fr, J, e)
            caps.append(e.mu_static * normal_load(e, maps, lam[jr]))
        from .friction import _base_rows
        Nb = null_basis(J[_base_rows(sys, fr.q, fr.v, t)], sys.nv)
        active = [_lock(sys, n) for n in stuck if sys.switched[n].at(t)[0] == "stick"]
        G = Nb.T @ J[[_lock(sys, n) for n in stuck]].T
        r = Nb.T @ (J[active].T @ lam[active])
        beta, dist = group_load(G, r, np.maximum(caps, 1e-300))
        cache[t] = (beta, dict(zip(stuck, caps)), dict(zip(stuck, dist)))
    beta, caps, _ = cache[t]
    cap = caps[elem.name]
    eps = STICK_TOL * (1 + cap)
    return (1.0 - min(beta, 1e6)) * cap + eps, eps
