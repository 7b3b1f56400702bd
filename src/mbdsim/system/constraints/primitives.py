"""Constraint primitives (Haug's basic constraints) evaluated for many rows at once, by the compiled
`system.kernels.row_terms` (their one implementation) through `kernels.ground_rows`.

Every primitive returns a `Rows` block: residual `phi`, Jacobian row vectors with respect to the
translation (J_ri, J_rj) and the ground-axes virtual rotation (J_pi, J_pj) of bodies i and j, and the
quadratic velocity term `quad` of the second time derivative (phi_dd = J vd + quad), so that the
acceleration right-hand side is gamma = -quad (+ driver terms).  Shapes: (n,) and (n, 3).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import kernels


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
    rate: np.ndarray | None = None   # phi's rate J v (no explicit time term), when evaluated
    aux: tuple | None = None         # (velocity columns, Jacobian entries) of auxiliary coordinates


def cross(a, b):
    """Row-wise cross product of (..., 3) arrays (much faster than np.cross on small arrays)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], -1)


def _frames(fr):
    return tuple(np.ascontiguousarray(x, dtype=float) for x in (fr.r, fr.A, fr.rd, fr.w))


def _evaluate(kind, fr, bi, bj, *vectors, par=None) -> Rows:
    """The compiled `kernels.row_terms` of rows of one kind (or kinds (n,)) between frames bi and bj, with
    the rows' vectors (body axes, each (n, 3) or one for all) and parameters par (n,)."""
    bi = np.ascontiguousarray(bi, dtype=np.int64)
    bj = np.ascontiguousarray(bj, dtype=np.int64)
    n = len(bi)
    kinds = np.full(n, kind, np.int64) if np.ndim(kind) == 0 else np.ascontiguousarray(kind, dtype=np.int64)
    V = np.zeros((n, 6, 3))
    for m, x in enumerate(vectors):
        V[:, m] = np.broadcast_to(np.asarray(x, dtype=float), (n, 3))
    p = np.zeros(n) if par is None else np.ascontiguousarray(np.broadcast_to(par, (n,)), dtype=float)
    phi, quad, rate = np.empty(n), np.empty(n), np.empty(n)
    J = np.empty((4, n, 3))
    kernels.ground_rows(kinds, *_frames(fr), bi, bj, V, p, phi, J[0], J[1], J[2], J[3], quad, rate)
    return Rows(bi, bj, phi, J[0], J[1], J[2], J[3], quad, rate)


def dot1(fr, bi, bj, a_iB, a_jB) -> Rows:
    """a_i . a_j = 0 for unit vectors a_i fixed on frame bi and a_j on bj (body axes given)."""
    return _evaluate(3, fr, bi, bj, a_iB, a_jB)


def dot2(fr, bi, bj, a_iB, s_iB, s_jB) -> Rows:
    """a_i . d_ij [m] with d_ij = P_j - P_i between points s_i on bi and s_j on bj (body axes given);
    Rows.rate its time derivative [m/s]."""
    return _evaluate(4, fr, bi, bj, a_iB, s_iB, s_jB)


def spherical(fr, bi, bj, s_iB, s_jB) -> Rows:
    """P_j - P_i = 0 [m] (three rows per pair, ordered x, y, z per joint)."""
    n = len(bi)
    rep = lambda x: np.repeat(np.broadcast_to(np.asarray(x, dtype=float), (n, 3)), 3, axis=0)  # noqa: E731
    return _evaluate(np.tile(np.arange(3), n), fr, np.repeat(bi, 3), np.repeat(bj, 3), rep(s_iB), rep(s_jB))


def angle(fr, bi, bj, f_iB, g_iB, f_jB):
    """Relative rotation angle theta [rad] of j about h_i = f_i x g_i (right-hand rule), in (-pi, pi].

    Returns (theta, Rows of theta with phi = theta, theta_dot [rad/s])."""
    rows = _evaluate(5, fr, bi, bj, f_iB, g_iB, f_jB)
    return rows.phi, rows, rows.rate


def screw(fr, bi, bj, f_iB, g_iB, f_jB, h_iB, s_iB, s_jB, c) -> Rows:
    """c wrap(s / c - theta) [m]: s = h_i . (P_j - P_i) the slide along the axis, theta the angle of j
    about h_i (from f_i towards g_i, measured on f_j), c = lead / 2 pi [m/rad] (n,) (body axes given)."""
    return _evaluate(7, fr, bi, bj, f_iB, g_iB, f_jB, h_iB, s_iB, s_jB, par=c)


def cvel(fr, bi, bj, f_iB, g_iB, f_jB, g_jB) -> Rows:
    """f_i . g_j - g_i . f_j: equal spin of the two shafts of a constant-velocity joint (body axes given)."""
    return _evaluate(8, fr, bi, bj, f_iB, g_iB, f_jB, g_jB)
