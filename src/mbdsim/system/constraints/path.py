"""Point-on-curve (path) constraint: a marker origin P on body j stays on a curve C(s) fixed on body i.

The curve parameter s is an auxiliary generalized coordinate (massless; q and v carry s and
s_dot after the body coordinates, see System.aux_q_idx / aux_v_idx).  Rows (3, ground axes):

    phi = r_j + A_j s_j - r_i - A_i c(s)              c: curve in body-i axes from its CM [m]
    Jacobian: [-I, skew(A_i c)] for body i, [I, -skew(A_j s_j)] for body j (ground-axes virtual
              rotations), -A_i c'(s) for s
    quad = w_j x (w_j x s_j) - w_i x (w_i x A_i c) - 2 s_dot w_i x (A_i c') - s_dot^2 A_i c''
    (phi_dd = J vd + quad, gamma = -quad).

These rows serve the reference path; the compiled core solves their two normal components at the foot
point instead (system.pathcoords, solvers.pathcoord; expression curves and splines).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...math.rotation import perpendicular_frame
from . import primitives as pr
from .base import JointGeom, RowSpec


@dataclass
class CurveRowSpec(RowSpec):
    """Three rows of one point-on-curve constraint; fn is its CurvePoint."""

    @property
    def nrow(self) -> int:
        return 3


class CurvePoint:
    """A curve fixed on body i, evaluated in body-i axes; `aux` is the index of its parameter s."""

    def __init__(self, spec, A0, r0, aux):
        self.spec, self.A0, self.r0, self.aux = spec, A0, r0, aux

    def local(self, s):
        """(c, c', c'') in body-i axes [m, m, m] at parameter s (beyond s_range: the callable as
        given, a spline extrapolated; integrator trial stages may probe there)."""
        C, C1, C2 = self.spec.curve.derivatives(float(s))
        return self.A0.T @ (np.asarray(C) - self.r0), self.A0.T @ np.asarray(C1), self.A0.T @ np.asarray(C2)


def path_specs(model, fid, aux_start_q, aux_start_v):
    """Row specs, initial s and s_dot, aux indices and joint geometries of the model's path constraints."""
    specs, s0, sd0, geoms = [], [], [], {}
    for k, pc in enumerate(getattr(model, "path_constraints", {}).values()):
        bi, bj, mk = pc.body, pc.marker.body, pc.marker
        cp = CurvePoint(pc, bi.orientation, bi.position, k)
        s = pc.curve.nearest(mk.point)
        C, C1, _ = pc.curve.derivatives(s)
        v_p = bj.velocity + np.cross(bj.angular_velocity, mk.point - bj.position)
        v_c = bi.velocity + np.cross(bi.angular_velocity, np.asarray(C) - bi.position)
        s0.append(s)
        sd0.append(float(np.dot(C1, v_p - v_c) / max(float(np.dot(C1, C1)), 1e-300)))
        spec = CurveRowSpec("curve", (mk.s_B,), pc.name, cp)
        spec.frames = (fid[bi], fid[bj])
        specs.append(spec)
        f, g, h = perpendicular_frame(C1 if np.linalg.norm(C1) > 0 else np.array([0.0, 0.0, 1.0]))
        Ai, Aj = bi.orientation.T, bj.orientation.T
        geoms[pc.name] = JointGeom(pc.name, fid[bi], fid[bj], bi.is_particle, bj.is_particle,
                                   Ai @ (np.asarray(C) - bi.position), mk.s_B, Ai @ f, Ai @ g, Ai @ h,
                                   Aj @ f, Aj @ g, Aj @ h)
    n = len(s0)
    return specs, s0, sd0, np.arange(aux_start_q, aux_start_q + n), np.arange(aux_start_v, aux_start_v + n), geoms


def curve_locals(fr, group):
    """(aux, s_dot, c, A_i c', A_i c'') of a point-on-curve group: parameter indices, rates [m/s per
    unit s], curve points in body-i axes [m] and the first and second parameter derivatives in ground
    axes, each (n, 3)."""
    n = len(group.bi)
    c, c1, c2 = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    aux = np.array([cp.aux for cp in group.fns], dtype=int)
    s, sd = fr.aux_q[aux], fr.aux_v[aux]
    for k, cp in enumerate(group.fns):
        c[k], c1[k], c2[k] = cp.local(s[k])
    A_i = fr.A[group.bi]
    return aux, sd, c, np.einsum("nij,nj->ni", A_i, c1), np.einsum("nij,nj->ni", A_i, c2)


def curve_extra_quad(fr, group, sd, t1, t2):
    """The parameter-rate part of quad (n*3,): 2 s_dot w_i x (A_i c') + s_dot^2 A_i c'' [m/s^2]."""
    return (2 * sd[:, None] * pr.cross(fr.w[group.bi], t1) + sd[:, None] ** 2 * t2).reshape(-1)


def curve_rows(sys, fr, group) -> pr.Rows:
    """Rows (3 per constraint, x y z) with `aux` = (velocity column of s, Jacobian entries)."""
    aux, sd, c, t1, t2 = curve_locals(fr, group)
    rows = pr.spherical(fr, group.bi, group.bj, c, group.vecs[0])
    rows.quad = rows.quad - curve_extra_quad(fr, group, sd, t1, t2)
    rows.aux = (np.repeat(sys.aux_v_idx[aux], 3), -t1.reshape(-1))
    return rows
