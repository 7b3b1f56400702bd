"""Planar models (issue 11): the out-of-plane equations of a 2D mechanism are dependent by design.

A model built with `mb.Model(..., planar=True)` (plane normal +z; or planar=normal) is a mechanism
moving in planes normal to n made of ordinary 3D joints (revolutes about n, translationals in the
plane, ...).  Each constraint row is then either in-plane (it acts only on the in-plane velocities:
translations perpendicular to n and rotations about n, ground axes) or out-of-plane (translations along
n, rotations about in-plane axes).  Closed loops make out-of-plane rows dependent; assembly drops them
as usual (an independent subset of rows) but, for a planar model, says so in the AssemblyReport
instead of warning: the in-plane reactions are determinate (the dependencies involve out-of-plane rows
only), the out-of-plane ones are the minimum-norm distribution.  Rows that mix both, or dependent
in-plane rows, are reported (warned) as redundant as in any model.
"""
from __future__ import annotations

import numpy as np

from ..math.rotation import perpendicular_frame
from ..system.frames import body_frames
from .common import dependent_owners


def plane_normal(model):
    """The plane normal (unit, ground) of a model flagged planar, else None."""
    n = getattr(model, "planar", None)
    return None if n is None else np.asarray(n, dtype=float)


def split_rows(sys, q, J, n, tol=1e-9):
    """(in-plane row indices, out-of-plane row indices, mixed row indices) of the constraint Jacobian
    J (nc, nv) at q for plane normal n."""
    e1, e2, _ = perpendicular_frame(n)
    fr = body_frames(sys, q)
    B_in, B_out = [], []                # velocity directions (nv,) in and out of the plane
    for k in range(sys.nbody):
        a, f = sys.frame_v_adr[k + 1], k + 1
        for d, dst in ((e1, B_in), (e2, B_in), (n, B_out)):
            x = np.zeros(sys.nv); x[a:a + 3] = d; dst.append(x)
        if sys.frame_rigid[f]:
            A = fr.A[f]
            for d, dst in ((n, B_in), (e1, B_out), (e2, B_out)):
                x = np.zeros(sys.nv); x[a + 3:a + 6] = A.T @ d; dst.append(x)   # w_B of a ground-axes w
    for c in sys.aux_v_idx:             # joint-coordinate auxiliaries (couplers) are in-plane
        x = np.zeros(sys.nv); x[c] = 1.0; B_in.append(x)
    Jin = J @ np.array(B_in).T if B_in else np.zeros((J.shape[0], 0))
    Jout = J @ np.array(B_out).T if B_out else np.zeros((J.shape[0], 0))
    a_in, a_out = np.abs(Jin).max(axis=1, initial=0.0), np.abs(Jout).max(axis=1, initial=0.0)
    scale = np.maximum(np.maximum(a_in, a_out), 1e-300)
    inp = np.where(a_out <= tol * scale)[0]
    out = np.where((a_in <= tol * scale) & (a_out > tol * scale))[0]
    mixed = np.setdiff1d(np.arange(J.shape[0]), np.union1d(inp, out))
    return inp, out, mixed


def planar_redundancy(sys, q, J, rows):
    """(redundant owners to warn about, note for the AssemblyReport) of a model flagged planar."""
    n = plane_normal(sys.model)
    inp, out, mixed = split_rows(sys, q, J, n)
    dropped = sys.nc - len(rows)
    if len(mixed):
        owners = sorted({sys.row_owner[r] for r in mixed})
        return dependent_owners(sys, J, rows), (f"planar model: rows of {', '.join(owners)} are not in the "
                                                f"plane normal to {tuple(np.round(n, 6))}")
    rank_in = np.linalg.matrix_rank(J[inp], tol=1e-9 * max(1.0, float(np.abs(J).max(initial=0.0)))) \
        if len(inp) else 0
    if rank_in < len(inp):   # a real redundancy among in-plane equations: reported as in any model
        return dependent_owners(sys, J, rows), "planar model: in-plane equations are redundant too"
    owners = sorted({sys.row_owner[r] for r in np.setdiff1d(np.arange(sys.nc), rows)})
    if not dropped:
        return [], None
    return [], (f"planar model: {dropped} out-of-plane equations are dependent by design and dropped "
                f"(rows of {', '.join(owners)}); in-plane reactions are determinate")
