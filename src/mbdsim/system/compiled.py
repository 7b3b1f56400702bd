"""The immutable compiled model (arrays and address maps) and the per-run work arrays.

`compile_system(sys, rows)` turns an assembled System and its independent constraint rows into a
`CompiledModel`: plain numpy arrays that the numba kernels of `solvers.fastdyn` read, in the spirit of
MuJoCo's mjModel / Pinocchio's Model. Everything that changes during a run lives in a separate `Work`
(mjData / pinocchio.Data). A model with an element the compiled kernels do not carry raises
`NotCompiled` with the reason; the analysis then runs the reference (Python) path.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.contacts import ShapeContact
from ..model.element_specs import Bushing, Contact
from ..model.forces import Force, SpringDamper, Torque
from ..model.friction_path import JointFriction
from . import exprloads_pack, jointtree, loopcoords, packing, pathcoords
from .measures import locate
from .topology import Topology, system_topology

# zero-DOF models with at most this many velocity variables solve their augmented equations through the
# LU of the square Jacobian (solvers.kkt_square): 1.5 us against 3.4 us for the tree elimination at
# nv = 18 (slider-crank); the LU grows as nv^3, the tree linearly
SQUARE_MAX = 24
# the tree elimination re-selects its loop rows (solvers.fastdyn._factor) when the smallest pivot of the
# loop rows' Schur complement falls below this fraction of the largest (the selected rows nearly dependent:
# a loop carried on a turning body, whose out-of-plane rows change with the turn)
RESELECT_RATIO = 1e-6


USE_TREE = True   # trees of revolute/translational/fixed joints in joint coordinates (False: absolute only)


class NotCompiled(Exception):
    """The model needs a feature the compiled kernels do not have (reason in the message)."""


@dataclass(frozen=True)
class CompiledModel:
    """Arrays of one model for the compiled kernels; `arrays()` gives the slots they take (order fixed:
    `tuple_`), as one `mbdsim._slots.Slots`."""

    r_idx: np.ndarray
    p_idx: np.ndarray
    rd_idx: np.ndarray
    w_idx: np.ndarray
    rigid_fid: np.ndarray
    vadr: np.ndarray          # (nf,) first velocity slot of each frame (-1 for ground)
    rigid: np.ndarray         # (nf,) bool
    M6: np.ndarray            # (nf, 6, 6) mass and inertia [kg, kg m^2]; unit dummy rotation for particles
    gravity: np.ndarray       # (3,) [m/s^2] ground axes
    mass: np.ndarray          # (nf,) [kg]
    inertia: np.ndarray       # (nf, 3, 3) [kg m^2] about the CM, body axes
    kind: np.ndarray          # constraint rows (system.packing.pack_rows)
    bi: np.ndarray
    bj: np.ndarray
    vecs: np.ndarray          # (nc, 6, 3) body-axes vectors of each row (kernels.row_terms)
    par: np.ndarray           # (nc,) parameter of each row (a screw's lead / 2 pi [m/rad])
    drv: np.ndarray           # (nc,) driver index of each row, -1 if none
    code: np.ndarray          # driver programs (system.exprvm): value, d1, d2 of each driver
    consts: np.ndarray
    tables: np.ndarray
    start: np.ndarray
    end: np.ndarray
    pf_f: np.ndarray          # constant loads: frame, offset s_B [m], vector, axes frame, marker rotation
    pf_s: np.ndarray
    pf_v: np.ndarray
    pf_ff: np.ndarray
    pf_R: np.ndarray
    pf_torque: np.ndarray
    sp_f: np.ndarray          # spring-dampers: frames (i, j), points s_B, (k, c, free length, preload)
    sp_s: np.ndarray
    sp_par: np.ndarray
    topo: Topology
    dims: np.ndarray          # (nq, nv, nc, nf, dense, mode): dense = 1 when a body's mass matrix is
    #                           singular, 2 for a small zero-DOF model (the independent rows' Jacobian is
    #                           square: solvers.kkt_square); mode = 1: joint-coordinate tree (state
    #                           [theta, theta_dot])
    active: np.ndarray        # independent rows in force
    stack_size: int
    bushings: tuple = ()      # (frames (n, 2), marker points s_B (n, 2, 3), marker axes R_BM (n, 2, 3, 3),
    #                           stiffness, damping, preload (n, 6) each), see model.element_specs.Bushing
    tree: tuple = ()          # joint-coordinate tree (system.jointtree) when dims[5] == 1, else empty arrays
    exprloads: tuple = ()     # loads written as expressions (system.exprloads_pack), arrays()[43]
    ex_stack: int = 4         # stack size of their programs
    contacts: tuple = ()      # sphere-sphere / sphere-plane contacts (`_contacts`), arrays()[44]
    # arrays()[45]: the loop rows the kernel may select from (all loop rows of the spanning tree;
    # `fastdyn._factor` re-selects among them when the rows in use turn dependent as the configuration changes)
    cand: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    python_loads: tuple = ()  # names of the force elements called back through their Python evaluators by
    #                           solvers.pyloads from inside the kernels (Work slot 48): Python callables and
    #                           what cannot be packed here (`_called_back`)
    python_drivers: tuple = ()   # driver indices (into the packed driver functions) called back the same way
    input_slots: tuple = ()   # (input name, index into exprloads[14]): where the expression programs hold each
    #                           model input (Model.add_input) as a constant; mbdsim.Simulator writes them
    driver_slots: tuple = ()  # (driver index, input or anchor name, index into consts): the constants of the
    #                           motion drivers that read model inputs (model.input_drivers)
    shape_contacts: tuple = ()   # arrays()[46]: shape contacts (geometry.pack.pack_contacts, issue 30) and an
    #                              empty record buffer (0, NREC) with its counter (solvers.fastcontact)
    coords: tuple = ()        # arrays()[47]: coordinate constraints of a joint-coordinate tree (couplers, gears,
    #                           user constraints: system.jointtree.coord_arrays, solvers.treecoord)
    coord_stack: int = 4      # stack size of their programs
    loop_coords: tuple = ()   # arrays()[50]: coordinate constraints in absolute coordinates (closed loops:
    #                           system.loopcoords, solvers.loopcoord); 48: joint friction, 49: point-on-curve
    #                           parameters
    loop_stack: int = 4       # stack size of their programs
    paths: tuple = ()         # arrays()[49]: point-on-curve constraints (system.pathcoords, solvers.pathcoord)
    path_stack: int = 4
    friction: tuple = ()      # arrays()[48]: joint friction elements (`_friction`, solvers.fastfriction; issue 29)

    def arrays(self):
        """The slots cm[0..] the kernels take (`tuple_`'s order), as one `mbdsim._slots.Slots` (made once per
        model: the kernels receive it as one pointer; Python indexes it as the tuple)."""
        s = self.__dict__.get("_slots")
        if s is None:
            from .._slots import Slots
            s = Slots(self.tuple_())
            object.__setattr__(self, "_slots", s)   # (frozen dataclass: a cache, not a field)
        return s

    def tuple_(self) -> tuple:
        """The kernels' slots as a plain tuple (order fixed; append new slots at the end)."""
        t = self.topo
        topo = (t.order, t.pblk, t.blk_child, t.blk_parent, t.blk_ptr, t.blk_rows, t.ch_ptr, t.ch_blk,
                t.loop_rows)
        return (self.r_idx, self.p_idx, self.rd_idx, self.w_idx, self.rigid_fid, self.vadr, self.rigid,
                self.M6, self.gravity, self.mass, self.inertia, self.kind, self.bi, self.bj, self.vecs,
                self.drv, self.code, self.consts, self.tables, self.start, self.end, self.pf_f, self.pf_s,
                self.pf_v, self.pf_ff, self.pf_R, self.pf_torque, self.sp_f, self.sp_s, self.sp_par, topo,
                # 33, 34: the rows' vectors and parameters as `kernels.rows_kernel` takes them (33 is 14
                # again); 35: unused, kept empty so that the later slots keep their numbers
                self.dims, self.active, self.vecs, self.par, np.zeros(0),
                *self.bushings, self.tree, self.exprloads, self.contacts, self.cand,
                self.shape_contacts or _shape_contacts(None, ()), self.coords or jointtree.empty_coords(),
                self.friction or _friction(None), self.paths or pathcoords.empty(),
                self.loop_coords or loopcoords.empty())


@dataclass
class Work:
    """Per-run scratch arrays of the compiled kernels (never shared between runs)."""

    arrays_: tuple

    @classmethod
    def for_model(cls, cm: CompiledModel, energy_outputs: int = -1) -> "Work":
        """The work arrays of a run of `cm`; with energy_outputs >= 0 the run keeps the energy bookkeeping
        (slot 53, `energy_work`) for that many outputs."""
        nq, nv, nc, nf, dense, _mode = (int(x) for x in cm.dims)
        # 32, 33, 39: the dense augmented matrix (dense = 1: singular masses) or the square Jacobian's LU
        # (dense = 2: zero-DOF models, solvers.kkt_square; 33's last slot flags a valid LU)
        nk = 6 * (nf - 1) + len(cm.active) if dense == 1 else (nv if dense == 2 else 1)
        n_dep = nc - len(cm.active) if dense == 2 else 0   # dependent rows of a square model
        t = cm.topo
        nblk, nl = max(len(t.blk_child), 1), max(len(t.loop_rows), len(cm.cand), 1)
        nd = len(cm.start) // 3
        z = np.zeros
        # 31: unused (the second tree solve's loads before kkt_solve's loop correction), kept empty so
        # that the later slots keep their numbers
        a = (z((nf, 3)), z((nf, 3, 3)), z((nf, 3)), z((nf, 3)), z(nc), z((nc, 2, 6)), z(nc), z(nc), z((nf, 6)),
             z((nf, 6, 6)), z((nblk, 6, 6)), z((nblk, 6, 6)), z((nblk, 6, 6)), z((nblk, 6, 6)), z((nf, 6)),
             z((nblk, 6)), z((nl, nf, 6)), z((nl, nl)), z((1, nl, nl)), z((1, nl)), z(nc), z((nl, nc)), z((3, nd)), z(4),
             z(max(cm.stack_size, 4)), z((nf, 6)), z(nc), z((nf, 6)), z(nv), z(nc), z((nf, 6)), z((0, 6)),
             z((nk, nk)), np.zeros(nk + 1, np.int64), z(nd), z(nd), z(nd), z((nf, 6)), z((6, 6)), z(nk), z((6, 6)), np.zeros(nl + 1, np.int64), z((2, 3, 3)),
             # 43: articulated-body scratch (solvers.fasttree): IA, pA, U, zeta, S, acc, D, u, Ia, pa, P, Rtmp
             (z((nf, 6, 6)), z((nf, 6)), z((nf, 6)), z((nf, 6)), z((nf, 6)), z((nf, 6)), z(nf), z(nf), z((6, 6)),
              z(6), z((nf, 3)), z((2, 3, 3))),
             exprloads_pack.work(cm.exprloads, cm.ex_stack),   # 44: expression loads' x and stack
             # 45: minimum-norm multipliers through the square LU (solvers.kkt_square): C, S, y
             (z((max(n_dep, 1), max(nv, 1))), z((max(n_dep, 1), max(n_dep, 1))), z(max(n_dep, nv, 1))),
             # 46: the loop rows in use (from the compiled selection; `fastdyn._factor` re-selects them),
             # 47: (the pivot ratio below which it re-selects, its nominal value RESELECT_RATIO)
             np.array(t.loop_rows, dtype=np.int64), np.full(2, RESELECT_RATIO),
             # 48: loads and drivers written as Python callables (solvers.pyloads): the loads (nf, 6) and
             # [load callback address (0: none), failed flag, driver callback address (0: none), whether the
             # loads' power is the applied loads' work (1: they are all forces and torques; solvers.fastenergy)]
             (z((nf, 6)), np.zeros(4, np.int64)),
             _coord_work(cm, nf),   # 49: coordinate constraints on the tree (solvers.treecoord)
             _friction_work(cm.friction or _friction(None), nf, nc, nv),   # 50: joint friction (solvers.fastfriction)
             pathcoords.work(cm.paths or pathcoords.empty(), cm.path_stack),   # 51: solvers.pathcoord
             loopcoords.work(cm.loop_coords or loopcoords.empty(), cm.loop_stack, nf, nc),   # 52: solvers.loopcoord
             energy_work(energy_outputs, len(cm.shape_contacts) > 10 and len(cm.shape_contacts[10]) > 0))   # 53
        work = cls(a)
        work.__dict__["model"] = cm   # (for the slot types, `arrays`)
        return work

    def arrays(self):
        """The slots wk[0..] as one `mbdsim._slots.Slots` (made once per Work; the same arrays as arrays_)."""
        s = self.__dict__.get("_slots")
        if s is None:
            from .._slots import Slots
            cm = self.__dict__.get("model")   # every Work of a model has the same slot types: typed once
            s = self.__dict__["_slots"] = Slots(self.arrays_, None if cm is None else cm.__dict__.get("_work_type"))
            if cm is not None:
                object.__setattr__(cm, "_work_type", s._numba_type_)
        return s


REFINE_PIECES = 96   # pieces the energy refinement of one step keeps at most (solvers.fastenergystep)


def energy_work(n_outputs: int = -1, shape_contacts: bool = False) -> tuple:
    """Slot 53 of the work arrays: the energy bookkeeping of a compiled run (solvers.fastenergy, the step
    loop's in solvers.fastenergystep): 0 [on (1.0) or off (0.0), dissipation power P [W], applied loads' power
    [W]] of the last loads evaluation, 1 flags [shape-contact records overflowed, the step refined, its pieces] (int64),
    2 the powers at the state of the step's f (2,), 3 the stage powers (16, 2), 4 z = [D, W] [J] since the
    run's start at the step's start, 5 z at its end, 6 z's dense output coefficients (7, 2), 7 scratch (2,), 8 z at each output
    (n_outputs, 2), 9 the shape contacts' point records (force_elements.shape_contact.MAX_POINTS, NREC) and
    10 their count (1,) (int64), 11 the refinement's pieces (REFINE_PIECES, 23), 12 its scratch (3, 2, 9), 13 [the
    largest kinetic energy at a step's end [J]] (solvers.fastenergystep). Off (n_outputs < 0): empty outputs and records."""
    from ..solvers.fastcontact import NREC
    from .force_elements.shape_contact import MAX_POINTS
    on = n_outputs >= 0
    z = np.zeros
    return (np.array([1.0 if on else 0.0, 0.0, 0.0]), z(3, np.int64), z(2), z((16, 2)), z(2), z(2), z((7, 2)),
            z(2), z((max(n_outputs, 0), 2)), z((MAX_POINTS if on and shape_contacts else 0, NREC)),
            z(1, np.int64), z((REFINE_PIECES, 23)), z((3, 2, 9)), z(1))


def _coord_work(cm, nf) -> tuple:
    """Work of solvers.treecoord: x, stack, X, X', A (nt), f, gamma, nu (m), Minv A^T (m, nj), S (m, m),
    lambda, b (m), a joint-state derivative (2 nj), tau (nj), zero loads (nf, 6), driver values (m, 3), the
    LU row swaps of S (m,)."""
    co = cm.coords or jointtree.empty_coords()
    m, nt = len(co[3]) - 1, len(co[0])
    nj = int(np.count_nonzero(cm.tree[7] >= 0)) if m else 0
    width = int(np.max(np.diff(co[3]))) if m else 0
    z = np.zeros
    return (z(1 + width), z(cm.coord_stack), z(nt), z(nt), z(nt), z(m), z(m), z(m), z((m, nj)), z((m, m)), z(m),
            z(m), z(2 * nj), z(nj), z((nf, 6)), z((m, 3)), z(m, np.int64))


def _friction(sys) -> tuple:
    """The joint friction elements of `sys` (its lock rows' owners, in the order of sys.switched) for
    solvers.fastfriction (layout there): lock rows, joint rows, frames, axis and joint point, parameters."""
    from .force_elements.friction_kkt import term_weights
    els = [] if sys is None else [sys.model.forces[n] for n in sys.switched]
    k = len(els)
    width = max([len(sys.owner_rows[e.joint.name]) for e in els], default=1)
    lock, jrows = np.zeros(k, np.int64), -np.ones((k, width), np.int64)
    fid, vec, par = np.zeros((k, 2), np.int64), np.zeros((k, 2, 3)), np.zeros((k, 8))
    for i, e in enumerate(els):
        g, jr = sys.geoms[e.joint.name], sys.owner_rows[e.joint.name]
        b, s_b = (g.bj, g.s_j) if g.bj != 0 else (g.bi, g.s_i)
        lock[i] = sys.owner_rows[e.name][0]
        jrows[i, :len(jr)] = jr
        fid[i] = (b, g.bi)
        vec[i] = (g.h_i, s_b)
        par[i] = (e.mu_static, e.mu_dynamic, e.preload, *term_weights(e), float(bool(sys.frame_rigid[b])))
    return lock, jrows, fid, vec, par


def _friction_work(fc, nf, nc, nv) -> tuple:
    """Work of solvers.fastfriction (layout there) for the packed elements fc."""
    k = len(fc[0])
    z = np.zeros
    return (np.zeros(k, np.int64), z(k), z(k), z((k, nf, 6)), z((k, nc)), z((nf, 6)), z(nc), z((k, k)), z(k), z(k),
            z(k), z((k, 4, 3)), z(nv), z(nc), z((nf, 6)), np.zeros(2, np.int64), z(k), z((3, 3)), z(k), z(k),
            np.full(k, -1, np.int64), z((k, k)), z(k), z((k, k)), z((k, k)), np.zeros(k, np.int64),
            np.zeros(k, np.int64), np.zeros(k, np.int64), z((k, k + 1, 3, 3)), z((k, k)))


def _contacts(sys) -> tuple:
    """The model's contacts for `fastloads.contacts_kernel`: frames (i, j) (n, 2), kind (n,) (0 sphere-sphere,
    1 plane on i and sphere on j, 2 sphere on i and plane on j), shape points s_B (n, 2, 3) [m, body axes],
    the plane's normal (n, 3) [body axes] and (radius_i, radius_j, stiffness, exponent, damping,
    penetration, mu, friction_velocity) (n, 8) (SI; a plane's radius 0)."""
    rows = []
    for e in sys.model.forces.values():
        if type(e) is not Contact:
            continue
        si, sj = e.shape_i, e.shape_j
        kind = 0 if si.kind == sj.kind == "sphere" else (1 if sj.kind == "sphere" else 2)
        plane = None if kind == 0 else (si if kind == 1 else sj)
        rows.append(((sys.fid[si.body], sys.fid[sj.body]), kind, (si.s_B, sj.s_B),
                     np.zeros(3) if plane is None else plane.n_B,
                     (si.radius, sj.radius, e.stiffness, e.exponent, e.damping, e.penetration, e.mu,
                      e.friction_velocity)))
    n = len(rows)
    arr = lambda k, shape, dt=float: np.array([r[k] for r in rows], dtype=dt).reshape(shape)  # noqa: E731
    return (arr(0, (n, 2), np.int64), arr(1, (n,), np.int64), arr(2, (n, 2, 3)), arr(3, (n, 3)), arr(4, (n, 8)))


def _shape_contacts(sys, skip) -> tuple:
    """The model's shape contacts (model.contacts.ShapeContact, but those named in `skip`) for
    `fastcontact.shape_contacts`: geometry.pack.pack_contacts (with its empty record buffer and counter)."""
    from ..geometry.pack import empty_contacts, pack_contacts
    elems = [] if sys is None else [e for e in sys.model.forces.values()
                                    if type(e) is ShapeContact and e.name not in skip]
    return pack_contacts(sys, elems) if elems else empty_contacts()


def _singular_masses(M6) -> bool:
    """True when a body's 6x6 mass matrix (stack (n, 6, 6)) has an eigenvalue <= 1e-12 of its largest
    entry (one batched eigvalsh)."""
    if not len(M6):
        return False
    ev = np.linalg.eigvalsh(M6)
    return bool(np.any(ev.min(axis=1) <= 1e-12 * np.maximum(np.abs(M6).max(axis=(1, 2)), 1e-300)))


def _driver_programs(fns):
    """Packed value/d1/d2 programs of every driver function, the indices of the drivers that have
    none (Python callables, integrals without a closed form): their programs are zeros and the kernels
    call them back (solvers.pyloads writes their values over the programs' at every evaluation), and
    (driver index, input or anchor name, index into the packed constants) of each constant of a driver
    reading model inputs (model.input_drivers; mbdsim.Simulator writes them between steps)."""
    if not fns:
        return (np.zeros((0, 2), np.int64), np.zeros(0), np.zeros(0), np.zeros(0, np.int64), np.zeros(0, np.int64),
                4, (), ())
    try:
        from . import exprvm
    except ImportError:
        raise NotCompiled("the expression compiler (system.exprvm) is not available") from None
    from .force_elements.friction import StickSlip
    progs, called, slots = [], [], []
    for d, fn in enumerate(fns):
        sym = getattr(fn, "symbolic", None)
        if isinstance(fn, StickSlip):   # a friction lock row: target 0, phi is the joint coordinate itself
            progs.extend((exprvm.constant_program(0.0),) * 3)
            continue
        if sym is not None:   # a driver reading model inputs: inputs and anchors as constants (written later)
            p = []
            for node in (sym.value, sym.d1, sym.d2):
                found = []
                p.append(exprloads_pack._compile(node, {"t": 0}, sym.constants, found))
                base = sum(len(q.consts) for q in progs) + sum(len(q.consts) for q in p[:-1])
                slots.extend((d, name, base + k) for k, name in found)
        else:
            p = exprvm.time_programs(fn)
        if p is None:
            called.append(d)
            p = (exprvm.constant_program(0.0),) * 3
        progs.extend(p)
    pk = exprvm.pack(progs)
    return pk.code, pk.consts, pk.tables, pk.start, pk.end, int(pk.stack_size), tuple(called), tuple(slots)


def python_loads(sys) -> tuple:
    """Names of the force elements whose value is a Python callable (t, state): a Force or Torque given as
    one callable, an expression vector with a callable component, a line or joint force with a callable
    magnitude/value. The compiled kernels call them back (solvers.pyloads) instead of packing them."""
    out = []
    for e in sys.model.forces.values():
        v = getattr(e, "force", getattr(e, "torque", getattr(e, "magnitude", getattr(e, "value", None))))
        parts = getattr(v, "components", (v,))
        if isinstance(e, (Force, Torque) + exprloads_pack.LOAD_TYPES) and any(callable(c) for c in parts):
            out.append(e.name)
    return tuple(out)


def _called_back(sys, mode, tree, state) -> tuple:
    """Names of every force element the kernels call back through its Python evaluator (solvers.pyloads)
    instead of packing it: the Python callables (`python_loads`), the expression loads, torsion springs and
    stops that cannot be packed in this formulation (joint angles of closed loops, continued beyond +-pi:
    the callback continues them), and element types the kernels do not have. Joint friction is not among
    them (its slip loads depend on the multipliers: the Python path)."""
    out = list(python_loads(sys))
    for e in sys.model.forces.values():
        if e.name in out:
            continue
        if isinstance(e, exprloads_pack.EXPR_TYPES):
            try:
                exprloads_pack.pack(sys, [e], mode, tree, state, ())
            except NotCompiled:
                out.append(e.name)
        elif not isinstance(e, (Force, Torque, Bushing, Contact, SpringDamper, ShapeContact)):
            from .force_elements import evaluator
            if not getattr(evaluator(e), "needs_lambda", False):
                out.append(e.name)
    return tuple(out)


def _loads(sys, skip=()):
    """Constant point forces and torques, spring-dampers and bushings as arrays (expression loads, torsion
    springs and stops are packed by exprloads_pack, contacts by `_contacts`, the elements named in `skip`
    are called back: `_called_back`); NotCompiled for anything else."""
    pf, sp, bu = [], [], []
    for e in sys.model.forces.values():
        if isinstance(e, exprloads_pack.EXPR_TYPES) or e.name in skip:
            continue   # packed by exprloads_pack, or called back (solvers.pyloads)
        if isinstance(e, (Force, Torque)):
            vec = e.force if isinstance(e, Force) else e.torque
            ff, R = (0, np.eye(3)) if e.frame is None else (lambda x: (x[0], x[2]))(locate(sys, e.frame))
            s = e.s_B if isinstance(e, Force) else np.zeros(3)
            pf.append((sys.fid[e.body], s, np.asarray(vec, float), ff, R, isinstance(e, Torque)))
        elif type(e) is Bushing:
            mi, mj = e.marker_i, e.marker_j
            bu.append(((sys.fid[mi.body], sys.fid[mj.body]), (mi.s_B, mj.s_B), (mi.R_BM, mj.R_BM),
                       e.stiffness, e.damping, e.preload))
        elif type(e) is Contact or type(e) is ShapeContact or type(e) is JointFriction:
            continue   # packed by _contacts / _shape_contacts / _friction
        elif type(e) is SpringDamper:
            sp.append(((sys.fid[e.marker_i.body], sys.fid[e.marker_j.body]),
                       (e.marker_i.s_B, e.marker_j.s_B), (e.stiffness, e.damping, e.free_length, e.preload)))
        else:
            raise NotCompiled(f"force element '{e.name}' ({type(e).__name__}) is not compiled yet")
    arr = lambda x, shape, dt=float: np.array(x, dtype=dt).reshape(shape) if x else np.zeros(shape, dt)  # noqa: E731
    n, m, nb = len(pf), len(sp), len(bu)
    bushings = (arr([b[0] for b in bu], (nb, 2), np.int64), arr([b[1] for b in bu], (nb, 2, 3)),
                arr([b[2] for b in bu], (nb, 2, 3, 3)), arr([b[3] for b in bu], (nb, 6)),
                arr([b[4] for b in bu], (nb, 6)), arr([b[5] for b in bu], (nb, 6)))
    return bushings, (arr([p[0] for p in pf], (n,), np.int64), arr([p[1] for p in pf], (n, 3)),
            arr([p[2] for p in pf], (n, 3)), arr([p[3] for p in pf], (n,), np.int64),
            arr([p[4] for p in pf], (n, 3, 3)), arr([p[5] for p in pf], (n,), np.bool_),
            arr([p[0] for p in sp], (m, 2), np.int64), arr([p[1] for p in sp], (m, 2, 3)),
            arr([p[2] for p in sp], (m, 4)))


def _callable_curves(sys) -> bool:
    """Whether a point-on-curve constraint has a Python-callable curve (tabulated to the run's tolerance)."""
    from ..model.curves import Spline
    return any(not isinstance(pc.curve, Spline) and getattr(pc.curve, "expressions", None) is None
               for pc in getattr(sys.model, "path_constraints", {}).values())


def compile_system(sys, rows, state=None, friction=False, tol=None) -> CompiledModel:
    """CompiledModel of System `sys` with independent constraint rows `rows`; NotCompiled if unsupported.
    With the assembled state=(q, v) a tree of one-degree-of-freedom joints gets its joint-coordinate
    model (system.jointtree; dims[5] = 1: integrated by the articulated-body algorithm).  Joint friction
    (lock rows) only with `friction` (the caller runs its stick/slip events: solvers.compiled_run), in
    absolute coordinates.  Kept in sys.derived for the same rows, state and flag (a System reused for an
    unchanged Model compiles once). tol = (rtol, atol) of the run: the tolerance of the tables of
    Python-callable point-on-curve curves (system.pathtable; part of the key only for such a model)."""
    rows = np.asarray(rows, dtype=np.int64)
    tol = tuple(tol) if tol is not None and _callable_curves(sys) else None
    key = (rows.tobytes(), None if state is None else tuple(np.asarray(x, float).tobytes() for x in state),
           bool(friction), tol)
    kept = sys.derived.get("compiled")
    if kept is not None and kept[0] == key:
        return kept[1]
    cm = _compile_system(sys, rows, None if friction and len(sys.lock_rows) else state, friction, tol)
    sys.derived["compiled"] = (key, cm)
    return cm


def _compile_system(sys, rows, state, friction=False, tol=None) -> CompiledModel:
    nf = sys.nbody + 1
    rows = np.asarray(rows, dtype=np.int64)
    paths = len(getattr(sys.model, "path_constraints", {})) > 0   # (absolute coordinates: solvers.pathcoord)
    mode, tree = (0, jointtree.empty_arrays(nf)) if state is None or not USE_TREE or paths else \
        jointtree.tree_arrays(sys, rows, *state)
    coords, cstack = jointtree.coord_arrays(sys, tree, *state) if mode == 1 else (jointtree.empty_coords(), 4)
    tree_coords = mode == 1 and len(coords[3]) > 1
    if tree_coords:   # couplers on a tree: solved in joint coordinates (solvers.treecoord);
        rows = rows[~np.isin(rows, jointtree.coord_rows(sys))]   # the absolute solve of the outputs skips them
    elif getattr(sys, "not_compiled", None):   # issue 11: rows the kernels do not evaluate, callable sensors
        raise NotCompiled("not compiled yet: " + "; ".join(sys.not_compiled))
    if len(sys.lock_rows) and not friction:
        names = ", ".join(repr(n) for n in getattr(sys, "switched", {}))   # issue 29: docs/theory.md 12c
        raise NotCompiled(f"joint friction (stick/slip) {names}: compiled with its mode events in the step loops "
                          "of mb.simulate (solvers.compiled_run, radau_run, hht_run), which compile with "
                          "friction=True; this compilation is without it")
    M6 = np.zeros((nf, 6, 6))
    M6[:, range(6), range(6)] = 1.0
    M6[1:, range(3), range(3)] = sys.mass[1:, None]
    rig = np.flatnonzero(sys.frame_rigid)
    M6[rig, 3:, 3:] = sys.inertia_B[rig]
    packed = sys.derived.get("packed")   # the rows as system.equations packed them, else packed here
    if packed is None:
        packed = sys.derived["packed"] = packing.pack_rows(sys)
    kind, bi, bj, V, par, drv, fns = packed
    kind, bi, bj, drv = kind.copy(), bi.copy(), bj.copy(), drv.copy()
    lc, lstack = (loopcoords.empty(), 4) if tree_coords else loopcoords.pack(sys, bi, bj)
    if len(lc[0]):   # couplers in absolute coordinates (issue 29): the link rows are not solved for, the
        lc = loopcoords.only_wide(lc, rows)   # wide rows (3+ bodies) bordered on the others (solvers.loopcoord)
        rows = rows[~np.isin(rows, np.concatenate([loopcoords.link_rows(sys), loopcoords.wide_rows(lc)]))]
    pc, pstack = pathcoords.pack(sys, *(tol or ())) if paths else (pathcoords.empty(), 4)
    if paths:        # point-on-curve: the tangential rows are residuals only
        rows = rows[~np.isin(rows, pathcoords.tangent_rows(sys))]
    code, consts, tables, start, end, stack, pyd, dslots = _driver_programs(fns)
    dense = int(_singular_masses(M6[1:]))
    if not dense and mode == 0 and len(rows) == sys.nv <= SQUARE_MAX:
        dense = 2   # zero DOF: the independent rows' Jacobian is square (solvers.kkt_square)
    pyl = _called_back(sys, mode, tree, state)
    bushings, loads = _loads(sys, pyl)
    exl = [e for e in sys.model.forces.values() if isinstance(e, exprloads_pack.EXPR_TYPES) and e.name not in pyl]
    sensors = list(getattr(sys.model, "sensors", {}).values())   # expression sensors (callables: not_compiled)
    input_slots = []
    ex, ex_stack = exprloads_pack.pack(sys, exl, mode, tree, state, sensors, input_slots, switches=True) \
        if exl or sensors or len(_contacts(sys)[1]) else (exprloads_pack.empty(), 4)
    topo = system_topology(sys, rows)
    return CompiledModel(sys.r_idx.astype(np.int64), sys.p_idx.astype(np.int64).reshape(-1, 4),
                         sys.rd_idx.astype(np.int64), sys.w_idx.astype(np.int64).reshape(-1, 3),
                         sys.rigid_fid.astype(np.int64), sys.frame_v_adr.astype(np.int64),
                         sys.frame_rigid.astype(np.bool_), M6, np.asarray(sys.model.gravity, float),
                         sys.mass.astype(float), sys.inertia_B.astype(float), kind, bi, bj,
                         V, par, drv, code, consts, tables, start, end, *loads,
                         topo, np.array([sys.nq, sys.nv, sys.nc, nf, dense, mode], np.int64),
                         np.sort(rows), stack, bushings, tree, ex, ex_stack, _contacts(sys), _candidates(sys, topo, loopcoords.wide_rows(lc)), pyl, pyd,
                         tuple(input_slots), dslots, _shape_contacts(sys, pyl), coords, cstack, lc, lstack, pc, pstack,
                         _friction(sys if len(sys.lock_rows) else None))


def _candidates(sys, topo, wide=()) -> np.ndarray:
    """All loop rows of the spanning tree (`topology._full_topology`) when `topo`, the topology of the
    selected rows, has the same tree rows (the tree-first selection of system.rows.independent_rows),
    else the selected loop rows only (no re-selection); never the wide coupler rows `wide` (bordered)."""
    from .topology import _full_topology
    full = _full_topology(sys)
    if full is None or not np.array_equal(np.sort(full.blk_rows), np.sort(topo.blk_rows)):
        return np.asarray(topo.loop_rows, dtype=np.int64).copy()
    loop = np.asarray(full.loop_rows, dtype=np.int64)
    skip = np.concatenate([loopcoords.link_rows(sys), pathcoords.tangent_rows(sys),   # never solved for
                           np.asarray(wide, dtype=np.int64)])
    return loop[~np.isin(loop, skip)].copy()
