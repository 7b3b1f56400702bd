"""Joint friction on the compiled DOP853 (issue 29): the stick/slip decisions between kernel calls.

The kernel (`fastdop.run` with `solvers.fastfriction`) integrates with the modes in wk[50] and stops
at the first zero of a switching function, located on the step's dense output (status FRICTION_EVENT,
the state there). `FrictionModes.decide` then takes the decisions of every joint at rest together, as
the reference does (`force_elements.friction_lcp.decide_all`: joints carried by the loop slip on in
the direction of their kinematic acceleration; the others by the complementarity conditions of
Coulomb friction), records them in the System's mode histories (sys.switched, what
`res.friction_events` and the reference evaluators read) and writes them into wk[50]; the run restarts
there. Outputs and dense output after the run use the modes in force at each time (`groups`,
`set_modes`). A "held" group (a loop stopped with friction in several joints, whose lock rows depend on
each other) sticks as one: the kernel enforces the sticking members' locks only, and their switching
function carries the group's shared static capacity (`held_groups`: each held member's lock row in the
sticking ones', wk[50][20], [21]; `fastfriction.group_margin`), for a loop of any number of degrees of
freedom. A held lock row outside the sticking ones' span (not expected: `decide_all` keeps an
independent subset) is not carried: the run raises NotCompiled and the analysis is redone on the
event-driven reference path.
"""
from __future__ import annotations

import numpy as np

from ..errors import SolverError
from ..system.compiled import NotCompiled

CODES = {"slip": 1, "stick": 2}   # wk[50][0]; anything else (undecided) carries no friction load


class FrictionModes:
    """The stick/slip modes of one compiled run: the System's histories and the kernel's mode arrays."""

    def __init__(self, sys, cm, work):
        self.sys, self.cm, self.work = sys, cm, work
        self.names = list(sys.switched)
        self.fw = work.arrays()[50]
        self.groups_at = []   # [(decision time [s], held group (k,), ratio (k, k))] (fastfriction wk[50][20], [21])

    def decide(self, t, y):
        """Decide the modes at the state y = [q, v] at t [s] (an event or the start), write them to wk[50];
        the velocities of y are corrected in place so that the sticking joints are at rest."""
        from ..system.force_elements.friction_lcp import decide_all
        sys = self.sys
        nq = sys.nq
        decide_all(sys, float(t), np.array(y[:nq], dtype=float), np.array(y[nq:], dtype=float))
        held = [n for n in self.names if (sys.switched[n].at(t) or ("",))[0] == "held"]
        grp, ratio = np.full(len(self.names), -1, np.int64), np.zeros((len(self.names),) * 2)
        if held:
            unsupported = held_groups(sys, self.names, float(t), y, grp, ratio)
            if unsupported:
                for st in sys.switched.values():   # the reference starts afresh
                    st.times.clear()
                    st.modes.clear()
                sys.run_state.pop("friction_decided", None)
                sys.derived["friction not compiled"] = msg = (
                    f"joint friction: {', '.join(map(repr, unsupported))} stopped together with other joints of a "
                    f"loop at t = {t:.9g} s, each lock depending on several sticking ones (a held group of more "
                    "than one degree of freedom, whose shared static capacity the compiled path does not carry): "
                    "the event-driven reference DOP853 runs it")
                raise NotCompiled(msg)
        self.groups_at = [g for g in self.groups_at if g[0] < t] + [(float(t), grp, ratio)]
        self.set_modes(t)
        if np.any(self.fw[0] == 2):   # sticking joints start exactly at rest (no creep at the event's V_TOL)
            from . import fastdyn
            if fastdyn.stick_velocities(self.cm.arrays(), self.work.arrays(), float(t), y) != fastdyn.OK:
                raise SolverError("singular equations of motion at a stick decision of joint friction", time=float(t))

    def set_modes(self, t):
        """Write the modes in force at t [s] into wk[50]."""
        mode, sdir = self.fw[0], self.fw[1]
        for e, n in enumerate(self.names):
            m = self.sys.switched[n].at(t)
            mode[e] = CODES.get(m[0], 0) if m is not None else 0
            sdir[e] = m[1] if m is not None else 0.0
        grp, ratio = self.fw[20], self.fw[21]
        grp[:], ratio[:] = -1, 0.0
        for t_d, g, c in self.groups_at:   # the held groups of the last decision at or before t
            if t_d <= t:
                grp[:], ratio[:] = g, c

    def groups(self, times):
        """Index arrays of the times [s] grouped by the modes in force (each group's modes set before use:
        iterate over the result)."""
        keys = [tuple(self.sys.switched[n].at(float(t)) or ("",) for n in self.names) for t in times]
        for key in dict.fromkeys(keys):
            idx = np.array([i for i, k in enumerate(keys) if k == key], dtype=np.int64)
            self.set_modes(float(times[idx[0]]))
            yield idx

    def failure(self, t, y):
        """The SolverError of a coupled friction solve that did not converge at t [s]."""
        info = self.fw[15]
        name = self.names[int(info[0]) - 1] if 0 < int(info[0]) <= len(self.names) else self.names[0]
        return SolverError(f"the coupled joint-friction solve does not converge (friction {name!r}: normal load "
                           f"and friction force iterated {int(info[1])} times)", time=float(t),
                           joints=[self.sys.model.forces[name].joint.name])


def held_groups(sys, names, t, y, grp, ratio, tol=1e-8):
    """The held groups decided at t [s], state y = [q, v]: for each held element h (index into `names`),
    its lock row in the sticking elements' on the motions the joint and driver rows allow (their null
    space N): N^T J_h^T = sum_a c_ha N^T J_a^T, c_ha into ratio[h, a] (for one sticking a, the ratio of the
    joint rates xd_h = c_ha xd_a); sticking and held elements connected through nonzero c_ha form a
    group, its id (its first sticking element) into grp of each member. With them the kernel carries the
    group's shared static capacity (`fastfriction.group_margin`, the reference's least-load distribution
    `friction_lcp.group_load` in closed form). Returns the names of the held elements whose lock row is
    not in the sticking ones' span (not carried by the kernel)."""
    from ..system.equations import constraint_terms
    from ..system.force_elements.friction import _base_rows
    from ..system.force_elements.friction_lcp import _lock, null_basis
    nq = sys.nq
    q, v = np.array(y[:nq], dtype=float), np.array(y[nq:], dtype=float)
    J = np.asarray(constraint_terms(sys, q, v, t)[1])
    Nb = null_basis(J[_base_rows(sys, q, v, t)], sys.nv)
    mode = [(sys.switched[n].at(t) or ("",))[0] for n in names]
    sticks = [e for e, m in enumerate(mode) if m == "stick"]
    GA = Nb.T @ J[[_lock(sys, names[e]) for e in sticks]].T if sticks else np.zeros((Nb.shape[1], 0))
    norms = np.linalg.norm(GA, axis=0)
    parent = {a: a for a in sticks}   # union-find over the sticking elements

    def root(a):
        while parent[a] != a:
            a = parent[a]
        return a
    bad, shares = [], {}
    for h, m in enumerate(mode):
        if m != "held":
            continue
        gh = Nb.T @ J[_lock(sys, names[h])]
        scale = max(float(np.linalg.norm(gh)), 1e-300)
        c = np.linalg.lstsq(GA, gh, rcond=None)[0] if sticks else np.zeros(0)
        share = np.flatnonzero(np.abs(c) * norms > tol * scale)
        if not sticks or np.linalg.norm(GA @ c - gh) > tol * scale or not len(share):
            bad.append(names[h])
            continue
        shares[h] = [(sticks[j], float(c[j])) for j in share]
        for a, _ in shares[h][1:]:
            parent[root(a)] = root(shares[h][0][0])
    ids = {}
    for h, sh in shares.items():
        gid = ids.setdefault(root(sh[0][0]), min(a for a in sticks if root(a) == root(sh[0][0])))
        grp[h] = gid
        for a, c in sh:
            ratio[h, a] = c
            grp[a] = gid
    return bad
