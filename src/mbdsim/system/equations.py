"""System-level constraint equations: scatter the vectorised primitive rows into global arrays.

phi (nc,): residual; phi_q (nc, nv): Jacobian with respect to the velocity variables (CM translation
[m] and body-axes virtual rotation [rad] per body); nu (nc,) = -phi_t; gamma (nc,): acceleration
right-hand side so that phi_q vd = gamma.
"""
from __future__ import annotations

import numpy as np

from . import kernels, packing
from .constraints import primitives as pr
from .constraints.registry import PAIR_ROW_KINDS
from .frames import Frames, body_frames


def _rows_of(group):
    if group.kind in ("sph", "curve"):
        return (group.row_adr[:, None] + np.arange(3)).reshape(-1)
    return group.row_adr


def group_rows(sys, fr: Frames, group):
    """Evaluate one group: returns (Rows, nu, extra_gamma) with driver targets applied."""
    v = group.vecs
    nu = extra = None
    if group.kind == "sph":
        rows = pr.spherical(fr, group.bi, group.bj, v[0], v[1])
    elif group.kind == "dot1":
        rows = pr.dot1(fr, group.bi, group.bj, v[0], v[1])
    elif group.kind == "dot2":
        rows = pr.dot2(fr, group.bi, group.bj, v[0], v[1], v[2])
    elif group.kind == "curve":   # point on a curve, with the curve parameter as extra coordinate
        from .constraints.path import curve_rows
        rows = curve_rows(sys, fr, group)
    elif group.kind in PAIR_ROW_KINDS:   # screw, constant-velocity
        rows = PAIR_ROW_KINDS[group.kind](fr, group)
    elif group.kind in ("angle", "slide"):
        if group.kind == "angle":
            _, rows, _ = pr.angle(fr, group.bi, group.bj, v[0], v[1], v[2])
        else:
            rows = pr.dot2(fr, group.bi, group.bj, v[0], v[1], v[2])
        t = fr.t
        f = np.array([fn.value(t) for fn in group.fns], dtype=float)
        nu = np.array([fn.d1(t) for fn in group.fns], dtype=float)
        extra = np.array([fn.d2(t) for fn in group.fns], dtype=float)
        d = rows.phi - f
        rows.phi = (d + np.pi) % (2 * np.pi) - np.pi if group.kind == "angle" else d
    else:  # pragma: no cover
        raise ValueError(f"unknown constraint primitive {group.kind!r}")
    return rows, nu, extra


def scatter_jacobian(sys, fr: Frames, idx, rows, out):
    """Add the row blocks of both bodies into out (nc, nv) at row indices idx."""
    for b, J_r, J_p in ((rows.bi, rows.J_ri, rows.J_pi), (rows.bj, rows.J_rj, rows.J_pj)):
        m = b > 0
        if not np.any(m):
            continue
        col = sys.frame_v_adr[b[m]]
        r = idx[m]
        out[r[:, None], col[:, None] + np.arange(3)] += J_r[m]  # (row, col) pairs are unique here
        rig = m & sys.frame_rigid[b]
        if np.any(rig):
            Jb = np.einsum("ni,nij->nj", J_p[rig], fr.A[b[rig]])
            out[idx[rig][:, None], sys.frame_v_adr[b[rig]][:, None] + 3 + np.arange(3)] += Jb
    aux = getattr(rows, "aux", None)   # auxiliary-coordinate columns (path constraints): (columns, entries)
    if aux is not None:
        np.add.at(out, (idx, aux[0]), aux[1])


def constraint_terms(sys, q, v, t, jacobian=True):
    """phi, phi_q, nu, gamma at (q, v, t); phi_q is None when jacobian=False.

    The compiled kernel evaluates every row of the kinds it knows (point-on-curve rows too, with the
    curve point evaluated here); coupler rows are added group by group."""
    if not sys.nc:
        return constraint_terms_numpy(sys, q, v, t, jacobian)
    if sys.kernel_rows:
        return _terms_compiled(sys, q, v, t, jacobian)
    return _terms_mixed(sys, q, v, t, jacobian)


def _packed(sys):
    """The System's constraint rows packed for the kernels (cached in sys.derived)."""
    packed = sys.derived.get("packed")
    if packed is None:
        packed = sys.derived["packed"] = packing.pack_rows(sys)
    return packed


def _terms_compiled(sys, q, v, t, jacobian):
    phi_, J, nu, gamma = _kernel_terms(sys, body_frames(sys, q, v), t)
    return phi_, (J if jacobian else None), nu, gamma


def driver_values(fns, t):
    """(f, f', f'') at time t [s] of the packed driver functions, as the row kernels take them."""
    return (np.array([fn.value(t) for fn in fns], dtype=float), np.array([fn.d1(t) for fn in fns], dtype=float),
            np.array([fn.d2(t) for fn in fns], dtype=float))


def _kernel_terms(sys, fr, t, V1=None):
    """phi, phi_q, nu, gamma of the packed rows from the compiled kernel at frames fr and time t [s]; V1:
    the packed vectors when the caller rewrote some (curve points), else the packed ones."""
    kind, bi, bj, V, par, drv, fns = _packed(sys)
    f, fd, fdd = driver_values(fns, t)
    phi_, nu, gamma = np.zeros(sys.nc), np.zeros(sys.nc), np.zeros(sys.nc)
    J = np.zeros((sys.nc, sys.nv))
    kernels.constraint_kernel(fr.r, fr.A, fr.rd, fr.w, kind, bi, bj, V if V1 is None else V1, par, drv,
                              f, fd, fdd, sys.frame_v_adr, sys.frame_rigid, phi_, J, nu, gamma)
    return phi_, J, nu, gamma


def _mixed_plan(sys):
    """(curve groups with their rows and parameter-rate columns, groups left to numpy), cached."""
    plan = sys.derived.get("mixed_plan")
    if plan is None:
        curves = [(g, _rows_of(g)) for g in sys.groups if g.kind == "curve"]
        rest = [g for g in sys.groups if g.kind not in kernels.KIND and g.kind not in ("sph", "curve")]
        plan = sys.derived["mixed_plan"] = (curves, rest)
    return plan


def _terms_mixed(sys, q, v, t, jacobian):
    """constraint_terms of a system with rows the kernel does not evaluate (see there)."""
    from .constraints.path import curve_extra_quad, curve_locals
    V1 = _packed(sys)[3]
    curve_groups, rest = _mixed_plan(sys)
    q, v = np.asarray(q), np.asarray(v)
    fr = body_frames(sys, q, v)
    fr.t = t
    fr.aux_q, fr.aux_v = q[sys.aux_q_idx], v[sys.aux_v_idx]
    curves = [(g, idx, curve_locals(fr, g)) for g, idx in curve_groups]
    if curves:
        V1 = V1.copy()
        for g, idx, (_, _, c, _, _) in curves:
            V1[idx, 0] = np.repeat(c, 3, axis=0)
    phi_, J, nu, gamma = _kernel_terms(sys, fr, t, V1)
    for g, idx, (aux, sd, _, t1, t2) in curves:
        gamma[idx] += curve_extra_quad(fr, g, sd, t1, t2)
        J[idx, np.repeat(sys.aux_v_idx[aux], 3)] -= t1.reshape(-1)
    for g in rest:
        _numpy_group(sys, g, fr, q, v, t, phi_, J, nu, gamma)
    return phi_, (J if jacobian else None), nu, gamma


def _numpy_group(sys, g, fr, q, v, t, phi_, J, nu, gamma):
    """Evaluate one group through the primitives' Rows (ground-axes rows, scattered here) into the global
    arrays (J may be None)."""
    if g.kind == "coord":   # couplers, gears, user constraints: rows over several joints
        from .constraints.coupler import coord_terms
        coord_terms(sys, g, fr, q, v, t, phi_, J, nu, gamma)
        return
    rows, nu_g, extra = group_rows(sys, fr, g)
    idx = _rows_of(g)
    phi_[idx] = rows.phi
    gamma[idx] = -rows.quad
    if nu_g is not None:
        nu[idx] = nu_g
        gamma[idx] += extra
    if J is not None:
        J[idx] = 0.0
        scatter_jacobian(sys, fr, idx, rows, J)


def jacobians(sys, q) -> np.ndarray:
    """Constraint Jacobians phi_q (N, nc, nv) at position samples q (N, nq), one compiled call (the
    numpy path row by row for models with path constraints)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    if not sys.nc or not sys.kernel_rows:
        return np.array([constraint_terms(sys, x, np.zeros(sys.nv), 0.0)[1] for x in q]).reshape(len(q), sys.nc, sys.nv)
    packed = _packed(sys)
    kind, bi, bj, V, par, drv, fns = packed
    return kernels.jacobian_batch(q, sys.r_idx, sys.p_idx, sys.rd_idx, sys.w_idx, sys.rigid_fid, sys.nbody + 1,
                                  kind, bi, bj, V, par, drv, len(fns), sys.frame_v_adr, sys.frame_rigid,
                                  sys.nv)


def jacobian_blocks(sys, fr, rows):
    """Compact Jacobian rows (N, len(rows), 2, 6) of constraint `rows` at the Frames `fr` (N samples):
    block 0 on the row's frame bi, block 1 on bj (sys.derived["packed"] kinds), in the velocity
    variables' axes; None when one of `rows` is not a row the kernel evaluates as packed (a coupler's,
    a point-on-curve's: the caller uses `jacobians`)."""
    rows = np.asarray(rows, dtype=np.int64)
    if not sys.kernel_rows and _outside_kernel(sys)[rows].any():
        return None
    kind, bi, bj, V, par, drv, fns = _packed(sys)
    R, A = np.ascontiguousarray(fr.r, dtype=float), np.ascontiguousarray(fr.A, dtype=float)
    return kernels.jacobian_blocks(R, A, kind[rows], bi[rows], bj[rows], np.ascontiguousarray(V[rows]),
                                   par[rows], drv[rows], len(fns), sys.frame_rigid)


def _outside_kernel(sys):
    """(nc,) True for the rows the kernel does not evaluate as packed (coupler and point-on-curve rows)."""
    out = sys.derived.get("rows outside the kernel")
    if out is None:
        out = np.zeros(sys.nc, dtype=bool)
        for g in sys.groups:
            if g.kind not in kernels.KIND and g.kind != "sph":
                out[_rows_of(g) if g.kind == "curve" else np.concatenate(
                    [np.arange(r, r + ev.nrow) for r, ev in zip(g.row_adr, g.fns)])] = True
        sys.derived["rows outside the kernel"] = out
    return out


def constraint_terms_numpy(sys, q, v, t, jacobian=True):
    """constraint_terms group by group through the primitives' Rows and `scatter_jacobian` (the same row
    maths, `kernels.row_terms`, as the compiled path, scattered by numpy: the cross-check of the packed
    rows and of the body-axes scatter)."""
    fr = body_frames(sys, q, v)
    fr.t = t
    fr.aux_q, fr.aux_v = np.asarray(q)[sys.aux_q_idx], np.asarray(v)[sys.aux_v_idx]
    phi_ = np.zeros(sys.nc)
    nu = np.zeros(sys.nc)
    gamma = np.zeros(sys.nc)
    J = np.zeros((sys.nc, sys.nv)) if jacobian else None
    for g in sys.groups:
        _numpy_group(sys, g, fr, np.asarray(q), np.asarray(v), t, phi_, J, nu, gamma)
    return phi_, J, nu, gamma


def phi(sys, q, t):
    """Constraint residual phi(q, t), shape (nc,)."""
    return constraint_terms(sys, q, np.zeros(sys.nv), t, jacobian=False)[0]
