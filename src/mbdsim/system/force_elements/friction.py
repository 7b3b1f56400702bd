"""Coulomb joint friction with event-driven stick/slip switching (translational and revolute joints).

Model
-----
x is the joint coordinate (slide [m] of body_j along the axis h, or angle [rad] of body_j about it)
and xd its rate.  Friction is a generalized force F_f on x (force [N] along h / torque [N m] about h
on body_j, the opposite on body_i), written as the multiplier lambda_f of the element's LOCK ROW
L(q) = x - x_stick, which is always present in the System's row layout (last rows,
System.lock_rows): its load on the bodies is -dx/dv^T lambda_f, so F_f = -lambda_f and
`res.friction_force(name)` = -lambda_f in both modes.

Friction capacity mu N, with N from the joint's reaction (multipliers of the joint's rows) on body_j
at the joint point: force F, moment T, split along / perpendicular to h:
    translational [N]:  N = preload + |F_perp| + |T_perp| / effective_length + |T.h| / reaction_arm
    revolute [N m]:     N = preload + pin_radius |F_perp| + friction_arm |F.h| + pin_radius |T_perp| / bending_arm
(a term whose parameter is None is left out).

Modes (history of (t, mode, direction s, x_stick) per element, kept on the System, so the state at
any time - dense output, Result.at - uses the mode in force then):
- slip, direction s = +-1: lambda_f = mu_dynamic N(lambda_) s, the lock row is inactive.  N depends on
  lambda_, which depends on the friction load: `friction_kkt.friction_kkt` (called by
  system.dynamics.accelerations) solves the coupled KKT system (N is homogeneous of degree one in
  lambda_: a rank-k update of one factorisation, iterated on the reaction directions).
  Switching function s xd + V_TOL/2: its zero (the joint comes to rest) is located as an event.
- stick: the lock row is active (position level, so the joint cannot creep: coordinate projection
  holds x = x_stick to the Newton tolerance); the friction force is its multiplier.  Switching
  function mu_static N - |lambda_f| + eps, eps = STICK_TOL (1 + mu_static N): its zero releases the
  joint.  held: stuck, but the lock row depends on the other active locks (a loop stopped with friction
  in several joints): inactive, the group's capacity is shared (friction_lcp.stuck_margin).
- at every event (and at the start) all joints at rest (|xd| <= V_TOL) are decided together
  (`friction_lcp.decide_all`): a joint whose lock row is dependent on the joint and driver rows is
  carried by the loop through zero velocity (slips on in the direction of its kinematic acceleration);
  the others by the complementarity conditions of Coulomb friction, solved over all their
  stick/slip assignments with the coupled normal loads.
The "dop853"/"rk45"/"radau"/"bdf" methods of mb.simulate run this logic on the reference path
(through the EventTracker hooks on_start / on_event / switch); "auto" and "dop853" run it on the
compiled core (solvers.fastfriction, solvers.friction_run: the same decisions, docs/theory.md 12c);
other analyses raise a ModelError naming the element.  One friction element per joint; a joint driven by a motion cannot have friction.  The
joint's `reaction_force` does not include the friction force (`res.friction_force(name)` gives it;
`res.friction_events(name)` the stick/slip history).  Energy: `dissipation` = lambda_f xd >= 0 [W].
"""
from __future__ import annotations

import bisect

import numpy as np

from ...model.friction_path import JointFriction
from ..constraints.base import RowSpec
from . import register
from .friction_kkt import load_maps, normal_load
from .friction_lcp import decide_all, stuck_margin

from ...solvers.fastfriction import STICK_TOL, V_TOL   # noqa: F401  (one definition, shared with the kernels)


class StickSlip:
    """Mode history of one friction element; also the target function of its lock row (x_stick)."""

    def __init__(self, name):
        self.name = name
        self.times, self.modes = [], []     # modes: (mode, direction, x_stick)

    def at(self, t):
        """(mode, direction, x_stick) in force at time t, or None before the first decision."""
        k = bisect.bisect_right(self.times, t) - 1
        return self.modes[k] if k >= 0 else (self.modes[0] if self.modes else None)

    def record(self, t, mode, direction=0.0, target=0.0):
        """Mode from time t on (replacing a decision at the same time); a repeat of the mode in force
        (same mode and direction) is not recorded again, so each transition appears once."""
        while self.times and self.times[-1] >= t:
            del self.times[-1], self.modes[-1]
        if self.modes and self.modes[-1][:2] == (mode, float(direction)):
            return
        self.times.append(float(t))
        self.modes.append((mode, float(direction), float(target)))

    # TimeFunction interface of the lock row: x_stick, constant within a stick period
    def value(self, t):
        m = self.at(t)
        return m[2] if m else 0.0

    @staticmethod
    def d1(t):
        return 0.0

    @staticmethod
    def d2(t):
        return 0.0


def lock_specs(model, geoms):
    """Lock RowSpecs (one per friction element; rows go last in the layout) and their StickSlip states."""
    specs = []
    for el in model.forces.values():
        if isinstance(el, JointFriction):
            driven = [m.name for m in model.motions.values() if m.joint is el.joint]
            if driven:
                from ...errors import ModelError
                raise ModelError(f"friction '{el.name}'", "joint", f"joint {el.joint.name!r} is driven by motion "
                                 f"{driven[0]!r}: friction on a driven joint is not supported")
            g = geoms[el.joint.name]
            st = StickSlip(el.name)
            if el.joint.kind == "revolute":
                s = RowSpec("angle", (g.f_i, g.g_i, g.f_j), el.name, st)
            else:
                s = RowSpec("slide", (g.h_i, g.s_i, g.s_j), el.name, st)
            s.frames = (g.bi, g.bj)
            specs.append(s)
    return specs


def locks_at(sys, t):
    """Row indices of the lock rows active (stick) at time t."""
    out = []
    for name, st in sys.switched.items():
        m = st.at(t)
        if m is not None and m[0] == "stick":
            out.append(int(sys.owner_rows[name][0]))
    return out


# ----------------------------------------------------------------------------- evaluator
def _rate(sys, fr, elem):
    """Joint coordinate rate xd (N,) of time-axis frames."""
    from ..measures import joint_coordinate
    _, angd, _, sld = joint_coordinate(sys, fr, elem.joint)
    return angd if elem.joint.kind == "revolute" else sld


def _coordinate(sys, fr, elem):
    from ..measures import joint_coordinate
    ang, _, sl, _ = joint_coordinate(sys, fr, elem.joint)
    return ang if elem.joint.kind == "revolute" else sl


def _timed(fr):
    from ..frames import Frames
    if fr.r.ndim == 3:
        return fr
    return Frames(fr.r[None], fr.A[None], fr.rd[None], fr.w[None])


def _stick_margin(sys, fr, J, lam, elem):
    """mu_static N - |lambda_f| + eps and lambda_f at one state (full J and lambda_)."""
    jr, maps = load_maps(sys, fr, J, elem)
    N = normal_load(elem, maps, lam[jr])
    lf = lam[sys.owner_rows[elem.name][0]]
    return elem.mu_static * N - abs(lf) + STICK_TOL * (1 + elem.mu_static * N), lf, STICK_TOL * (1 + elem.mu_static * N)


def _multipliers(sys, fr, elem, t):
    """lambda_ (N, nc) at the states fr.q, fr.v (N, ...) and times t, in the modes then in force."""
    from ..dynamics import accelerations
    q, v = getattr(fr, "q", None), getattr(fr, "v", None)
    t = getattr(fr, "t", None) if t is None else t
    if q is None or v is None or t is None:
        raise ValueError(f"friction '{elem.name}': dissipation needs the multipliers or the states (q, v, t)")
    q, v, t = np.atleast_2d(q), np.atleast_2d(v), np.broadcast_to(np.asarray(t, dtype=float), (len(q),))
    rows, sf = _base_rows(sys, q[0], v[0], t[0]), sys.run_state.get("state_factory")
    return np.array([accelerations(sys, q[n], v[n], t[n], rows, sf)[1] for n in range(len(q))])


def _base_rows(sys, q, v, t):
    """Independent rows among the always-active ones (as assembly picks them), cached on the System."""
    rows = sys.derived.get("friction_base_rows")
    if rows is None:
        from ..rows import independent_rows
        from ..equations import constraint_terms
        J = constraint_terms(sys, q, v, t)[1]
        rows = sys.derived["friction_base_rows"] = sys.fixed_rows[independent_rows(J[sys.fixed_rows])]
    return rows


@register(JointFriction)
class FrictionEval:
    """Evaluator of JointFriction (its load enters through `friction_kkt`, not `generalized`)."""

    needs_lambda = True       # switching functions use the multipliers (EventTracker attaches them)
    restart_positive = True   # after an event every switching function starts positive

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        if not sys.switched[elem.name].times:   # no stick/slip logic runs in this analysis
            from ...errors import ModelError
            raise ModelError(f"friction '{elem.name}'", "method", "joint friction is modelled by the "
                             "event-driven index-1 methods of mb.simulate (method='dop853', 'rk45', 'radau' "
                             "or 'bdf'); this analysis cannot include it")
        return np.zeros(sys.nv)

    @staticmethod
    def switch(sys, fr, elem, t):
        """slip: s xd [m/s, rad/s]; stick: mu_static N - |lambda_f| + eps [N, N m]."""
        m = sys.switched[elem.name].at(t)
        if m is None:
            return np.ones(1)
        if m[0] == "slip":   # offset V_TOL/2: the event is met with the joint at rest, never just before
            return np.array([m[1] * float(_rate(sys, _timed(fr), elem)[0]) + 0.5 * V_TOL])
        if m[0] == "free":
            return np.ones(1)
        from ..equations import constraint_terms
        J = constraint_terms(sys, fr.q, fr.v, t)[1]
        return np.array([stuck_margin(sys, fr, J, fr.lambda_, elem, t)[0]])

    @staticmethod
    def on_start(sys, elem, t, q, v):
        decide_all(sys, t, q, v)

    @staticmethod
    def on_event(sys, elem, t, q, v):
        decide_all(sys, t, q, v)

    @staticmethod
    def dissipation(sys, fr, elem, t=None):
        """Friction power lambda_f xd >= 0 [W] (N,) of time-axis frames carrying the multipliers
        `lambda_` (N, nc), or the states `q`, `v` (N, nq/nv) and times `t` to solve for them."""
        lam = getattr(fr, "lambda_", None)
        if lam is None:
            lam = _multipliers(sys, fr, elem, t)
        lam = np.atleast_2d(lam)
        return lam[:, sys.owner_rows[elem.name][0]] * _rate(sys, _timed(fr), elem)


def _element(res, name):
    from ...errors import ModelError
    el = res.system.model.forces.get(name if isinstance(name, str) else getattr(name, "name", None))
    if not isinstance(el, JointFriction) or el.name not in res.system.switched:
        raise ModelError(f"friction {name!r}", "name", "is not a joint friction element of the analysed model")
    return el


def friction_events(res, name):
    """[(time [s], mode, direction)] of the element's stick/slip history within the result's span."""
    st = res.system.switched[_element(res, name).name]
    t1 = res.time[-1] if len(res.time) else -np.inf
    out = []
    for t, (m, d, _) in zip(st.times, st.modes):
        m = "stick" if m == "held" else m
        if t <= t1 and m != "free" and (not out or out[-1][1:] != (m, d)):
            out.append((t, m, d))
    return out


def friction_force(res, name):
    """Friction force [N] / torque [N m] on body_j along / about the joint axis, (N,): -lambda_f."""
    el = _element(res, name)
    if res.lambda_ is None:
        raise ValueError("friction forces are not available: this result holds no multipliers")
    return -res.lambda_[:, res.system.owner_rows[el.name][0]]
