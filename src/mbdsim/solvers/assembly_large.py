"""Assembly of large tree-structured systems without dense matrices (issue 35: a 10,000-body chain).

The general assembly (solvers.assembly) works on the dense constraint Jacobian (nc, nv): 24 GB for a
10,000-body chain. A large system (more than DENSE_LIMIT velocity variables) whose joints form a tree,
whose rows the compiled kernel evaluates, and whose initial state is already consistent (phi(q0) = 0
and phi_q v0 = nu within the tolerance, no joint initial displacement or velocity to hold; or free bodies
alone) needs no assembly step: `consistent_tree` checks exactly that with the sparse Jacobian (CSR,
from the compact rows of `kernels.rows_kernel`, O(N)) and the tree blocks' independence on their
child bodies, and returns the report of that state; anything else (None) goes to the general assembly.
"""
from __future__ import annotations

import numpy as np

from .._blas import lazy_import
from ..system.equations import _packed, driver_values
from ..system.frames import body_frames
from ..system import kernels
from ..system.rows import DENSE_LIMIT, _tree_plan, compact_blocks_independent


def sparse_terms(sys, q, v, t):
    """(phi (nc,), phi_q as a CSR matrix (nc, nv), nu (nc,), gamma (nc,), the compact rows (nc, 2, 6)) at
    (q, v, t) of a system whose rows the kernel evaluates: the compact rows scattered into a sparse
    matrix, O(nc)."""
    kind, bi, bj, V, par, drv, fns = _packed(sys)
    fr = body_frames(sys, q, v)
    f, fd, fdd = driver_values(fns, t)
    nc = sys.nc
    phi, nu, gamma, Jc = np.zeros(nc), np.zeros(nc), np.zeros(nc), np.zeros((nc, 2, 6))
    kernels.rows_kernel(fr.r, fr.A, fr.rd, fr.w, kind, bi, bj, V, par, drv, f, fd, fdd, sys.frame_rigid,
                        phi, Jc, nu, gamma)
    return phi, compact_to_csr(sys, Jc, bi, bj), nu, gamma, Jc


def compact_to_csr(sys, Jc, bi, bj):
    """CSR (nc, nv) of the compact rows Jc (nc, 2, 6) on frames bi, bj (`kernels.scatter_dense`'s layout)."""
    sparse = lazy_import("scipy.sparse")
    nc = Jc.shape[0]
    rows, cols, vals = [], [], []
    for side, b in ((0, bi), (1, bj)):
        width = np.where(sys.frame_rigid[b], 6, 3)
        for k in range(6):
            on = (b != 0) & (k < width)
            rows.append(np.flatnonzero(on))
            cols.append(sys.frame_v_adr[b[on]] + k)
            vals.append(Jc[on, side, k])
    return sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(nc, sys.nv))


def consistent_tree(sys, q0, v0, t, tol):
    """(rows, phi) when the state (q0, v0) at t needs no assembly (see the module docstring), else None."""
    if sys.nv <= DENSE_LIMIT:
        return None
    if not sys.nc and sys.kernel_rows and not len(sys.lock_rows):   # free bodies: any given state is consistent
        return np.arange(0), np.zeros(0)
    if structural_reason(sys) is not None:
        return None
    blocks = _tree_plan(sys)[3]
    phi, J, nu, _, Jc = sparse_terms(sys, q0, v0, t)
    scale = max(1.0, float(np.max(np.abs(J.data), initial=0.0)))
    if np.max(np.abs(phi), initial=0.0) > tol or \
            np.max(np.abs(J @ v0 - nu), initial=0.0) > 1e-9 * max(1.0, float(np.max(np.abs(nu), initial=0.0))):
        return None
    if not compact_blocks_independent(sys, Jc, _packed(sys)[2], blocks, 1e-9 * scale):
        return None   # each tree block independent on its child body's velocities
    return np.arange(sys.nc), phi


NOT_KERNEL_ROWS = "it has constraints the compiled kernels do not evaluate (couplers, paths, joint friction)"


def structural_reason(sys) -> str | None:
    """Why the model itself (whatever its state) cannot take `consistent_tree`, in words, or None."""
    if not sys.kernel_rows or len(sys.lock_rows):
        return NOT_KERNEL_ROWS
    if any(jt.initial_displacement is not None or jt.initial_velocity is not None
           for jt in sys.model.joints.values()):
        return "joint initial displacements or velocities are given"
    _, tree, loop, blocks = _tree_plan(sys)
    if len(loop) or len(tree) != sys.nc or blocks is None:
        return "its joints close loops"
    return None


def why_dense(sys) -> str:
    """Why `consistent_tree` did not take a large system's state (words for the error of a too-large
    dense assembly)."""
    return structural_reason(sys) or "the bodies are not drawn in an assembled configuration with consistent velocities"
