"""Assembly of large systems with sparse matrices (issue 35: no dense (nc, nv) matrix on the default
route of a 10,000-body model's assembly).

The general assembly (solvers.assembly) works on the dense constraint Jacobian.  Above SPARSE_NV velocity
variables, a System assembles here with the same steps in sparse form:

- the Jacobian phi_q as a CSR matrix from the kernel's compact rows, with the columns of the curve
  parameters of point-on-curve rows and the rows of couplers, gears and user constraints
  (`assembly_rows.sparse_terms_all`); the lock rows of joint friction only where in force (none at
  the start);
- the rows kept: the spanning tree's rows (independent by structure), then the loop rows and the held
  values independent of them (`system.rows.independent_rows_sparse`, dense only in loop rows x nv);
- Newton steps least in the position metric D (diagonal): dx = D^-1 A^T (A D^-1 A^T)^-1 r with
  A = [phi_q; C] the kept constraint rows and the rows C of the held joint coordinates (joint initial
  displacements), r = [-phi; target - value], the normal matrix factored by SuperLU (O(N) for chains
  and trees); held values reached by the same continuation from as drawn as the dense route;
- velocities the same linear solve in the kinetic metric (block diagonal): the kept rows, the held
  joint rates and body velocities.

The held joint coordinates are the kernel's own angle and slide rows (`held.coordinate_rows`: a motion
driver's rows without its target), so nothing is evaluated twice, and the rotation vectors of spherical,
universal and constant-velocity joints (`assembly_rows.rotvec_rows`, `held.joint_values`' measure).  Given
values that are consistent are held exactly, as on the dense route (the same state to round-off).  A
held value dependent on the constraints and the values before it is not fitted in the kinetic-energy
metric as on the dense route: its row is dropped, the others held exactly, and it is reported
(InitialConditionWarning) when not met.  `assemble_sparse` returns why not (a str: the dense route then
decides, or refuses above 2 GB) for held values of a planar joint on a particle, dependent tree rows at the
drawn configuration, or more loop rows than `rows.LOOP_BYTES` allows; `sparse_reason` says which.  The
rows are chosen once as drawn and once more where those kept are met: a loop drawn at a singular
configuration (a row dependent as drawn and not met) may not close here where the dense route's
least-squares steps close it.
"""
from __future__ import annotations

import numpy as np

from .._blas import lazy_import
from ..system import kernels
from ..system.equations import _packed
from ..system.frames import body_frames
from ..system.metrics import kinetic_parts, length_scale, position_metric
from ..system.rows import DENSE_LIMIT, _tree_plan, independent_rows_sparse
from ..system.rows import active_rows
from .assembly_large import compact_to_csr
from .assembly_rows import rotvec_rows, sparse_terms_all as sparse_terms
from .common import increment
from .held import ROTVEC_JOINTS, Held, changed_items, coordinate_rows

SPARSE_NV = DENSE_LIMIT   # velocity variables above which assembly takes this route (tests lower it)


class _Refused(Exception):
    """The sparse route cannot take this state (the message says why): the dense route decides."""


def sparse_reason(sys) -> str | None:
    """Why the sparse assembly cannot take this System (whatever its state), in words, or None."""
    for jt in sys.model.joints.values():
        given = jt.initial_displacement is not None or jt.initial_velocity is not None
        if given and jt.name in sys.geoms and _held_kind(sys, jt) is None:
            return (f"joint '{jt.name}' ({jt.kind}) on a particle has initial values, which the sparse "
                    "assembly does not hold")
    return None


def _held_kind(sys, jt):
    """The kernel's coordinate rows of a joint (`held.coordinate_rows`), "rotvec" for a joint whose
    coordinates are a rotation vector, or None (a planar joint on a particle)."""
    return "rotvec" if jt.kind in ROTVEC_JOINTS else coordinate_rows(sys, jt)


def assemble_sparse(sys, q0, v0, t, tol):
    """(q, v, rows, changed, vchanged, phi, dropped rows) of the assembled state, as the dense route
    computes them (vchanged None when v0 is not the System's own: v is then the least change of v0),
    or why this route cannot take the System or state (a str; see the module docstring).  The lock rows
    of joint friction take part only where in force at t (none at the start, as on the dense route)."""
    reason = sparse_reason(sys)
    if reason is not None:
        return reason
    own_q, own_v = q0 is sys.q0, v0 is sys.v0
    active = active_rows(sys, sys.fixed_rows, t)
    off = np.setdiff1d(np.arange(sys.nc), active)
    try:
        q, changed = _positions(sys, q0, t, tol, own_q, active, off)
        phi, J, nu, _, Jc = sparse_terms(sys, q, np.zeros(sys.nv), t)
        vel = _Coords(sys, "initial_velocity", q, bodies=True) if own_v else None
        rows, hk = _select(sys, J, Jc, vel, off)
        if own_v:
            v, vchanged = _velocities(sys, J, nu, rows, vel, hk)
        else:
            v, vchanged = v0 - _solve(J[rows], None, J[rows] @ v0 - nu[rows]), None
    except _Refused as exc:
        return str(exc)
    fixed = sys.fixed_rows
    return (q, v, rows[rows < len(fixed)], changed, vchanged, phi[fixed], np.setdiff1d(active, rows))


# ------------------------------------------------------------------------------ held rows
class _Coords:
    """The rows C (CSR (m, nv)), values and targets of the given joint coordinates (`field`:
    initial_displacement or initial_velocity, at q) and, with `bodies`, of the given body velocities
    [m/s] and angular velocities [rad/s] (ground axes), in the dense route's order (held.velocity_items).
    Angle and slide coordinates are the kernel's rows (`held.coordinate_rows`); the rotation vectors of
    spherical, universal and constant-velocity joints are `assembly_rows.rotvec_rows`."""

    def __init__(self, sys, field, q, bodies=False):
        self.sys, self.field = sys, field
        kind, bi, bj, V, angle, g, self.items, self.block = [], [], [], [], [], [], [], []
        kern, self.rot, self.rot_at = [], [], []
        block_of = _block_of_joint(sys)
        for jt in sys.model.joints.values():
            given = getattr(jt, field)
            if given is None or jt.name not in sys.geoms:
                continue
            rows = _held_kind(sys, jt)
            geom = sys.geoms[jt.name]
            start = len(kind)
            if rows == "rotvec":
                rows = [(0, ((0.0, 0.0, 0.0),), False)] * 3   # placeholders: evaluated by rotvec_rows
                self.rot.append(jt)
                self.rot_at.append(start)
            else:
                kern += range(start, start + len(rows))
            for k, vecs, ang in rows:
                kind.append(k)
                bi.append(geom.bi)
                bj.append(geom.bj)
                V.append(np.array(tuple(vecs) + ((0.0, 0.0, 0.0),) * (6 - len(vecs))))
                angle.append(ang)
            g.extend(np.atleast_1d(given)[:len(rows)])
            self.items.append((f"joint '{jt.name}'", field, slice(start, len(kind)), ""))
            self.block += [block_of.get(jt.name, -1)] * len(rows)
        n = len(kind)
        self.kern = np.array(kern, dtype=np.int64)
        self.rot_at = (np.array(self.rot_at, dtype=np.int64)[:, None] + np.arange(3)).ravel()
        self.kind, self.bi, self.bj = (np.array(x, dtype=np.int64)[self.kern] for x in (kind, bi, bj))
        self.bj_all = np.array(bj, dtype=np.int64)
        self.bi_all = np.array(bi, dtype=np.int64)
        self.V = np.array(V, dtype=float).reshape(n, 6, 3)[self.kern]
        self.angle, self.g = np.array(angle, dtype=bool), np.array(g, dtype=float)
        self.nj = n
        self.body_rows = self._bodies(sys, q) if bodies else None
        nb = 0 if self.body_rows is None else self.body_rows[0].shape[0]
        self.block = np.array(self.block + [-1] * nb, dtype=np.int64)
        self.angle = np.concatenate([self.angle, np.zeros(nb, dtype=bool)])
        self.eval(q)

    def _bodies(self, sys, q):
        """(CSR rows, targets, compact rows, frames j) of the given body velocities."""
        fr = body_frames(sys, q) if any(b.angular_velocity_given for b in sys.bodies) else None
        rows, g, Hc, hbj = [], [], [], []
        for k, b in enumerate(sys.bodies):
            a = sys.frame_v_adr[k + 1]
            for fld, on, off, C in (("velocity", b.velocity_given, 0, np.eye(3)),
                                    ("angular_velocity", b.angular_velocity_given and not b.is_particle, 3,
                                     None if fr is None else fr.A[k + 1])):
                if not on:
                    continue
                start = self.nj + len(g)
                for r in range(3):
                    rows.append((a + off, C[r]))
                    c = np.zeros((2, 6))
                    c[1, off:off + 3] = C[r]
                    Hc.append(c)
                    hbj.append(k + 1)
                g.extend(getattr(b, fld))
                self.items.append((f"body '{b.name}'", fld, slice(start, start + 3),
                                   "m/s" if fld == "velocity" else "rad/s"))
        if not rows:
            return None
        sparse = lazy_import("scipy.sparse")
        n = len(rows)
        C = sparse.csr_matrix((np.concatenate([c for _, c in rows]),
                               (np.repeat(np.arange(n), 3), np.concatenate([a + np.arange(3) for a, _ in rows]))),
                              shape=(n, sys.nv))
        return C, np.array(g, dtype=float), np.array(Hc), np.array(hbj, dtype=np.int64)

    def eval(self, q):
        """Values x, rows C, compact rows Hc and frames hbj at q."""
        sys, n, k = self.sys, self.nj, len(self.kern)
        x, Jc = np.zeros(n), np.zeros((n, 2, 6))
        if k:
            fr = body_frames(sys, q)
            xk, Jk, z = np.zeros(k), np.zeros((k, 2, 6)), np.zeros(k)
            kernels.rows_kernel(fr.r, fr.A, fr.rd, fr.w, self.kind, self.bi, self.bj, self.V, z,
                                np.arange(k, dtype=np.int64), z, z, z, sys.frame_rigid, xk, Jk, np.zeros(k),
                                np.zeros(k))
            x[self.kern], Jc[self.kern] = xk, Jk
        if self.rot:
            th, Jr = rotvec_rows(sys, self.rot, q, self.field == "initial_velocity")
            x[self.rot_at], Jc[self.rot_at] = th.ravel(), Jr.reshape(-1, 2, 6)
        self.x, self.C, self.Hc, self.hbj = x, compact_to_csr(sys, Jc, self.bi_all, self.bj_all), Jc, self.bj_all
        if self.body_rows is not None:
            sparse = lazy_import("scipy.sparse")
            C, g, Hc, hbj = self.body_rows
            self.C = sparse.vstack([self.C, C]).tocsr()
            self.Hc, self.hbj = np.concatenate([Jc, Hc]), np.concatenate([self.bj_all, hbj])
            self.x, self.g = np.concatenate([x, C @ np.zeros(sys.nv)]), np.concatenate([self.g[:n], g])

    def residual(self, scale=1.0):
        """Target (scaled) minus value, angles wrapped to [-pi, pi)."""
        r = scale * self.g - self.x
        return np.where(self.angle, (r + np.pi) % (2 * np.pi) - np.pi, r)

    def changed(self, v=None):
        """`held.changed_items` of the items (the values at the last `eval`; rates C v with v), asked of
        the items whose values differ from their targets at all."""
        used = self.x if v is None else self.C @ v
        off = np.abs(used - self.g) > 1e-15 * np.maximum(1.0, np.abs(self.g))
        items = [Held(e, f, self.g[s], self.C[s], self.x[s], self.angle[s], u)
                 for e, f, s, u in self.items if off[s].any()]
        return changed_items(items, v)


def _block_of_joint(sys) -> dict:
    """{joint name: index of the spanning tree's block whose rows are that joint's} (kept in derived)."""
    out = sys.derived.get("sparse_block_of_joint")
    if out is None:
        from ..system.topology import _joint_graph
        topo = _tree_plan(sys)[0]
        row_joint = _joint_graph(sys)[1]
        ptr = topo.blk_ptr.tolist()
        out = sys.derived["sparse_block_of_joint"] = {
            row_joint[int(topo.blk_rows[ptr[b]])]: b for b in range(len(ptr) - 1) if ptr[b + 1] > ptr[b]}
    return out


def _select(sys, J, Jc, coords=None, off=None):
    """(kept constraint rows, kept held rows) at the Jacobian J (CSR) with compact rows Jc; the rows
    `off` (friction locks not in force) left out."""
    bj = _packed(sys)[2]
    if coords is None or not coords.C.shape[0]:
        out = independent_rows_sparse(sys, J, Jc, bj, off=off)
    else:
        out = independent_rows_sparse(sys, J, Jc, bj, coords.C, coords.Hc, coords.hbj, coords.block, off=off)
    if out is None:
        raise _Refused("its tree joints are dependent at the drawn configuration or its loops close more "
                       "rows than the sparse selection holds")
    return out


# ------------------------------------------------------------------------------ the linear solve
def _solve(A, Winv, r):
    """x = W^-1 A^T (A W^-1 A^T)^-1 r (least x^T W x with A x = r; W = I when Winv is None): the normal
    matrix factored by SuperLU, refined while the residual of A x = r falls."""
    if A.shape[0] == 0:
        return np.zeros(A.shape[1])
    splu = lazy_import("scipy.sparse.linalg").splu
    AW = A.T if Winv is None else Winv @ A.T
    try:
        lu = splu((A @ AW).tocsc(), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError as exc:   # exactly singular: the kept rows were judged independent elsewhere
        raise _Refused("the kept rows are dependent here") from exc
    x = AW @ lu.solve(r)
    err, floor = np.inf, 1e-15 * max(float(np.max(np.abs(r), initial=0.0)), 1e-300)
    for _ in range(8):   # iterative refinement: the normal matrix squares the condition number
        e = r - A @ x
        prev, err = err, float(np.max(np.abs(e), initial=0.0))
        if err <= floor or err >= 0.5 * prev:
            break
        x += AW @ lu.solve(e)
    return x


def _metric_inverse(sys):
    """The inverse of the kinetic metric (system.metrics.kinetic_parts) as a CSR matrix, block by block."""
    sparse = lazy_import("scipy.sparse")
    adr, blocks, extra = kinetic_parts(sys)
    idx = adr[:, None] + np.arange(3)
    B = blocks + extra[idx][:, :, None] * np.eye(3)
    inv = np.linalg.inv(B)
    rest = np.setdiff1d(np.arange(sys.nv), idx.ravel())
    rows = np.concatenate([np.repeat(idx, 3, axis=1).ravel(), rest])
    cols = np.concatenate([np.tile(idx, (1, 3)).ravel(), rest])
    return sparse.csr_matrix((np.concatenate([inv.ravel(), 1.0 / extra[rest]]), (rows, cols)),
                             shape=(sys.nv, sys.nv))


# ------------------------------------------------------------------------------ positions
def _positions(sys, q0, t, tol, held, active, off):
    """(q, changed items): `assembly._positions` in sparse form (Newton least in the position metric on
    the rows `active`, the rows `off` left out; held joint displacements reached by continuation from as
    drawn)."""
    sparse = lazy_import("scipy.sparse")
    Dinv = sparse.diags(1.0 / position_metric(sys)).tocsr()
    coords = _Coords(sys, "initial_displacement", q0) if held else None
    if coords is None or not coords.nj:
        q, res = _newton(sys, q0, t, tol, Dinv, None, 1.0, 50, False, active, off)
        if res > 1e-9:
            q, res = _newton(sys, q0, t, tol, Dinv, None, 1.0, 200, True, active, off)
        _check(sys, q, t, res, active)
        return q, []
    L = length_scale(sys)
    span = max(float(np.max(np.abs(np.where(coords.angle, coords.g, coords.g / L)))), 1e-300)
    n = int(min(400, max(1, np.ceil(span / 0.2))))
    q = q0
    for k in range(1, n + 1):
        q, res = _newton(sys, q, t, tol, Dinv, coords, k / n, 50, False, active, off, held=True)
    _check(sys, q, t, res, active)
    coords.eval(q)
    consistent = bool(np.all(np.abs(np.where(coords.angle, 1.0, 1.0 / L) * coords.residual()) <= 1e-9))
    return q, ([] if consistent else coords.changed())


def _newton(sys, q, t, tol, Dinv, coords, scale, maxit, backtrack, active, off, held=False):
    """Newton on the kept rows (and held coordinates at `scale` of their targets); the rows are chosen
    again once where the kept ones are met and the others not.  Returns (q, max |phi| of the rows
    `active`)."""
    L = length_scale(sys)
    zero = np.zeros(sys.nv)
    res = np.inf
    for attempt in range(2):
        phi, J, _, _, Jc = sparse_terms(sys, q, zero, t)
        if coords is not None:
            coords.eval(q)
        rows, hk = _select(sys, J, Jc, coords, off)
        last = np.inf
        for _ in range(maxit):
            res = float(np.max(np.abs(phi[active]), initial=0.0))
            if not held and res <= tol:
                return q, res
            A, r = J[rows], -phi[rows]
            if coords is not None:
                A = lazy_import("scipy.sparse").vstack([A, coords.C[hk]]).tocsr()
                r = np.concatenate([r, coords.residual(scale)[hk]])
            dx = _solve(A, Dinv, r)
            step = 1.0
            if backtrack and res > 1e-6:
                n0 = float(np.linalg.norm(phi[rows]))
                trial = lambda h: sparse_terms(sys, increment(sys, q, h * dx), zero, t)[0][rows]  # noqa: E731
                while step > 1e-3 and np.linalg.norm(trial(step)) >= n0:
                    step *= 0.5   # far from the solution: backtrack along the Gauss-Newton direction
            q = increment(sys, q, step * dx)
            small = float(np.max(np.abs(dx), initial=0.0))
            phi, J, _, _, Jc = sparse_terms(sys, q, zero, t)
            if coords is not None:
                coords.eval(q)
            if held and small < 1e-14 * max(1.0, L) and (res <= tol or res >= last):
                break   # converged (or at round-off: phi of a km-long chain does not reach 1e-12)
            last = res
            if not held and small < 1e-15 * max(1.0, float(np.max(np.abs(q)))):
                break
        res = float(np.max(np.abs(phi[active]), initial=0.0))
        if res <= 1e-9 or float(np.max(np.abs(phi[rows]), initial=0.0)) > 1e-9:
            break   # converged, or the kept rows themselves are not met: choosing again changes nothing
    return q, res


def _check(sys, q, t, res, active):
    if res > 1e-9:
        from .assembly import _check_residual
        _check_residual(sys, q, t, active, res, sparse_terms(sys, q, np.zeros(sys.nv), t)[0])


# ------------------------------------------------------------------------------ velocities
def _velocities(sys, J, nu, rows, coords, hk):
    """(v, changed items): the kept rows met, the held joint rates and body velocities held (the
    independent ones exactly), the rest of least kinetic energy."""
    sparse = lazy_import("scipy.sparse")
    A = sparse.vstack([J[rows], coords.C[hk]]).tocsr() if len(hk) else J[rows]
    v = _solve(A, _metric_inverse(sys), np.concatenate([nu[rows], coords.g[hk]]))
    return v, coords.changed(v)
