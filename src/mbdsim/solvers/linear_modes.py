"""Modes of a Linearization: the eigenvalues of A grouped into modes, and each body's motion in a mode.

A complex pair lambda, conj(lambda) is one mode (the member with Im > 0 is listed); each real eigenvalue
is one mode (an over-damped or unstable one); eigenvalues below the zero tolerance are rigid-body
eigenvalues, two per free coordinate (a Jordan block), so they pair into rigid-body modes at zero
frequency whose shapes are the kernel of A (its position part).
"""
from __future__ import annotations

import numpy as np


def mode_list(A, d, zero_tol=None):
    """[(lambda [rad/s], position part of the eigenvector (d,))], rigid-body modes first, then by
    increasing |lambda| and |Im lambda|."""
    if A.size == 0:
        return []
    lam, V = np.linalg.eig(A)
    top = max(1.0, float(np.max(np.abs(lam))))
    ztol = 1e-5 * top if zero_tol is None else float(zero_tol)
    zeros = [k for k in range(len(lam)) if abs(lam[k]) <= ztol]
    out = []
    for k in range(len(lam)):
        if k in zeros:
            continue
        lk = lam[k]
        if abs(lk.imag) <= 1e-9 * top:
            out.append((complex(lk.real, 0.0), _position_part(V[:, k], lk, d)))
        elif lk.imag > 0:
            out.append((complex(lk), _position_part(V[:, k], lk, d)))
    out.sort(key=lambda m: (abs(m[0]), abs(m[0].imag)))
    n_rigid = (len(zeros) + 1) // 2
    shapes = _kernel_shapes(A, d, ztol)
    shapes += [V[:d, k] for k in zeros][: max(0, n_rigid - len(shapes))]
    return [(0j, s) for s in shapes[:n_rigid]] + out


def _position_part(vec, lam, d):
    z = vec[:d]
    if np.linalg.norm(z) < 1e-12 * np.linalg.norm(vec) and abs(lam) > 0:
        z = vec[d:] / lam
    return z


def _kernel_shapes(A, d, ztol):
    """Orthonormal position parts of the kernel of A (rigid-body motions)."""
    _, s, vt = np.linalg.svd(A)
    ker = vt[s <= max(ztol, 1e-9) * max(1.0, s[0])].T
    if ker.size == 0:
        return []
    u, sz, _ = np.linalg.svd(ker[:d], full_matrices=False)
    return [u[:, k] for k in range(len(sz)) if sz[k] > 1e-6]


def modes_table(lin, zero_tol=None):
    """(DataFrame of the modes, mode list)."""
    import pandas as pd
    ml = mode_list(lin.A_mechanical, lin.dof, zero_tol)
    rows = []
    for lam, _ in ml:
        wn = abs(lam)
        rows.append({"eigenvalue": lam, "frequency [Hz]": wn / (2 * np.pi),
                     "damped frequency [Hz]": abs(lam.imag) / (2 * np.pi),
                     "damping ratio": _clean(-lam.real / wn) if wn > 0 else np.nan})
    df = pd.DataFrame(rows, columns=["eigenvalue", "frequency [Hz]", "damped frequency [Hz]", "damping ratio"])
    # complex eigenvalues as Python objects: a row (df.iloc[i]) then keeps real floats for the other
    # columns instead of upcasting them all to complex
    df["eigenvalue"] = pd.Series([complex(x) for x in df["eigenvalue"]], index=df.index, dtype=object)
    df.index.name = "mode"
    return df, ml


def _clean(zeta):
    """0.0 for a damping ratio at round-off level (an undamped mode), else zeta."""
    return 0.0 if abs(zeta) < 1e-12 else float(zeta)


def mode_shape_table(lin, i, zero_tol=None):
    """DataFrame, one row per body: x, y, z (CM) and rx, ry, rz (rotation vector), ground axes, complex,
    the largest entry (rotations weighted by the model's length) scaled to 1."""
    import pandas as pd
    from .reduced import length_scale
    ml = mode_list(lin.A_mechanical, lin.dof, zero_tol)
    if not isinstance(i, (int, np.integer)) or not 0 <= i < len(ml):
        from ..errors import ModelError
        raise ModelError("mode_shape", "i", f"expected a mode number 0..{len(ml) - 1}, got {i!r}")
    sys = lin.system
    dx = lin.basis @ ml[i][1]
    L = length_scale(sys, lin.q)
    rigid = list(sys.rigid_fid)
    table = {}
    for k, b in enumerate(sys.bodies):
        t = dx[sys.rd_idx[k]]
        r = np.zeros(3, complex) if b.is_particle else dx[sys.w_idx[rigid.index(k + 1)]]
        table[b.name] = np.concatenate([t, r]).astype(complex)
    arr = np.array(list(table.values()))
    weight = np.abs(arr) * np.r_[np.full(3, 1.0 / L), np.ones(3)]
    ref = arr.flat[int(np.argmax(weight))] if arr.size else 1.0
    arr = arr / (ref if abs(ref) > 0 else 1.0)
    df = pd.DataFrame(arr, index=list(table), columns=["x", "y", "z", "rx", "ry", "rz"])
    df.index.name = "body"
    return df
