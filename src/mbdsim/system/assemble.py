"""Build the frozen System (coordinate layout, row layout, mass data) from a Model.

Coordinates q per rigid body: CM position r [m] then Euler parameters p (4); per particle: r.
Velocities v per rigid body: CM velocity [m/s] then angular velocity in body axes w_B [rad/s];
per particle: CM velocity.  Frame index 0 is ground, k+1 is system body k.
Auxiliary coordinates (the curve parameter s of each point-on-curve constraint) follow the bodies in
q and v (s and s_dot, zero mass).  Rows: joints, motions, path constraints, then one lock row per
joint friction element (active only while it sticks, see force_elements.friction).
"""
from __future__ import annotations

import contextlib
import contextvars
import dataclasses
from dataclasses import dataclass, field
from typing import Any

from .._userwarn import warn

import numpy as np

from .guard import guarded_time_function
from ..errors import ModelError
from ..math.rotation import cross3, matrix_to_quat, perpendicular_frame
from .constraints.base import JointGeom, RowSpec
from .constraints.coupler import coord_specs
from .constraints.driver import driver_rows
from .constraints.path import path_specs
from .constraints.registry import JOINT_TYPES
from .force_elements.friction import lock_specs
from .packing import pack_rows

KERNEL_KINDS = ("sph", "dot1", "dot2", "angle", "slide", "screw", "cvel")   # row kinds of system.kernels


@dataclass
class Group:
    """All rows of one primitive kind: frame indices, stacked body-axes vectors, first-row addresses."""

    kind: str
    bi: np.ndarray
    bj: np.ndarray
    vecs: tuple
    row_adr: np.ndarray
    fns: list = field(default_factory=list)


@dataclass(repr=False)
class System:
    """Assembled equations of a Model; see module docstring for the coordinate layout."""

    model: Any
    bodies: list
    fid: dict                  # Body -> frame index
    nq: int
    nv: int
    nc: int
    r_idx: np.ndarray          # (nbody, 3) into q
    p_idx: np.ndarray          # (nrigid, 4) into q
    rd_idx: np.ndarray         # (nbody, 3) into v
    w_idx: np.ndarray          # (nrigid, 3) into v
    rigid_fid: np.ndarray      # (nrigid,) frame indices of rigid bodies
    frame_v_adr: np.ndarray    # (nbody+1,) start of each frame's velocity block, -1 for ground
    frame_rigid: np.ndarray    # (nbody+1,) bool
    mass: np.ndarray           # (nbody+1,) [kg]
    inertia_B: np.ndarray      # (nbody+1, 3, 3) [kg m^2] about the CM, body axes
    groups: list
    row_owner: list            # name of the joint/motion of each row
    owner_rows: dict           # name -> row indices
    geoms: dict                # joint name -> JointGeom
    q0: np.ndarray
    v0: np.ndarray
    # issue 3: auxiliary coordinates (curve parameters of path constraints) after the bodies' blocks,
    # massless, ignored by Frames; run-time switched rows (stick locks of joint friction), last rows
    aux_q_idx: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    aux_v_idx: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    lock_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    switched: dict = field(default_factory=dict)   # friction name -> StickSlip (mode history)
    # issue 11: why the compiled core cannot run this system (rows the kernels do not carry: couplers,
    # user constraints); empty when it can (callable sensors are called back: solvers.pyloads).  compile_system checks it.
    not_compiled: list = field(default_factory=list)
    # simulate(monitor=True): compiled runs accumulate the dissipated energy and the applied loads' work in
    # their step loop for the energy balance (solvers.energy_run); set per simulate call
    track_energy: bool = False
    # Caches of functions of this System alone (packed constraint rows, friction base rows, the compiled
    # model, the assembled initial state): computed on first use, never changed after, shared by the
    # copies assemble_system hands out for an unchanged Model.  Not run state.
    derived: dict = field(default_factory=dict)
    # Per-analysis mutable state (force-element memory, joint-angle anchors of load callables, the
    # multipliers' Jacobians): every analysis gets its own System copy with it empty; nothing else may
    # be added at run time.
    run_state: dict = field(default_factory=dict)

    @property
    def nbody(self) -> int:
        return len(self.bodies)

    def __repr__(self) -> str:
        return f"System({self.model.name!r}: nq={self.nq}, nv={self.nv}, nc={self.nc})"

    @property
    def M(self) -> np.ndarray:
        """The constant mass matrix (nv, nv) [kg, kg m^2]: masses on the translation blocks, inertias
        about the CM in body axes on the rotation blocks, zero for the massless auxiliary coordinates.
        Built on first use (kept in `derived`): the compiled path never needs it, so a 10,000-body
        chain does not allocate 60,000 x 60,000 doubles (issue 35)."""
        M = self.derived.get("mass matrix")
        if M is None:
            M = self.derived["mass matrix"] = mass_matrix(self)
        return M

    @property
    def kernel_rows(self) -> bool:
        """True when every row is of a kind the compiled constraint kernel evaluates."""
        return not len(self.aux_q_idx) and all(g.kind in KERNEL_KINDS for g in self.groups)

    @property
    def fixed_rows(self) -> np.ndarray:
        """Rows always in force (all but the switched lock rows)."""
        return np.arange(self.nc - len(self.lock_rows))


_KEEP = contextvars.ContextVar("mbdsim_keep_assembly", default=True)


@contextlib.contextmanager
def single_use():
    """Within this context every Model is assembled afresh and its System is not kept for reuse (no
    content fingerprint is taken: about 1 ms for a small model), for code that builds each Model once and
    analyses it once, such as the runs of a study."""
    token = _KEEP.set(False)
    try:
        yield
    finally:
        _KEEP.reset(token)


def assemble_system(model) -> System:
    """Assemble the System of a Model (layout, constraint rows, mass matrix, initial q and v).

    A Model assembled before and unchanged since (same content fingerprint, system.fingerprint) gets a
    copy of that System: the same arrays and caches (`derived`, the compiled model among them) with an
    empty `run_state`, as MuJoCo reuses an mjModel with a new mjData.  Models with joint friction (their
    stick/slip histories live on the System) are assembled every time."""
    if not _KEEP.get():
        sys = _assemble_system(model)
        sys.derived["calls_python"] = True   # unknown: nothing computed from the model's callables is kept
        return dataclasses.replace(sys, run_state={})
    from .fingerprint import fingerprint
    fp, callables = fingerprint(model)
    kept = getattr(model, "__dict__", {}).get("_assembled")
    if kept is not None and kept[0] == fp:
        return dataclasses.replace(kept[1], run_state={})
    sys = _assemble_system(model)
    sys.derived["calls_python"] = callables   # results of calling them (assembly) are not kept
    if not sys.switched and hasattr(model, "__dict__"):
        model.__dict__["_assembled"] = (fp, sys)   # not pickled or copied (Model.__getstate__)
    return dataclasses.replace(sys, run_state={})


def _assemble_system(model) -> System:
    """The assembly itself (see assemble_system)."""
    bodies = [b for b in model.bodies.values() if not b.is_ground]
    fid = {model.ground: 0}
    fid.update({b: k + 1 for k, b in enumerate(bodies)})
    q0, v0, r_idx, p_idx, rd_idx, w_idx, rigid, v_adr = [], [], [], [], [], [], [], [-1]
    for k, b in enumerate(bodies):
        r_idx.append(range(len(q0), len(q0) + 3)); q0 += list(b.position)
        rd_idx.append(range(len(v0), len(v0) + 3)); v_adr.append(len(v0)); v0 += list(b.velocity)
        if not b.is_particle:
            p_idx.append(range(len(q0), len(q0) + 4)); q0 += list(matrix_to_quat(b.orientation))
            w_idx.append(range(len(v0), len(v0) + 3)); v0 += list(b.orientation.T @ b.angular_velocity)
            rigid.append(k + 1)
    pspecs, s0, sd0, aux_q, aux_v, pgeoms = path_specs(model, fid, len(q0), len(v0))
    q0, v0 = q0 + s0, v0 + sd0
    nv = len(v0)
    mass = np.array([0.0] + [b.mass for b in bodies])
    J = np.zeros((len(bodies) + 1, 3, 3))
    for k, b in enumerate(bodies):
        if not b.is_particle:
            J[k + 1] = b.inertia
    specs, geoms = _row_specs(model, fid)
    geoms.update(pgeoms)
    cspecs, psi0, psid0, caux_q, caux_v = coord_specs(model, fid, geoms, len(q0), len(v0))
    if len(psi0):   # continuous angles of coupled joints (issue 11), massless like the path parameters
        q0, v0, nv = q0 + psi0, v0 + psid0, nv + len(psi0)
        aux_q, aux_v = np.concatenate([aux_q, caux_q]), np.concatenate([aux_v, caux_v])
    locks = lock_specs(model, geoms)
    specs += pspecs + cspecs + locks
    groups, owners, owner_rows = _groups(specs, fid)
    not_compiled = [f"{g.kind} rows ({', '.join(sorted({owners[r] for r in g.row_adr}))})"
                    for g in groups if g.kind not in KERNEL_KINDS + ("curve", "coord")]
    as_idx = lambda x, n: np.array([r.start for r in x], dtype=int).reshape(-1, 1) + np.arange(n)  # noqa: E731
    sys = System(model, bodies, fid, len(q0), nv, len(owners), as_idx(r_idx, 3), as_idx(p_idx, 4),
                 as_idx(rd_idx, 3), as_idx(w_idx, 3), np.array(rigid, dtype=int), np.array(v_adr),
                 np.array([False] + [not b.is_particle for b in bodies]), mass, J, groups, owners,
                 owner_rows, geoms, np.array(q0, dtype=float), np.array(v0, dtype=float), aux_q, aux_v,
                 np.arange(len(owners) - len(locks), len(owners)), {s.owner: s.fn for s in locks},
                 not_compiled)
    sys.derived["packed"] = pack_rows(sys)   # the rows for the compiled kernels (system.packing)
    return sys


def mass_matrix(sys) -> np.ndarray:
    """Dense constant mass matrix (nv, nv) of a System (see System.M)."""
    M = np.zeros((sys.nv, sys.nv))
    for a, block in zip(*mass_blocks(sys)):
        M[a:a + 3, a:a + 3] = block
    return M


def mass_blocks(sys):
    """(first velocity column (nb,), 3x3 blocks (nb, 3, 3)) of the block-diagonal mass matrix: each body's
    mass times the identity on its CM velocity [kg], each rigid body's inertia about its CM in body axes
    on its angular velocity [kg m^2]; the massless auxiliary coordinates have no block."""
    f = np.arange(1, sys.nbody + 1)
    adr = sys.frame_v_adr[f]
    trans = sys.mass[f, None, None] * np.eye(3)
    rig = f[sys.frame_rigid[f]]
    return (np.concatenate([adr, sys.frame_v_adr[rig] + 3]).astype(np.int64),
            np.concatenate([trans, sys.inertia_B[rig]]))


def joint_geometry(joint, fid) -> JointGeom:
    """Joint point and axes expressed on each of its bodies at t=0.

    A joint between two markers (joint.marker_i / marker_j) takes s_i and (f_i, g_i, h_i) from the I
    marker and s_j and (f_j, g_j, h_j) from the J marker (their x, y, z axes), so the bodies may be drawn
    apart; a universal joint's second axis is then the J marker's z axis."""
    bi, bj = joint.body_i, joint.body_j
    mi, mj = getattr(joint, "marker_i", None), getattr(joint, "marker_j", None)
    if mi is not None and mj is not None:
        Ri, Rj = mi.R_BM, mj.R_BM
        extra = Rj[:, 2] if joint.kind in ("universal", "perpendicular") else getattr(joint, "lead", None)
        return JointGeom(joint.name, fid[bi], fid[bj], bi.is_particle, bj.is_particle, mi.s_B, mj.s_B,
                         Ri[:, 0], Ri[:, 1], Ri[:, 2], Rj[:, 0], Rj[:, 1], Rj[:, 2], extra)
    f, g, h = perpendicular_frame(joint.axis)
    if joint.kind == "planar" and joint.u_axis is not None:   # the user's / documented in-plane axes
        f, g = joint.u_axis, cross3(joint.axis, joint.u_axis)
    Ai, Aj = bi.orientation, bj.orientation
    loc = lambda A, x: A.T @ x  # noqa: E731
    extra = None if joint.axis_j is None else loc(Aj, joint.axis_j)
    if joint.kind == "screw":
        extra = joint.lead
    fi = fj = (f, g, h)
    if hasattr(JOINT_TYPES.get(joint.kind), "frames"):   # own axes on each body (constant-velocity joint)
        fi, fj = JOINT_TYPES[joint.kind].frames(joint)
    return JointGeom(joint.name, fid[bi], fid[bj], bi.is_particle, bj.is_particle,
                     loc(Ai, joint.point - bi.position), loc(Aj, joint.point - bj.position),
                     *(loc(Ai, x) for x in fi), *(loc(Aj, x) for x in fj), extra)


def _row_specs(model, fid):
    specs, geoms = [], {}
    for jt in model.joints.values():
        if jt.body_i.is_particle and not jt.body_j.is_particle and jt.kind not in ("spherical", "atpoint"):
            raise ModelError(f"joint '{jt.name}'", "body_i", "a particle must be body_j of a "
                             f"{jt.kind} joint (it has no orientation to carry the joint axes)")
        if getattr(JOINT_TYPES[jt.kind], "needs_orientation", False) and (jt.body_i.is_particle or
                                                                          jt.body_j.is_particle):
            raise ModelError(f"joint '{jt.name}'", "body_j" if jt.body_j.is_particle else "body_i",
                             f"a {jt.kind} joint constrains orientations; a particle has none")
        g = joint_geometry(jt, fid)
        geoms[jt.name] = g
        _warn_particle_offset(jt, g)
        specs += _placed(JOINT_TYPES[jt.kind].rows(g), g)
    for m in model.motions.values():
        g = geoms[m.joint.name]
        if m.dof == "rotation" and g.particle_j:
            raise ModelError(f"motion '{m.name}'", "joint", "cannot drive a rotation of a particle")
        fn = guarded_time_function(m.function, f"motion '{m.name}'", m.kind)   # failures named (system.guard)
        specs += _placed(driver_rows(g, m.dof, fn, m.name), g)
    return specs, geoms


def _warn_particle_offset(jt, g):
    """A particle has no rotation: a point joint away from its position pins the particle itself."""
    if jt.kind not in ("revolute", "spherical", "universal", "fixed"):
        return
    for particle, s in ((jt.body_i, g.s_i), (jt.body_j, g.s_j)):
        if particle.is_particle and np.linalg.norm(s) > 1e-9:
            warn(f"joint '{jt.name}': its point is {np.linalg.norm(s):.6g} m from particle "
                 f"'{particle.name}', which has no rotation, so the particle is held at a fixed "
                 "offset from the joint point (it cannot swing about it); use a rigid body (e.g. a "
                 "massless link) to make a pendulum", UserWarning)


def _placed(rows, g):
    for s in rows:
        s.frames = (g.bi, g.bj)
    return rows


def _groups(specs: list[RowSpec], fid):
    owners, owner_rows, row = [], {}, 0
    buckets: dict[str, list] = {}
    for s in specs:
        buckets.setdefault(s.kind, []).append((s, row))
        owners += [s.owner] * s.nrow
        owner_rows.setdefault(s.owner, []).extend(range(row, row + s.nrow))
        row += s.nrow
    groups = []
    for kind, items in buckets.items():
        vecs = tuple(np.array([s.vecs[k] for s, _ in items], dtype=float) for k in range(len(items[0][0].vecs)))
        groups.append(Group(kind, np.array([s.frames[0] for s, _ in items]),
                            np.array([s.frames[1] for s, _ in items]), vecs,
                            np.array([r for _, r in items]), [s.fn for s, _ in items]))
    return groups, owners, {k: np.array(v) for k, v in owner_rows.items()}
