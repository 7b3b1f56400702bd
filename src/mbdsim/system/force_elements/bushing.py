"""Bushing between two markers (Adams BUSHING semantics, small-angle rotations)."""
from __future__ import annotations

import numpy as np

from ...model.element_specs import Bushing
from ..frames import point_state
from ..constraints.primitives import cross
from . import register
from ._common import batched
from .loads import add_point_force, add_torque


def bushing_state(sys, fr, elem):
    """Deflections of a bushing for time-axis frames (N, ...), all in marker_i axes.

    Returns x [m], xd [m/s], a [rad] (rotation vector of marker_j relative to marker_i), w [rad/s]
    (relative angular velocity), Ai (N, 3, 3) marker_i axes -> ground, and the ground points p_i, p_j."""
    mi, mj = elem.marker_i, elem.marker_j
    fi, fj = sys.fid[mi.body], sys.fid[mj.body]
    p_i, v_i, _ = point_state(fr, fi, mi.s_B, False)
    p_j, v_j, _ = point_state(fr, fj, mj.s_B, False)
    Ai = fr.A[:, fi] @ mi.R_BM
    Aj = fr.A[:, fj] @ mj.R_BM
    w_i, w_j = fr.w[:, fi], fr.w[:, fj]
    d = p_j - p_i
    to_i = lambda vec: np.einsum("nji,nj->ni", Ai, vec)  # noqa: E731
    x = to_i(d)
    xd = to_i(v_j - v_i - cross(w_i, d))
    from scipy.spatial.transform import Rotation
    a = Rotation.from_matrix(np.einsum("nji,njk->nik", Ai, Aj)).as_rotvec().reshape(-1, 3)
    w = to_i(w_j - w_i)
    return x, xd, a, w, Ai, p_i, p_j


def bushing_loads(elem, x, xd, a, w):
    """Force F [N] and torque T [N m] on body_j, marker_i axes, (N, 3) each."""
    k, c, f0 = elem.stiffness, elem.damping, elem.preload
    F = -k[:3] * x - c[:3] * xd + f0[:3]
    T = -k[3:] * a - c[3:] * w + f0[3:]
    return F, T


@register(Bushing)
class BushingEval:
    @staticmethod
    def generalized(sys, fr, elem, t, state):
        fb, _ = batched(fr)
        x, xd, a, w, Ai, _, p_j = bushing_state(sys, fb, elem)
        F, T = bushing_loads(elem, x, xd, a, w)
        Fg, Tg, p_j = Ai[0] @ F[0], Ai[0] @ T[0], p_j[0]
        fi, fj = sys.fid[elem.marker_i.body], sys.fid[elem.marker_j.body]
        Q = np.zeros(sys.nv)
        add_point_force(sys, fr, Q, fj, p_j - fr.r[fj], Fg)
        add_torque(sys, fr, Q, fj, Tg)
        add_point_force(sys, fr, Q, fi, p_j - fr.r[fi], -Fg)   # reaction at the same point: offset moment
        add_torque(sys, fr, Q, fi, -Tg)
        return Q

    @staticmethod
    def potential(sys, fr, elem):
        """1/2 x.K x - F0.x + 1/2 a.K a - T0.a [J] (exact for the translations and for isotropic
        rotational stiffness; small-angle otherwise: Adams' torque -K a with unequal rotational
        stiffnesses has no potential for finite rotations, and the run monitor skips the energy balance)."""
        x, _, a, *_ = bushing_state(sys, fr, elem)
        k, f0 = elem.stiffness, elem.preload
        return (0.5 * np.einsum("ni,i,ni->n", x, k[:3], x) - x @ f0[:3]
                + 0.5 * np.einsum("ni,i,ni->n", a, k[3:], a) - a @ f0[3:])

    @staticmethod
    def dissipation(sys, fr, elem, t):
        """Damping power xd.C xd + w.C w [W]."""
        _, xd, _, w, *_ = bushing_state(sys, fr, elem)
        c = elem.damping
        return np.einsum("ni,i,ni->n", xd, c[:3], xd) + np.einsum("ni,i,ni->n", w, c[3:], w)
