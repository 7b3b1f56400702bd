"""Point forces, torques and translational spring-dampers."""
from __future__ import annotations

import numpy as np

from ...errors import ModelError
from ...model.forces import Force, SpringDamper, Torque
from ..frames import cross, point_state
from ..guard import call_vector
from . import register


def add_point_force(sys, fr, Q, fid, s_ground, F):
    """Add a ground-axes force F [N] applied at offset s_ground [m] from the CM of frame fid into Q."""
    if fid == 0:
        return
    a = sys.frame_v_adr[fid]
    Q[a:a + 3] += F
    if sys.frame_rigid[fid]:
        Q[a + 3:a + 6] += cross(s_ground, F).dot(fr.A[fid])   # A^T (s x F) (.dot: a third of @'s cost on 3-vectors)


def add_torque(sys, fr, Q, fid, T):
    """Add a ground-axes torque T [N m] on frame fid into Q."""
    if fid == 0 or not sys.frame_rigid[fid]:
        return
    a = sys.frame_v_adr[fid]
    Q[a + 3:a + 6] += T.dot(fr.A[fid])   # A^T T


def _vector(elem, value, t, state, fr, sys, what):
    if callable(value):
        v = call_vector(value, t, state, f"{what} '{elem.name}'", what)
    else:
        v = np.asarray(value, dtype=float).reshape(-1)
    if elem.frame is not None:
        from ..measures import locate
        fid, _, R_BM = locate(sys, elem.frame)
        v = fr.A[fid].dot(R_BM.dot(v))
    return v


@register(Force)
class ForceEval:
    @staticmethod
    def accumulate(sys, fr, elem, t, state, Q, power=False):
        """Add the force's generalized load (single state) into Q (nv,); returns its power [W] (F . v of
        the point) with power=True, else 0."""
        fid = sys.fid[elem.body]
        F = _vector(elem, elem.force, t, state, fr, sys, "force")
        add_point_force(sys, fr, Q, fid, fr.A[fid].dot(elem.s_B), F)
        return float(F.dot(point_state(fr, fid, elem.s_B, False)[1])) if power else 0.0

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        Q = np.zeros(sys.nv)
        ForceEval.accumulate(sys, fr, elem, t, state, Q)
        return Q


@register(Torque)
class TorqueEval:
    @staticmethod
    def accumulate(sys, fr, elem, t, state, Q, power=False):
        """Add the torque's generalized load (single state) into Q (nv,); returns its power [W] (T . w,
        ground axes) with power=True, else 0."""
        fid = sys.fid[elem.body]
        T = _vector(elem, elem.torque, t, state, fr, sys, "torque")
        add_torque(sys, fr, Q, fid, T)
        return float(T.dot(fr.w[fid])) if power and sys.frame_rigid[fid] else 0.0

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        Q = np.zeros(sys.nv)
        TorqueEval.accumulate(sys, fr, elem, t, state, Q)
        return Q


def spring_state(sys, fr, elem):
    """Length L [m], rate dL/dt [m/s], unit vector i->j, ground points and offsets (single state)."""
    fi, fj = sys.fid[elem.marker_i.body], sys.fid[elem.marker_j.body]
    pi, vi, _ = point_state(fr, fi, elem.marker_i.s_B, False)
    pj, vj, _ = point_state(fr, fj, elem.marker_j.s_B, False)
    d = pj - pi
    L = np.linalg.norm(d, axis=-1)
    u = d / np.where(L > 0, L, 1.0)[..., None]
    Ld = np.einsum("...i,...i->...", u, vj - vi)
    return L, Ld, u, (fi, pi), (fj, pj)


@register(SpringDamper)
class SpringEval:
    @staticmethod
    def tension(elem, L, Ld):
        """Tension [N], positive pulling the points together."""
        return elem.stiffness * (L - elem.free_length) + elem.damping * Ld + elem.preload

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        Q = np.zeros(sys.nv)
        L, Ld, u, (fi, pi), (fj, pj) = spring_state(sys, fr, elem)
        T = SpringEval.tension(elem, L, Ld)
        add_point_force(sys, fr, Q, fi, pi - fr.r[fi], T * u)
        add_point_force(sys, fr, Q, fj, pj - fr.r[fj], -T * u)
        return Q

    @staticmethod
    def potential(sys, fr, elem):
        L = spring_state(sys, fr, elem)[0]
        x = L - elem.free_length
        return 0.5 * elem.stiffness * x**2 + elem.preload * x

    @staticmethod
    def dissipation(sys, fr, elem, t):
        Ld = spring_state(sys, fr, elem)[1]
        return elem.damping * Ld**2
