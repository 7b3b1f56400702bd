"""Linearization about an operating point: state-space matrices in independent coordinates, modes.

Coordinates (`reduced.Chart`): at the operating point (q0, v0, t0), N (nv x d) is an orthonormal basis of
the null space of phi_q (independent rows; redundant and closed-loop mechanisms alike) and G = T0 N the
same basis with each rigid body's rotational block expressed in ground axes (T0 = diag(I3, A0) per
body). The state is x = (z, y) (2d):

    position:  q(z) = project(q0 (+) N z)     z: CM translations [m] and ground-axes rotations [rad]
    velocity:  u = u0 + G y, then v = T(q)^T u projected onto phi_q v = nu
               (u: velocity variables with angular velocities in ground axes)

and the perturbation dynamics about the reference motion through (q0, u0) are

    dz/dt = y + G^T (W G - G') z,   W = diag(0, [w0]x) per rigid body (w0: reference angular velocity)
    dy/dt = G^T (a(q, u) - a0) + G'^T (u - u0)     a: accelerations, angular parts in ground axes

The term W comes from perturbing the attitude in ground axes, A = exp([dtheta]) A_ref(t), so that a
spinning body's gyroscopic modes appear at the frequencies seen in ground, as in rotordynamics. G' is the
rate of the basis carried along the reference motion (the tangent space of a joint on a driven shaft
turns with it): bases at t0 +- h on the reference path q0 (+) (h v0 + h^2/2 vd0), projected with the
motions at t0 +- h, turned onto G by orthogonal Procrustes (so G^T G' = 0), central difference with
h = 1e-5 / (fastest rate of the reference); zero at rest. The accelerations come from the equations of
motion (KKT solve, the same as dynamics); dy/dt is differentiated by central differences, steps
h_z = 1e-5 min(L, 1) and h_y = 1e-5 max(min(L, 1), |u0|) (L: the model's length scale), error about
1e-10 relative.

Inputs (B, D) are loads or motions. A load input is one component, in the element's axes (ground when
it has no frame), of an extra force [N] or torque [N m] on an `add_force` / `add_torque` element ("push"
gives "push.x", "push.y", "push.z"; "push.y" that one alone). A motion input is the acceleration
[rad/s^2 or m/s^2] added to the driven coordinate: the driver row becomes phi = delta_m, phi_q v = nu +
delta_m', gamma + u, and the state gains (delta_m, delta_m') after the mechanical states (so the model is
proper; a displacement transfer function is the acceleration one times s^2). Both enter linearly;
B and D by central differences (steps 1e-4 max(1, |load|), 1 for accelerations), exact up to round-off.
Outputs (C, D) are callables of a Result evaluated on one-sample Results (central differences, the
steps above). `eigenvalues` and `modes()` use the mechanical block (motion inputs only add zeros).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from ..errors import ModelError, SolverError
from ..model.forces import Force, Torque
from ..results.result import Result
from ..system.assemble import assemble_system
from ..system.dynamics import applied_forces, solve_kkt
from ..system.equations import constraint_terms
from ..system.force_elements import evaluator
from ..system.frames import body_frames
from .assembly import assemble_state
from .common import increment, independent_rows, project_positions
from .linear_modes import mode_shape_table, modes_table
from .reduced import Chart, length_scale, min_norm, tangent_basis, velocity_scale
from ..results.state import state_factory
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model.model import Model
    from .._types import Signal
    from typing import Sequence
    from typing import Any
    import pandas as pd

FD_REL = 1e-5


@dataclass(repr=False)
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

    def __repr__(self) -> str:
        return (f"Linearization(t={self.t:g} s, {self.dof} independent coordinates, {self.A.shape[0]} states, "
                f"inputs={self.input_names}, outputs={self.output_names})")

    @property
    def dof(self) -> int:
        """Number of independent coordinates d (the state has 2 d entries)."""
        return self.basis.shape[1]

    @property
    def A_mechanical(self) -> np.ndarray:
        """The block of A on the 2 d mechanical states (without the states of motion inputs)."""
        n = 2 * self.dof
        return self.A[:n, :n]

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues [rad/s] of the mechanical block of A (motion inputs only add zeros), complex,
        ordered by magnitude."""
        A = self.A_mechanical
        lam = np.linalg.eigvals(A) if A.size else np.zeros(0, complex)
        return lam[np.argsort(np.abs(lam), kind="stable")]

    def modes(self, zero_tol: float | None = None) -> pd.DataFrame:
        """pandas DataFrame, one row per mode, by increasing frequency: `eigenvalue` [rad/s],
        `frequency [Hz]` (undamped natural |lambda| / 2 pi), `damped frequency [Hz]` (|Im lambda| / 2 pi),
        `damping ratio` (-Re lambda / |lambda|: 0 undamped, 1 critically or over-damped real root, < 0
        unstable; NaN for rigid-body modes). A complex pair is one mode; each real eigenvalue is a mode;
        eigenvalues below zero_tol [rad/s] (default 1e-5 max(1, |lambda|max)) are zero and pair into
        rigid-body modes at zero frequency (a free coordinate has a double zero eigenvalue)."""
        return modes_table(self, zero_tol)[0]

    def mode_shape(self, i: int, zero_tol: float | None = None) -> pd.DataFrame:
        """Motion of every body in mode i (row i of `modes()`): DataFrame indexed by body, columns
        x, y, z [m] (CM displacement) and rx, ry, rz [rad] (rotation vector), ground axes, complex
        (magnitude and phase), scaled so that the largest entry is 1 (rotations count with the model's
        length scale)."""
        return mode_shape_table(self, i, zero_tol)

    def to_scipy(self) -> Any:
        """The state-space model as a `scipy.signal.StateSpace`."""
        from scipy.signal import StateSpace
        return StateSpace(self.A, self.B, self.C, self.D)


def linearize(model: Model, at: None | str | Result | tuple[Result, float] = None, inputs: str | Sequence[str] = (),
              outputs: Signal | Sequence[Signal] | dict[str, Signal] = ()) -> Linearization:
    """Linearize the equations of motion of `model` about an operating point.

    at: None (the assembled initial state at t = 0), "equilibrium" (static equilibrium first,
    `mb.equilibrium`), a Result (its last sample) or (result, t) (the result at time t [s], dense output).
    inputs: names of `add_force` / `add_torque` elements ("f" for its three components, "f.x" for one; in
    the element's axes, ground when it has none) [N, N m], or of motions (the acceleration [rad/s^2 or
    m/s^2] added to the driven coordinate; each adds two states, the displacement and rate offsets, after
    the mechanical ones). outputs: Result measures: callables of a Result returning one sample (e.g.
    `lambda r: r.position(tip)[:, 1]`), column names of `res.to_dataframe()` ("tip.y", "pin.angle"; matched
    as by `mb.plot`) or ("label [unit]", callable) pairs, in a sequence or a dict name -> measure. See the module docstring for the
    coordinates and the finite-difference steps."""
    sys, q0, v0, t0 = _operating_point(model, at)
    _, J, _, _ = constraint_terms(sys, q0, v0, t0)
    rows = independent_rows(J[sys.fixed_rows], sys=sys)
    ins = _inputs(model, sys, inputs, rows)
    N = tangent_basis(sys, q0, t0, rows)
    d, nm, nu = N.shape[1], sum(i.row >= 0 for i in ins), len(ins)
    nx = 2 * d + 2 * nm
    G, u0 = _to_ground(sys, q0, N), _to_ground(sys, q0, v0)
    L = min(length_scale(sys, q0), 1.0)
    hz, hy = FD_REL * L, FD_REL * max(L, float(np.max(np.abs(u0), initial=0.0)))
    state = _StateMap(sys, Chart(sys, q0, t0, rows, N), G, u0, state_factory(sys), ins, d)
    vd0 = state(np.zeros(nx), multipliers=False)[2]
    a0 = _to_ground(sys, q0, vd0)
    Gd = _basis_rate(sys, q0, v0, vd0, t0, rows, G)

    def rate(x, du=None):   # dy/dt = d(G^T du)/dt
        q, v, vd, _ = state(x, du, multipliers=False)
        return G.T @ (_to_ground(sys, q, vd) - a0) + Gd.T @ (_to_ground(sys, q, v) - u0)

    steps = np.r_[np.full(d, hz), np.full(d, hy), np.full(nm, hz), np.full(nm, hy)]
    A = np.zeros((nx, nx))
    A[:d, d:2 * d] = np.eye(d)
    A[:d, :d] = G.T @ (_spin_matrix(sys, q0, v0) @ G - Gd)
    A[2 * d:2 * d + nm, 2 * d + nm:] = np.eye(nm)
    A[d:2 * d] = _central(rate, nx, steps, d)
    B = np.zeros((nx, nu))
    for k, m in enumerate(i for i in range(nu) if ins[i].row >= 0):
        B[2 * d + nm + k, m] = 1.0
    isteps = np.array([i.step for i in ins])
    B[d:2 * d] = _central(lambda e: rate(np.zeros(nx), e), nu, isteps, d)
    fns, names = _outputs(outputs)
    y0, sizes = _measure(sys, t0, fns, state(np.zeros(nx)))
    C = _central(lambda e: _measure(sys, t0, fns, state(e))[0], nx, steps, len(y0))
    D = _central(lambda e: _measure(sys, t0, fns, state(np.zeros(nx), e))[0], nu, isteps, len(y0))
    out_names = [nm_ if n == 1 else f"{nm_}[{i}]" for nm_, n in zip(names, sizes) for i in range(n)]
    return Linearization(A, B, C, D, t0, q0, v0, G, sys, [i.name for i in ins], out_names, y0)


def _basis_rate(sys, q0, v0, vd0, t0, rows, G):
    """dG/dt along the reference motion (central differences over +-h, h = 1e-5 / its fastest rate), the
    basis at each time turned onto G by orthogonal Procrustes (so G^T dG/dt = 0); zero at rest."""
    rate = max(float(np.max(np.abs(_to_ground(sys, q0, v0) / velocity_scale(sys, length_scale(sys, q0))),
                            initial=0.0)), 0.0)
    if rate == 0.0 or G.shape[1] == 0:
        return np.zeros_like(G)
    h = 1e-5 / rate
    out = []
    for s in (h, -h):
        q, res, _ = project_positions(sys, increment(sys, q0, s * v0 + 0.5 * s * s * vd0), t0 + s, rows, tol=1e-14)
        Gs = _to_ground(sys, q, tangent_basis(sys, q, t0 + s, rows))
        u, _, vt = np.linalg.svd(Gs.T @ G)
        out.append(Gs @ u @ vt)
    return (out[0] - out[1]) / (2 * h)


def _central(fn, n, steps, rows):
    """(rows, n) matrix of columns (fn(h e_k) - fn(-h e_k)) / 2 h."""
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = steps[k]
        cols.append((np.asarray(fn(e)) - np.asarray(fn(-e))) / (2 * steps[k]))
    return np.array(cols).T if cols else np.zeros((rows, 0))


@dataclass
class _Input:
    name: str
    elem: object = None        # Force or Torque (loads)
    comp: int = 0              # load component 0..2
    row: int = -1              # constraint row of a motion input (-1 for loads)
    step: float = 1.0          # finite-difference step [N, N m, rad/s^2, m/s^2]


class _StateMap:
    """x = (z, y, motion offsets, their rates), du (inputs) -> (q, v, vd, lambda_) at the operating time."""

    def __init__(self, sys, chart, G, u0, sf, ins, d):
        self.sys, self.chart, self.G, self.u0, self.sf, self.ins, self.d = sys, chart, G, u0, sf, ins, d
        self.mrows = np.array([i.row for i in ins if i.row >= 0], dtype=int)

    def __call__(self, x, du=None, multipliers=True):
        sys, d, c, nm = self.sys, self.d, self.chart, len(self.mrows)
        du = np.zeros(len(self.ins)) if du is None else du
        off = np.zeros((3, sys.nc))
        off[0, self.mrows], off[1, self.mrows] = x[2 * d:2 * d + nm], x[2 * d + nm:]
        off[2, self.mrows] = [s for s, i in zip(du, self.ins) if i.row >= 0]
        q = c.q(x[:d], offset=off[0] if nm else None) if d or nm else c.q0
        v = _project_velocities(sys, q, _to_body(sys, q, self.u0 + self.G @ x[d:2 * d]), c.t, c.rows, off[1])
        Qx = np.zeros(sys.nv)
        if np.any(du):
            fr = body_frames(sys, q, v)
            for s, i in zip(du, self.ins):
                if s and i.row < 0:
                    Qx += _unit_load(sys, fr, c.t, i, float(s))
        return (q, v) + _kkt(sys, q, v, c.t, c.rows, self.sf, Qx, off[2], multipliers)


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
def _kkt(sys, q, v, t, rows, sf, Qx, dgamma, multipliers=True):
    """vd (body-axes angular parts) and multipliers of all rows (minimum norm; None unless `multipliers`),
    with extra load Qx and extra acceleration right-hand side dgamma (nc) of the motion inputs."""
    fr = body_frames(sys, q, v)
    Q = applied_forces(sys, fr, t, sf(t, q, v) if sf else None) + Qx
    _, J, _, gamma = constraint_terms(sys, q, v, t)
    try:
        vd = _solve_eom(sys, J[rows], Q, (gamma + dgamma)[rows])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"linearize: singular equations of motion ({exc}); massless bodies need a mass "
                          "matrix positive on the free motions", time=t) from None
    Jf = J[sys.fixed_rows]
    lam = np.zeros(sys.nc) if multipliers else None
    if multipliers and Jf.shape[0]:
        lam[sys.fixed_rows] = np.linalg.lstsq(Jf.T, Q - sys.M @ vd, rcond=None)[0]
    return vd, lam


def _solve_eom(sys, J, Q, gamma):
    """vd of M vd + J^T lambda = Q, J vd = gamma: Schur complement (J M^-1 J^T) lambda = J M^-1 Q - gamma
    with M^-1 cached on the System (block diagonal), the full augmented solve when M is singular."""
    Minv = sys.derived.get("linear_Minv")
    if Minv is None:
        try:
            Minv = np.linalg.inv(sys.M) if np.linalg.cond(sys.M) < 1e12 else False
        except np.linalg.LinAlgError:
            Minv = False
        sys.derived["linear_Minv"] = Minv
    if Minv is False or J.shape[0] == 0:
        return solve_kkt(sys.M, J, Q, gamma)[0] if Minv is False else Minv @ Q
    W = J @ Minv
    lam = sla.cho_solve(sla.cho_factor(W @ J.T), W @ Q - gamma)
    return Minv @ (Q - J.T @ lam)


def _project_velocities(sys, q, v, t, rows, dnu):
    """Minimum-norm correction of v so that phi_q v = nu + dnu on the rows (dnu: motion-input rates)."""
    _, J, nu, _ = constraint_terms(sys, q, v, t)
    J, nu = J[rows], (nu + dnu)[rows]
    return v - min_norm(J, J @ v - nu)


# ----------------------------------------------------------------------------- inputs
def _inputs(model, sys, inputs, rows):
    """[_Input] for load components and motions, in the order given."""
    if isinstance(inputs, str):
        inputs = (inputs,)
    out = []
    for spec in inputs:
        if not isinstance(spec, str):
            raise ModelError("linearize", "inputs", f"expected load or motion names (str), got {spec!r}")
        if spec in model.motions:
            mo = model.motions[spec]
            row = sys.owner_rows[spec][0]
            if row not in rows:
                raise ModelError("linearize", "inputs", f"motion {spec!r} is redundant with the joints here")
            unit = "rad/s^2" if mo.dof == "rotation" else "m/s^2"
            out.append(_Input(f"{spec} [{unit}]", row=row, step=1.0))
            continue
        name, _, comp = spec.partition(".")
        elem = model.forces.get(name)
        if not isinstance(elem, (Force, Torque)):
            raise ModelError("linearize", "inputs", f"{name!r} is neither a force or torque (add_force / "
                             f"add_torque) nor a motion of model '{model.name}'")
        if comp and comp not in "xyz" or len(comp) > 1:
            raise ModelError("linearize", "inputs", f"{spec!r}: the component must be x, y or z")
        unit = "N" if isinstance(elem, Force) else "N m"
        val = elem.force if isinstance(elem, Force) else elem.torque
        step = 1e-4 * max(1.0, float(np.max(np.abs(val))) if isinstance(val, np.ndarray) else 1.0)
        for c in ("xyz".index(comp),) if comp else range(3):
            out.append(_Input(f"{name}.{'xyz'[c]} [{unit}]", elem, c, -1, step))
    return out


def _unit_load(sys, fr, t, inp, size=1.0):
    """Generalized force Q (nv) of `size` along component inp.comp of element inp.elem (its axes)."""
    e = np.zeros(3)
    e[inp.comp] = size
    base = Force if isinstance(inp.elem, Force) else Torque   # (an expression load's input: a plain load)
    tmp = base(**{f.name: getattr(inp.elem, f.name) for f in dataclasses.fields(base)})
    tmp = dataclasses.replace(tmp, **{"force" if base is Force else "torque": e})
    return evaluator(tmp).generalized(sys, fr, tmp, t, None)


# ----------------------------------------------------------------------------- outputs
def _outputs(outputs):
    """(callables of a Result, names) of the outputs: callables, column names of `res.to_dataframe()`
    ("slider.x", matched as by mb.plot) or ("label [unit]", callable) pairs, in a sequence or a dict."""
    if callable(outputs) or isinstance(outputs, str) or _is_pair(outputs):
        outputs = (outputs,)
    if isinstance(outputs, dict):
        items = list(outputs.items())
    else:
        items = [(f if isinstance(f, str) else f[0] if _is_pair(f) else f"y{k}", f) for k, f in enumerate(outputs)]
    fns = []
    for name, f in items:
        if isinstance(f, str) or _is_pair(f):
            fns.append(lambda r, spec=f: _signal(r, spec))
        elif callable(f):
            fns.append(f)
        else:
            raise ModelError("linearize", "outputs", f"output {name!r} must be a callable of a Result, a column "
                             f"name of res.to_dataframe() or a ('label [unit]', callable) pair, got {f!r}")
    return fns, [n for n, _ in items]


def _is_pair(f) -> bool:
    return isinstance(f, tuple) and len(f) == 2 and isinstance(f[0], str) and callable(f[1])


def _signal(res, spec):
    from ..plotting import resolve
    try:
        return resolve(res, spec).values
    except ModelError as exc:
        raise ModelError("linearize", "outputs", str(exc)) from None


def _measure(sys, t, fns, st):
    """(outputs concatenated, size of each) on the one-sample Result of state st = (q, v, vd, lambda_)."""
    q, v, vd, lam = st
    res = Result(sys, [t], q[None], v[None], vd[None], lam[None])
    vals = [np.ravel(np.asarray(f(res), dtype=float)) for f in fns]
    return (np.concatenate(vals) if vals else np.zeros(0)), [len(x) for x in vals]
