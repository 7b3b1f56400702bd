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
each other) sticks as one: the kernel enforces the sticking member's lock only, and its switching
function carries the group's shared capacity (`held_groups`: each held member's share in the ratio of
its joint rate to the sticking member's, wk[50][20], [21]; fastfriction). A held lock row that depends
on several sticking locks at once (a loop of several degrees of freedom stopped with more joints than
that) is not carried: the run raises NotCompiled and the analysis is redone on the event-driven
reference path.
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
        self.groups_at = []   # [(decision time [s], held group (k,), ratio (k,))] (fastfriction wk[50][20], [21])

    def decide(self, t, y):
        """Decide the modes at the state y = [q, v] at t [s] (an event or the start), write them to wk[50];
        the velocities of y are corrected in place so that the sticking joints are at rest."""
        from ..system.force_elements.friction_lcp import decide_all
        sys = self.sys
        nq = sys.nq
        decide_all(sys, float(t), np.array(y[:nq], dtype=float), np.array(y[nq:], dtype=float))
        held = [n for n in self.names if (sys.switched[n].at(t) or ("",))[0] == "held"]
        grp, ratio = np.full(len(self.names), -1, np.int64), np.zeros(len(self.names))
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
    the sticking element a whose lock row its own depends on, into grp[h], and the ratio c_h of the joint
    rates xd_h = c_h xd_a on the motions the joint and driver rows allow (their null space), into
    ratio[h]; with it the group's static capacity is mu_s N_a + sum_h |c_h| mu_s N_h, the reference's
    least-load distribution (`friction_lcp.group_load`) in closed form.  Returns the names of the held
    elements whose lock row depends on several sticking locks (not carried by the kernel)."""
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
    bad = []
    for h, m in enumerate(mode):
        if m != "held":
            continue
        gh = Nb.T @ J[_lock(sys, names[h])]
        scale = max(float(np.linalg.norm(gh)), 1e-300)
        c = np.linalg.lstsq(GA, gh, rcond=None)[0] if sticks else np.zeros(0)
        share = np.abs(c) * norms > tol * scale
        if not sticks or np.linalg.norm(GA @ c - gh) > tol * scale or np.count_nonzero(share) != 1:
            bad.append(names[h])
            continue
        j = int(np.flatnonzero(share)[0])
        grp[h], ratio[h] = sticks[j], float(c[j])
    return bad
