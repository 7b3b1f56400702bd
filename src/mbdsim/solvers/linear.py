"""Linearization about an operating point: state-space matrices in independent coordinates, modes.

Coordinates (`reduced.Chart`): at the operating point (q0, v0, t0), N (nv x d) is an orthonormal basis of
the null space of phi_q (independent rows; redundant and closed-loop mechanisms alike) and G = T0 N the
same basis with each rigid body's rotational block expressed in ground axes (T0 = diag(I3, A0) per
body). The state is x = (z, y) (2d):

    position:  q(z) = project(q0 (+) N z)     z: CM translations [m] and ground-axes rotations [rad]
    velocity:  u = u0 + G y, then v = T(q)^T u projected onto phi_q v = nu
               (u: velocity variables with angular velocities in ground axes)

and the perturbation dynamics about the reference motion through (q0, u0) are

    dz/dt = y + G^T W G z,   W = diag(0, [w0]x) per rigid body (w0: reference angular velocity, ground)
    dy/dt = G^T (a(q, u) - a0)                  a: accelerations with angular parts in ground axes

(the term W comes from perturbing the attitude in ground axes, A = exp([dtheta]) A_ref(t), so that a
spinning body's gyroscopic modes appear at the frequencies seen in ground, as in rotordynamics). The
accelerations come from the equations of motion (KKT solve, the same as dynamics); dy/dt is
differentiated by central differences, steps h_z = 1e-5 min(L, 1) and h_y = 1e-5 max(min(L, 1), |u0|)
(L: the model's length scale), error about 1e-10 relative. The basis is frozen at t0: a reference
motion whose tangent space turns (a driven mechanism moving) is linearized at that instant.

Inputs (B, D) are loads: the three components, in the element's axes (ground when it has no frame), of
an extra force [N] or torque [N m] added to an `add_force` / `add_torque` element ("push" gives
"push.x", "push.y", "push.z"; "push.y" that one alone); B is exact (the load enters the KKT solve
linearly). Outputs (C, D) are callables of a Result evaluated on one-sample Results (central
differences, the same steps; inputs step 1e-4 max(1, |load|)).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, SolverError
from ..model.forces import Force, Torque
from ..results.result import Result
from ..system.assemble import assemble_system
from ..system.dynamics import applied_forces, solve_kkt
from ..system.equations import constraint_terms
from ..system.force_elements import evaluator
from ..system.frames import body_frames
from .assembly import assemble_state
from .common import independent_rows, project_velocities
from .linear_modes import mode_shape_table, modes_table
from .reduced import Chart, length_scale, tangent_basis
from .state import state_factory

FD_REL = 1e-5


@dataclass
class Linearization:
    """dx/dt = A x + B u, y = C x + D u about an operating point (x = (z, z_dot), see module docstring).

    `eigenvalues` [rad/s] (complex), `modes()` a table of modes, `mode_shape(i)` each body's motion in
    mode i, `to_scipy()` a `scipy.signal.StateSpace`."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    t: float                                 # operating time [s]
    q: np.ndarray                            # operating configuration
    v: np.ndarray                            # operating velocities (body-axes angular parts)
    basis: np.ndarray                        # G (nv, d): ground-axes directions of z
    system: object = field(repr=False)
    input_names: list = field(default_factory=list)
    output_names: list = field(default_factory=list)
    y0: np.ndarray = field(default_factory=lambda: np.zeros(0))   # outputs at the operating point

    @property
    def dof(self) -> int:
        """Number of independent coordinates d (the state has 2 d entries)."""
        return self.basis.shape[1]

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of A [rad/s], complex, ordered by magnitude."""
        lam = np.linalg.eigvals(self.A) if self.A.size else np.zeros(0, complex)
        return lam[np.argsort(np.abs(lam), kind="stable")]

    def modes(self, zero_tol=None):
        """pandas DataFrame, one row per mode, by increasing frequency: `eigenvalue` [rad/s],
        `frequency [Hz]` (undamped natural |lambda| / 2 pi), `damped frequency [Hz]` (|Im lambda| / 2 pi),
        `damping ratio` (-Re lambda / |lambda|: 0 undamped, 1 critically or over-damped real root, < 0
        unstable; NaN for rigid-body modes). A complex pair is one mode; each real eigenvalue is a mode;
        eigenvalues below zero_tol [rad/s] (default 1e-5 max(1, |lambda|max)) are zero and pair into
        rigid-body modes at zero frequency (a free coordinate has a double zero eigenvalue)."""
        return modes_table(self, zero_tol)[0]

    def mode_shape(self, i, zero_tol=None):
        """Motion of every body in mode i (row i of `modes()`): DataFrame indexed by body, columns
        x, y, z [m] (CM displacement) and rx, ry, rz [rad] (rotation vector), ground axes, complex
        (magnitude and phase), scaled so that the largest entry is 1 (rotations count with the model's
        length scale)."""
        return mode_shape_table(self, i, zero_tol)

    def to_scipy(self):
        """The state-space model as a `scipy.signal.StateSpace`."""
        from scipy.signal import StateSpace
        return StateSpace(self.A, self.B, self.C, self.D)


def linearize(model, at=None, inputs=(), outputs=()) -> Linearization:
    """Linearize the equations of motion of `model` about an operating point.

    at: None (the assembled initial state at t = 0), "equilibrium" (static equilibrium first,
    `mb.equilibrium`), a Result (its last sample) or (result, t) (the result at time t [s], dense output).
    inputs: names of `add_force` / `add_torque` elements ("f" for its three components, "f.x" for one; in
    the element's axes, ground when it has none) [N, N m]. outputs: callables of a Result returning one
    sample (e.g. `lambda r: r.position(tip)[:, 1]`), or a dict name -> callable. See the module docstring
    for the coordinates and the finite-difference steps."""
    sys, q0, v0, t0 = _operating_point(model, at)
    _, J, _, _ = constraint_terms(sys, q0, v0, t0)
    rows = independent_rows(J[sys.fixed_rows], sys=sys)
    sf = state_factory(sys)
    N = tangent_basis(sys, q0, t0, rows)
    d = N.shape[1]
    chart = Chart(sys, q0, t0, rows, N)
    G = _to_ground(sys, q0, N)
    u0 = _to_ground(sys, q0, v0)
    L = min(length_scale(sys, q0), 1.0)
    hz, hy = FD_REL * L, FD_REL * max(L, float(np.max(np.abs(u0), initial=0.0)))
    loads, in_names = _inputs(model, inputs)
    out_fns, out_names = _outputs(outputs)

    def state(x, du=None):
        q = chart.q(x[:d]) if d else q0
        v = project_velocities(sys, q, _to_body(sys, q, u0 + G @ x[d:]), t0, rows)
        Qx = _input_load(sys, q, v, t0, loads, du)
        vd, lam = _kkt(sys, q, v, t0, rows, sf, Qx)
        return q, v, vd, lam

    def rate(x):
        q, v, vd, _ = state(x)
        return G.T @ (_to_ground(sys, q, vd) - a0)

    a0 = _to_ground(sys, q0, state(np.zeros(2 * d))[2])
    A = np.zeros((2 * d, 2 * d))
    A[:d, d:] = np.eye(d)
    A[:d, :d] = G.T @ _spin_matrix(sys, q0, v0) @ G
    for k in range(2 * d):
        h = hz if k < d else hy
        e = np.zeros(2 * d)
        e[k] = h
        A[d:, k] = (rate(e) - rate(-e)) / (2 * h)
    B = np.zeros((2 * d, len(loads)))
    fr0 = body_frames(sys, q0, v0)
    for k, ld in enumerate(loads):
        J0 = constraint_terms(sys, q0, v0, t0)[1][rows]
        vd = solve_kkt(sys.M, J0, _unit_load(sys, fr0, t0, ld), np.zeros(len(rows)))[0]
        B[d:, k] = G.T @ _to_ground(sys, q0, vd)
    C, D, y0, sizes = _output_matrices(sys, t0, state, out_fns, 2 * d, len(loads), hz, hy, d, loads)
    names = [nm if n == 1 else f"{nm}[{i}]" for nm, n in zip(out_names, sizes) for i in range(n)]
    return Linearization(A, B, C, D, t0, q0, v0, G, sys, in_names, names, y0)


# ----------------------------------------------------------------------------- operating point
def _operating_point(model, at):
    from .kinematic import check_model
    from .static import equilibrium
    check_model(model)
    if at is None:
        sys = assemble_system(model)
        rep = assemble_state(sys, sys.q0, sys.v0, 0.0)
        return sys, rep.q, rep.v, 0.0
    if isinstance(at, str):
        if at != "equilibrium":
            raise ModelError("linearize", "at", f"expected None, 'equilibrium', a Result or (result, t), got {at!r}")
        res = equilibrium(model)
        return res.system, res.q[0], res.v[0], float(res.time[0])
    res, t = (at, None) if isinstance(at, Result) else (at if isinstance(at, tuple) and len(at) == 2 else (None, None))
    if not isinstance(res, Result):
        raise ModelError("linearize", "at", f"expected None, 'equilibrium', a Result or (result, t), got {at!r}")
    if res.system.model is not model:
        raise ModelError("linearize", "at", "the Result belongs to another model")
    sub = res.at(res.time[-1] if t is None else t)
    return res.system, sub.q[0], sub.v[0], float(sub.time[0])


# ----------------------------------------------------------------------------- frames of velocity variables
def _rot_blocks(sys, q):
    fr = body_frames(sys, q, np.zeros(sys.nv))
    return [(sys.w_idx[k], fr.A[f]) for k, f in enumerate(sys.rigid_fid)]


def _to_ground(sys, q, v):
    """Velocity-variable vectors (or columns) with each rigid body's angular part rotated to ground axes."""
    out = np.array(v, dtype=float, copy=True)
    for idx, A in _rot_blocks(sys, q):
        out[idx] = A @ out[idx]
    return out


def _to_body(sys, q, u):
    out = np.array(u, dtype=float, copy=True)
    for idx, A in _rot_blocks(sys, q):
        out[idx] = A.T @ out[idx]
    return out


def _spin_matrix(sys, q, v):
    """W (nv, nv): [w0]x on each rigid body's (ground-axes) rotation block, w0 its angular velocity."""
    W = np.zeros((sys.nv, sys.nv))
    for idx, A in _rot_blocks(sys, q):
        w = A @ v[idx]
        W[np.ix_(idx, idx)] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    return W


# ----------------------------------------------------------------------------- equations of motion
def _kkt(sys, q, v, t, rows, sf, Qx):
    """vd (body-axes angular parts) and multipliers of all rows (minimum norm), with extra load Qx."""
    fr = body_frames(sys, q, v)
    Q = applied_forces(sys, fr, t, sf(t, q, v) if sf else None) + Qx
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    try:
        vd = solve_kkt(sys.M, J[rows], Q, gamma[rows])[0]
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"linearize: singular equations of motion ({exc}); massless bodies need a mass "
                          "matrix positive on the free motions", time=t) from None
    Jf = J[sys.fixed_rows]
    lam = np.zeros(sys.nc)
    if Jf.shape[0]:
        lam[sys.fixed_rows] = np.linalg.lstsq(Jf.T, Q - sys.M @ vd, rcond=None)[0]
    return vd, lam


# ----------------------------------------------------------------------------- inputs
def _inputs(model, inputs):
    """[(element, component 0..2)], names."""
    if isinstance(inputs, str):
        inputs = (inputs,)
    loads, names = [], []
    for spec in inputs:
        if not isinstance(spec, str):
            raise ModelError("linearize", "inputs", f"expected load names (str), got {spec!r}")
        name, _, comp = spec.partition(".")
        elem = model.forces.get(name)
        if not isinstance(elem, (Force, Torque)):
            raise ModelError("linearize", "inputs", f"{name!r} is not a force or torque of model "
                             f"'{model.name}' (add_force / add_torque); motions cannot be inputs yet")
        if comp and comp not in "xyz" or len(comp) > 1:
            raise ModelError("linearize", "inputs", f"{spec!r}: the component must be x, y or z")
        unit = "N" if isinstance(elem, Force) else "N m"
        for c in ("xyz".index(comp),) if comp else range(3):
            loads.append((elem, c))
            names.append(f"{name}.{'xyz'[c]} [{unit}]")
    return loads, names


def _unit_load(sys, fr, t, load, size=1.0):
    """Generalized force Q (nv) of `size` along component c of element `elem` (its axes)."""
    elem, c = load
    e = np.zeros(3)
    e[c] = size
    tmp = dataclasses.replace(elem, **{"force" if isinstance(elem, Force) else "torque": e})
    return evaluator(tmp).generalized(sys, fr, tmp, t, None)


def _input_load(sys, q, v, t, loads, du):
    if du is None or not np.any(du):
        return np.zeros(sys.nv)
    fr = body_frames(sys, q, v)
    return sum(_unit_load(sys, fr, t, ld, float(s)) for ld, s in zip(loads, du) if s)


def _input_step(load, t):
    elem, _ = load
    val = elem.force if isinstance(elem, Force) else elem.torque
    mag = float(np.max(np.abs(val))) if not callable(val) else 1.0
    return 1e-4 * max(1.0, mag)


# ----------------------------------------------------------------------------- outputs
def _outputs(outputs):
    if callable(outputs):
        outputs = (outputs,)
    if isinstance(outputs, dict):
        items = list(outputs.items())
    else:
        items = [(f"y{k}", f) for k, f in enumerate(outputs)]
    for name, f in items:
        if not callable(f):
            raise ModelError("linearize", "outputs", f"output {name!r} must be a callable of a Result, got {f!r}")
    return [f for _, f in items], [n for n, _ in items]


def _measure(sys, t, fns, st):
    q, v, vd, lam = st
    res = Result(sys, [t], q[None], v[None], vd[None], lam[None])
    vals = []
    for f in fns:
        vals.append(np.ravel(np.asarray(f(res), dtype=float)))
    return vals


def _output_matrices(sys, t, state, fns, nx, nu, hz, hy, d, loads):
    if not fns:
        return np.zeros((0, nx)), np.zeros((0, nu)), np.zeros(0), []
    vals = _measure(sys, t, fns, state(np.zeros(nx)))
    y0 = np.concatenate(vals)
    C, D = np.zeros((len(y0), nx)), np.zeros((len(y0), nu))
    for k in range(nx):
        h = hz if k < d else hy
        e = np.zeros(nx)
        e[k] = h
        C[:, k] = (np.concatenate(_measure(sys, t, fns, state(e))) -
                   np.concatenate(_measure(sys, t, fns, state(-e)))) / (2 * h)
    for k in range(nu):
        h = _input_step(loads[k], t)
        du = np.zeros(nu)
        du[k] = h
        D[:, k] = (np.concatenate(_measure(sys, t, fns, state(np.zeros(nx), du))) -
                   np.concatenate(_measure(sys, t, fns, state(np.zeros(nx), -du)))) / (2 * h)
    return C, D, y0, [len(v) for v in vals]
