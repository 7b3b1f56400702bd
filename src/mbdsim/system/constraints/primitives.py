"""Vectorised constraint primitives (Haug's basic constraints) evaluated for many rows at once.

Every primitive returns a `Rows` block: residual `phi`, Jacobian row vectors with respect to the
translation (J_ri, J_rj) and the ground-axes virtual rotation (J_pi, J_pj) of bodies i and j, and the
quadratic velocity term `quad` of the second time derivative (phi_dd = J vd + quad), so that the
acceleration right-hand side is gamma = -quad (+ driver terms).  Shapes: (n,) and (n, 3).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Rows:
    """A block of constraint rows between frames bi and bj (frame indices, ground = 0)."""

    bi: np.ndarray
    bj: np.ndarray
    phi: np.ndarray
    J_ri: np.ndarray
    J_pi: np.ndarray
    J_rj: np.ndarray
    J_pj: np.ndarray
    quad: np.ndarray


def cross(a, b):
    """Row-wise cross product of (..., 3) arrays (much faster than np.cross on small arrays)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], -1)


def _dot(a, b):
    return (a * b).sum(-1)


def _wwx(w, x):
    """w x (w x x), row-wise."""
    return cross(w, cross(w, x))


def _rot(fr, b, x_B):
    return np.einsum("nij,nj->ni", fr.A[b], x_B)


def dot1(fr, bi, bj, a_iB, a_jB) -> Rows:
    """a_i . a_j = 0 for unit vectors a_i fixed on frame bi and a_j on bj (body axes given)."""
    a_i, a_j = _rot(fr, bi, a_iB), _rot(fr, bj, a_jB)
    w_i, w_j = fr.w[bi], fr.w[bj]
    c = cross(a_i, a_j)
    quad = (_dot(_wwx(w_i, a_i), a_j) + 2 * _dot(cross(w_i, a_i), cross(w_j, a_j))
            + _dot(a_i, _wwx(w_j, a_j)))
    z = np.zeros_like(c)
    return Rows(bi, bj, _dot(a_i, a_j), z, c, z.copy(), -c, quad)


def dot2(fr, bi, bj, a_iB, s_iB, s_jB) -> Rows:
    """a_i . d_ij with d_ij = P_j - P_i between points s_i on bi and s_j on bj (body axes given)."""
    a_i = _rot(fr, bi, a_iB)
    s_i, s_j = _rot(fr, bi, s_iB), _rot(fr, bj, s_jB)
    w_i, w_j = fr.w[bi], fr.w[bj]
    d = fr.r[bj] + s_j - fr.r[bi] - s_i
    dd = fr.rd[bj] + cross(w_j, s_j) - fr.rd[bi] - cross(w_i, s_i)
    quad = (_dot(_wwx(w_i, a_i), d) + 2 * _dot(cross(w_i, a_i), dd)
            + _dot(a_i, _wwx(w_j, s_j) - _wwx(w_i, s_i)))
    return Rows(bi, bj, _dot(a_i, d), -a_i, cross(a_i, d + s_i), a_i.copy(),
                cross(s_j, a_i), quad)


def dot2_rate(fr, bi, bj, a_iB, s_iB, s_jB) -> np.ndarray:
    """Time derivative of a_i . d_ij [m/s]."""
    a_i = _rot(fr, bi, a_iB)
    s_i, s_j = _rot(fr, bi, s_iB), _rot(fr, bj, s_jB)
    d = fr.r[bj] + s_j - fr.r[bi] - s_i
    dd = fr.rd[bj] + cross(fr.w[bj], s_j) - fr.rd[bi] - cross(fr.w[bi], s_i)
    return _dot(a_i, dd) + _dot(cross(fr.w[bi], a_i), d)


def spherical(fr, bi, bj, s_iB, s_jB) -> Rows:
    """P_j - P_i = 0 (three rows per pair, ordered x, y, z per joint)."""
    s_i, s_j = _rot(fr, bi, s_iB), _rot(fr, bj, s_jB)
    phi = fr.r[bj] + s_j - fr.r[bi] - s_i
    quad = _wwx(fr.w[bj], s_j) - _wwx(fr.w[bi], s_i)
    n = len(bi)
    eye = np.broadcast_to(np.eye(3), (n, 3, 3))
    sk_i, sk_j = _skew(s_i), _skew(s_j)
    rep = lambda x: np.repeat(x, 3)  # noqa: E731
    return Rows(rep(bi), rep(bj), phi.reshape(-1), -eye.reshape(-1, 3), sk_i.reshape(-1, 3),
                eye.reshape(-1, 3).copy(), -sk_j.reshape(-1, 3), quad.reshape(-1))


def angle(fr, bi, bj, f_iB, g_iB, f_jB):
    """Relative rotation angle theta of j about h_i = f_i x g_i (right-hand rule), wrapped to (-pi, pi].

    Returns (theta, Rows of theta with phi = theta, theta_dot)."""
    S = dot1(fr, bi, bj, g_iB, f_jB)
    C = dot1(fr, bi, bj, f_iB, f_jB)
    th = np.arctan2(S.phi, C.phi)
    rho2 = S.phi**2 + C.phi**2
    Sd = _dot(S.J_pi, fr.w[bi]) + _dot(S.J_pj, fr.w[bj])
    Cd = _dot(C.J_pi, fr.w[bi]) + _dot(C.J_pj, fr.w[bj])
    N = C.phi * Sd - S.phi * Cd
    cS, cC = (C.phi / rho2)[:, None], (S.phi / rho2)[:, None]
    quad = (C.phi * S.quad - S.phi * C.quad) / rho2 - N * (2 * S.phi * Sd + 2 * C.phi * Cd) / rho2**2
    z = np.zeros_like(S.J_pi)
    rows = Rows(bi, bj, th, z, cS * S.J_pi - cC * C.J_pi, z.copy(), cS * S.J_pj - cC * C.J_pj, quad)
    return th, rows, N / rho2


def _skew(a):
    z = np.zeros(len(a))
    return np.stack([np.stack([z, -a[:, 2], a[:, 1]], -1), np.stack([a[:, 2], z, -a[:, 0]], -1),
                     np.stack([-a[:, 1], a[:, 0], z], -1)], -2)
