"""Given initial values held at assembly: joint coordinates and rates, body velocities.

Everything here works in the velocity-variable space of a System (per rigid body: CM velocity [m/s] in
ground, angular velocity in body axes [rad/s]); a position increment dx uses the same layout (CM shift
[m], body-axes rotation vector [rad]), see `common.increment`.

`lexi_solve` is the one numerical kernel: hard rows J x = b exactly, then the held rows C x = g exactly
when that is consistent, else in the least-squares sense weighted per item by W_k = (C_k M^-1 C_k^T)^-1
(the kinetic-energy metric: the energy of the smallest correction that would fix the item, so the fit
is independent of units), and what is left free by the least x^T M x.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._blas import scipy_linalg
from ..math.lapack import cho_solve_spd
from ..system import measures as ms
from ..system.frames import body_frames

ROTVEC_JOINTS = ("spherical", "universal", "constant_velocity")


@dataclass
class Held:
    """One held item: `entity` ("joint 'pin'", "body 'rod'"), `field`, target g (k,), rows C (k, nv)
    of the linearised quantity, current value, whether its components are angles (wrapped residuals)
    and its unit for messages."""

    entity: str
    field: str
    g: np.ndarray
    C: np.ndarray
    value: np.ndarray
    angle: np.ndarray
    unit: str = ""

    def residual(self) -> np.ndarray:
        r = self.g - self.value
        return np.where(self.angle, (r + np.pi) % (2 * np.pi) - np.pi, r)


def item_weight(C, Minv) -> np.ndarray:
    """W = (C M^-1 C^T)^+ for one item's rows."""
    return np.linalg.pinv(C @ Minv @ C.T, rcond=1e-12)


# ------------------------------------------------------------------------------ joint coordinates
def joint_values(sys, jt, q, v=None):
    """(coordinates (k,), rates (k,) at v or None, rate rows (k, nv), position rows (k, nv), angle mask)
    of a joint at q: Result.joint_coordinate / joint_velocity of one state, with their Jacobians."""
    nv = sys.nv
    Q = np.broadcast_to(q, (nv + 2, len(q)))
    V = np.vstack([np.zeros(nv) if v is None else v, np.zeros(nv), np.eye(nv)])
    fr = body_frames(sys, Q, V)
    if jt.kind in ROTVEC_JOINTS:
        from ..results.joints import rotvec_rate
        th = ms.relative_rotation_vector(sys, fr, jt)
        w = ms.relative_angular_velocity(sys, fr, jt)[0]
        x, xd, rows = th[0], w, w[2:].T
        pos = rotvec_rate(th[2:], w[2:]).T
        angle = np.zeros(3, dtype=bool)
    elif jt.kind == "planar":
        x, xd = ms.planar_coordinates(sys, fr, jt)
        x, rows = x[0], xd[2:].T
        pos, angle = rows, np.array([False, False, True])
    else:
        ang, angd, sl, sld = ms.joint_coordinate(sys, fr, jt)
        parts = [(a, b, flag) for a, b, flag in ((ang, angd, True), (sl, sld, False)) if a is not None]
        x = np.array([a[0] for a, _, _ in parts])
        xd = np.stack([b for _, b, _ in parts], -1)
        rows = xd[2:].T
        pos, angle = rows, np.array([f for _, _, f in parts])
    rate = None if v is None else xd[0]
    return x, rate, rows, pos, angle


def coordinate_rows(sys, jt):
    """The joint's coordinates as constraint rows the compiled kernels evaluate, [(kind, vectors, angle)]:
    an angle row (kind 5: the angle of f_j about h_i, as `measures.joint_coordinate`) and a slide row
    (kind 6: h_i . (P_j - P_i)), the rows of a motion driver on that coordinate without its target; a
    planar joint's u and v are slides along f_i and g_i, then its angle.  None for the joints whose
    coordinates are a rotation vector (spherical, universal, constant velocity) or a planar joint on a
    particle (`joint_values` evaluates those)."""
    from ..model.joint_kinds import has_slide, is_angle
    g = sys.geoms[jt.name]
    if jt.kind in ROTVEC_JOINTS or (jt.kind == "planar" and g.particle_j):
        return None
    angle = (5, (g.f_i, g.g_i, g.f_j), True)
    if jt.kind == "planar":
        return [(6, (g.f_i, g.s_i, g.s_j), False), (6, (g.g_i, g.s_i, g.s_j), False), angle]
    out = [angle] if is_angle(jt.kind) and not g.particle_j else []
    return out + ([(6, (g.h_i, g.s_i, g.s_j), False)] if has_slide(jt.kind) else [])


def joint_position_items(sys, q, scale=1.0):
    """Held joint displacements (scaled by `scale`, for continuation) at q."""
    out = []
    for jt in sys.model.joints.values():
        if jt.initial_displacement is None or jt.name not in sys.geoms:
            continue
        x, _, _, pos, angle = joint_values(sys, jt, q)
        g = scale * jt.initial_displacement[:len(x)]
        out.append(Held(f"joint '{jt.name}'", "initial_displacement", g, pos, x, angle))
    return out


def velocity_items(sys, q):
    """Held joint rates and given body velocities [m/s] / angular velocities [rad/s] (ground) at q."""
    out = []
    for jt in sys.model.joints.values():
        if jt.initial_velocity is None or jt.name not in sys.geoms:
            continue
        x, _, rows, _, _ = joint_values(sys, jt, q)
        out.append(Held(f"joint '{jt.name}'", "initial_velocity", jt.initial_velocity[:len(x)], rows,
                        np.zeros(len(x)), np.zeros(len(x), dtype=bool)))
    fr = body_frames(sys, q) if any(b.angular_velocity_given for b in sys.bodies) else None
    for k, b in enumerate(sys.bodies):
        a = sys.frame_v_adr[k + 1]
        if b.velocity_given:
            C = np.zeros((3, sys.nv))
            C[:, a:a + 3] = np.eye(3)
            out.append(Held(f"body '{b.name}'", "velocity", b.velocity.copy(), C, np.zeros(3),
                            np.zeros(3, dtype=bool), "m/s"))
        if b.angular_velocity_given and not b.is_particle:
            C = np.zeros((3, sys.nv))
            C[:, a + 3:a + 6] = fr.A[k + 1]
            out.append(Held(f"body '{b.name}'", "angular_velocity", b.angular_velocity.copy(), C,
                            np.zeros(3), np.zeros(3, dtype=bool), "rad/s"))
    return out


# ------------------------------------------------------------------------------ the solver
def lexi_solve(J, b, items, M, rel_tol=1e-9):
    """x with J x = b (least squares if impossible), the items' rows C x = g held exactly when
    consistent, else fitted in the kinetic-energy metric of M, the rest by the least x^T M x.

    Returns (x, consistent)."""
    n = M.shape[0]
    if not items and J.shape[0]:   # nothing held: x = M^-1 J^T (J M^-1 J^T)^-1 b when J has full row rank
        MiJt = np.linalg.solve(M, J.T)
        try:
            x = MiJt @ cho_solve_spd(J @ MiJt, b)   # scipy's cho_solve(cho_factor(.)) without its checks
            atol = 1e-12 * max(1.0, float(np.abs(b).max()))
            if (np.abs(J @ x - b) <= atol + 1e-10 * np.abs(b)).all():   # np.allclose(J x, b, 1e-10, atol)
                return x, True
        except (np.linalg.LinAlgError, ValueError):
            pass   # dependent rows or an inconsistent b: the general path below
    sla = scipy_linalg()   # imported here: ~0.3 s at start-up, the fast path needs none
    if J.shape[0]:
        xp = np.linalg.lstsq(J, b, rcond=None)[0]
        N = sla.null_space(J, rcond=1e-10)
    else:
        xp, N = np.zeros(n), np.eye(n)
    consistent = True
    if items and N.shape[1]:
        Minv = np.linalg.inv(M)
        C = np.vstack([it.C for it in items])
        r = np.concatenate([it.g for it in items]) - C @ xp
        W = sla.block_diag(*[item_weight(it.C, Minv) for it in items])
        A = C @ N
        y, A_null = _cut_lstsq(A, r, np.linalg.norm(C, 2))
        e = A @ y - r
        ref = float(r @ W @ r + (C @ xp) @ W @ (C @ xp)) + 1e-300
        if float(e @ W @ e) > rel_tol ** 2 * ref:
            consistent = False
            Wh = _sqrt_psd(W)
            y, A_null = _cut_lstsq(Wh @ A, Wh @ r, np.linalg.norm(Wh @ C, 2))
        xp = xp + N @ y
        N = N @ A_null
    elif items:
        C = np.vstack([it.C for it in items])
        consistent = bool(np.allclose(C @ xp, np.concatenate([it.g for it in items]), rtol=rel_tol,
                                      atol=rel_tol))
    if N.shape[1]:
        H = N.T @ M @ N
        xp = xp - N @ np.linalg.solve(H, N.T @ (M @ xp))
    return xp, consistent


def _cut_lstsq(A, r, scale, rcond=1e-10):
    """(least-squares y of A y = r, null-space basis of A), singular values below rcond * scale cut off:
    `scale` is the size of the rows before their projection onto the free motions (A = C N), so that
    rows the constraints fix entirely (a body welded to ground given a velocity: A is round-off) fit
    nothing, rather than round-off divided by round-off (before: velocities of 1e15 m/s)."""
    if not A.shape[0]:
        return np.zeros(A.shape[1]), np.eye(A.shape[1])
    U, sv, Vt = np.linalg.svd(A, full_matrices=True)
    k = int((sv > rcond * max(float(scale), 1e-300)).sum())
    y = Vt[:k].T @ ((U[:, :k].T @ r) / sv[:k])
    return y, Vt[k:].T


def _sqrt_psd(W):
    w, U = np.linalg.eigh(0.5 * (W + W.T))
    return (U * np.sqrt(np.clip(w, 0.0, None))) @ U.T


def changed_items(items, x, given_label="given", tol=1e-9):
    """Messages for the items whose value at x differs from the given one (relative tol)."""
    out = []
    for it in items:
        used = it.C @ x if it.field != "initial_displacement" else it.value
        if np.max(np.abs(used - it.g), initial=0.0) > tol * max(1.0, float(np.max(np.abs(it.g), initial=0.0))):
            out.append((it.entity, it.field, it.g.copy(), np.asarray(used, dtype=float).copy()))
    return out
