"""Compliant sphere-plane and sphere-sphere contact with the Adams IMPACT law and regularised friction.

Kinematics (ground axes): signed gap g [m] (< 0 when penetrating), unit normal n pointing from body_i's
shape towards body_j's, contact point cp in the middle of the overlap, and the relative velocity
v_rel = v_j(cp) - v_i(cp) of the two material points at cp.  g_dot = n . v_rel exactly, so the normal
force (along n, through the sphere centres) does work -Fn d(delta)/dt and the friction force -Ft . v_t.
"""
from __future__ import annotations

import numpy as np

from ...model.element_specs import Contact
from ..constraints.primitives import cross
from . import register
from ._common import batched, element_state
from .loads import add_point_force


def _material_velocity(fr, fid, P):
    return fr.rd[:, fid] + cross(fr.w[:, fid], P - fr.r[:, fid])


def _sphere_center(fr, shape, fid):
    return fr.r[:, fid] + np.einsum("nij,j->ni", fr.A[:, fid], shape.s_B)


def contact_state(sys, fr, elem):
    """(g (N,), n (N,3), cp (N,3), v_rel (N,3)) for time-axis frames."""
    si, sj = elem.shape_i, elem.shape_j
    fi, fj = sys.fid[si.body], sys.fid[sj.body]
    if si.kind == "sphere" and sj.kind == "sphere":
        ci, cj = _sphere_center(fr, si, fi), _sphere_center(fr, sj, fj)
        d = cj - ci
        L = np.linalg.norm(d, axis=-1)
        n = d / np.where(L > 0, L, 1.0)[:, None]
        g = L - si.radius - sj.radius
        cp = ci + (si.radius - 0.5 * np.maximum(-g, 0.0))[:, None] * n
    else:
        sph, pl, sign = (sj, si, 1.0) if sj.kind == "sphere" else (si, sj, -1.0)
        fs, fp = sys.fid[sph.body], sys.fid[pl.body]
        c = _sphere_center(fr, sph, fs)
        n_pl = np.einsum("nij,j->ni", fr.A[:, fp], pl.n_B)
        p = fr.r[:, fp] + np.einsum("nij,j->ni", fr.A[:, fp], pl.s_B)
        g = np.einsum("ni,ni->n", n_pl, c - p) - sph.radius
        cp = c - (sph.radius - 0.5 * np.maximum(-g, 0.0))[:, None] * n_pl
        n = sign * n_pl
    v_rel = _material_velocity(fr, fj, cp) - _material_velocity(fr, fi, cp)
    return g, n, cp, v_rel


def normal_force(elem, g, gd):
    """IMPACT normal force [N] >= 0 of gap g [m] and gap rate gd [m/s].

    Same law as mbdsim.functions.impact(g, gd, 0, k, e, c_max, d), written out for speed:
    max(0, k delta^e - STEP(delta, 0, 0, d, c_max) gd) with delta = -g > 0, else 0."""
    g, gd = np.asarray(g, dtype=float), np.asarray(gd, dtype=float)
    delta = np.maximum(-g, 0.0)
    u = np.minimum(delta / elem.penetration, 1.0)
    F = elem.stiffness * delta**elem.exponent - elem.damping * u * u * (3.0 - 2.0 * u) * gd
    return np.where(delta > 0.0, np.maximum(F, 0.0), 0.0)


def _forces(elem, g, n, v_rel):
    """Normal force (N,), rate gd (N,), tangential slip v_t (N,3) and friction force on body_j (N,3)."""
    gd = np.einsum("ni,ni->n", n, v_rel)
    Fn = normal_force(elem, g, gd)
    v_t = v_rel - gd[:, None] * n
    reg = np.sqrt(np.einsum("ni,ni->n", v_t, v_t) + elem.friction_velocity**2)
    Ft = -(elem.mu * Fn / reg)[:, None] * v_t
    return Fn, gd, v_t, Ft


@register(Contact)
class ContactEval:
    """Contact force element; spring_length/velocity/force give the gap [m], its rate and Fn [N]."""

    @staticmethod
    def measure(sys, fr, elem):
        g, n, _, v_rel = contact_state(sys, fr, elem)
        return g, np.einsum("ni,ni->n", n, v_rel)

    @staticmethod
    def tension(elem, g, gd):
        return normal_force(elem, g, gd)

    @staticmethod
    def generalized(sys, fr, elem, t, state):
        fb, _ = batched(fr)
        g, n, cp, v_rel = contact_state(sys, fb, elem)
        Q = np.zeros(sys.nv)
        if g[0] >= 0.0:
            return Q
        Fn, _, _, Ft = _forces(elem, g, n, v_rel)
        F = Fn[0] * n[0] + Ft[0]
        fi, fj = sys.fid[elem.shape_i.body], sys.fid[elem.shape_j.body]
        add_point_force(sys, fr, Q, fj, cp[0] - fr.r[fj], F)
        add_point_force(sys, fr, Q, fi, cp[0] - fr.r[fi], -F)
        return Q

    @staticmethod
    def potential(sys, fr, elem):
        """k delta^(e+1) / (e+1) [J] while in contact."""
        delta = np.maximum(-contact_state(sys, fr, elem)[0], 0.0)
        return elem.stiffness * delta ** (elem.exponent + 1.0) / (elem.exponent + 1.0)

    @staticmethod
    def dissipation(sys, fr, elem, t):
        """Damping power (Fn - k delta^e) d(delta)/dt plus friction power mu Fn |v_t|^2 / sqrt(|v_t|^2 + vs^2) [W]."""
        g, n, _, v_rel = contact_state(sys, fr, elem)
        Fn, gd, v_t, Ft = _forces(elem, g, n, v_rel)
        delta = np.maximum(-g, 0.0)
        return (Fn - elem.stiffness * delta**elem.exponent) * (-gd) - np.einsum("ni,ni->n", Ft, v_t)

    @staticmethod
    def switch(sys, fr, elem, t):
        """Signed gap [m]: contact onset and separation are located as events."""
        return contact_state(sys, batched(fr)[0], elem)[0]

    @staticmethod
    def on_event(sys, elem, t, q, v):
        from ..frames import body_frames
        g = contact_state(sys, batched(body_frames(sys, q, v))[0], elem)[0][0]
        if abs(g) < 1e-9:
            element_state(sys, elem.name).setdefault("events", []).append(float(t))
