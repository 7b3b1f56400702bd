"""Frame kinematics of a Result: orientations of markers, motion relative to a moving frame.

All functions take (system, frames) with a leading time axis and return ground-axes arrays (N, 3)
[m, m/s, m/s^2, rad/s, rad/s^2] or rotation matrices (N, 3, 3); `Result` expresses them in a frame.

Relative motion (Adams' VX(i, j, k, l) with j = l = the reference frame f): for a point P and a frame f
with origin O, angular velocity w and angular acceleration alpha, rho = P - O and

    v_rel = d_f/dt rho       = v_P - v_O - w x rho
    a_rel = d_f^2/dt^2 rho   = a_P - a_O - alpha x rho - w x (w x rho) - 2 w x v_rel

so that a_P = a_rel + a_transport + a_coriolis with a_transport = a_O + alpha x rho + w x (w x rho)
(the acceleration of the point of f that P occupies) and a_coriolis = 2 w x v_rel.  For angular
motion, w_rel = w_B - w_f and alpha_rel = d_f/dt w_rel = alpha_B - alpha_f - w_f x w_rel.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..system import measures as ms


def orientation(sys, fr, target) -> np.ndarray:
    """Rotation matrices (N, 3, 3) target axes -> ground: body orientation times the marker's R_BM."""
    fid, _, R_BM = ms.locate(sys, target)
    return fr.A[:, fid] @ R_BM


@dataclass
class RelativeMotion:
    """Motion of a point relative to a frame f, ground axes (N, 3): rho [m], v_rel [m/s], a_rel [m/s^2]
    (None without accelerations), and the transport and Coriolis accelerations [m/s^2]."""

    rho: np.ndarray
    v_rel: np.ndarray
    v_transport: np.ndarray
    a_rel: np.ndarray | None = None
    a_transport: np.ndarray | None = None
    a_coriolis: np.ndarray | None = None


def relative_point_motion(sys, fr, target, ref) -> RelativeMotion:
    """Motion of the CM / marker origin `target` relative to the frame `ref` (derivatives taken in ref)."""
    p, vp, ap = ms.point_kinematics(sys, fr, target)
    o, vo, ao = ms.point_kinematics(sys, fr, ref)
    fid = ms.locate(sys, ref)[0]
    w = fr.w[:, fid]
    rho = p - o
    v_tr = vo + np.cross(w, rho)
    v_rel = vp - v_tr
    out = RelativeMotion(rho, v_rel, v_tr)
    if ap is not None:
        al = fr.alpha[:, fid]
        out.a_transport = ao + np.cross(al, rho) + np.cross(w, np.cross(w, rho))
        out.a_coriolis = 2.0 * np.cross(w, v_rel)
        out.a_rel = ap - out.a_transport - out.a_coriolis
    return out


def relative_angular_motion(sys, fr, target, ref):
    """(w_rel [rad/s], alpha_rel [rad/s^2] or None) (N, 3), ground axes, of target's body relative to
    the frame `ref`; alpha_rel is the derivative of w_rel taken in ref."""
    fb, ff = ms.locate(sys, target)[0], ms.locate(sys, ref)[0]
    w_rel = fr.w[:, fb] - fr.w[:, ff]
    if fr.alpha is None:
        return w_rel, None
    return w_rel, fr.alpha[:, fb] - fr.alpha[:, ff] - np.cross(fr.w[:, ff], w_rel)
