"""MJCF import: `from_mjcf(path, ...)` builds an ordinary mbdsim Model from a MuJoCo model file.

The file is checked by the hardened reader (mbdsim.importers.mjcf_check) and compiled by MuJoCo's own
compiler (`mujoco.MjModel`, an optional dependency: pip install "mbdsim[import]"), so that <default>
classes, geom-derived masses and inertias (density, box/sphere/capsule/cylinder/ellipsoid/mesh) and
frames are exactly MuJoCo's.  Mapping (docs/import.md has the table):
  body (+ bodies welded to it)   -> one body: mass properties merged, axes = the body frame
  hinge / slide / ball           -> revolute / translational / spherical joint (several joints in one
                                    body: a chain through massless bodies)
  free                           -> no joint (a free body)
  ref                            -> the model is drawn at qpos0, so a joint coordinate is q - ref
  stiffness, springref, damping  -> torsion spring / joint force (hinge, slide), bushing (ball)
  armature                       -> a massless ground rotor (inertia = armature) coupled 1:1 to the joint
  range (limited)                -> compliant stop;  frictionloss -> Coulomb joint friction
  equality joint / connect / weld-> coupler or user constraint / spherical joint / fixed joint (exact)
  motor actuator                 -> joint force gear * gain * ctrl (ctrl of the keyframe, else 0)
  gravity, keyframe              -> Model gravity; the initial state
  geoms, contact pairs           -> with collision=True: contact shapes and IMPACT contacts (solref/solimp
                                    mapped as in importers.collision.mujoco_impact)
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, ModelFileError
from ._common import (FRICTION_PIN_RADIUS, STOP_DAMPING, STOP_EXPONENT, STOP_PENETRATION, STOP_STIFFNESS,
                      MassPart, Names, VisualShape, finish, is_identifier, merge_mass)
from .mjcf_check import check_file, compile_error

FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3
GEOM_KIND = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh"}


def from_mjcf(path, initial_displacement: dict | None = None, initial_velocity: dict | None = None,
              keyframe: int | str | None = None, collision: bool = False, contact: dict | None = None):
    """Build a Model from a MuJoCo MJCF file (SI units; ground = MuJoCo's world frame).

    The initial state is the keyframe `keyframe` (index or name; default: the file's first keyframe if it
    has one, else qpos0; False: qpos0), then `initial_displacement` / `initial_velocity` {joint name:
    value} override hinge [rad, rad/s] and slide [m, m/s] joints, in MuJoCo's qpos / qvel convention.
    Joint coordinates (Result.joint_coordinate) are q - ref (the model is drawn at qpos0).  collision:
    geoms that can collide (contype/conaffinity) become contact shapes (a plane geom an mb.Plane, a mesh
    the convex hull of its vertices) and every pair MuJoCo would collide (bitmasks, parent-child and
    <exclude> filters, <pair> elements) an IMPACT contact mapped from solref/solimp
    (importers.collision.mujoco_impact; `contact`, a dict of Model.add_contact arguments, overrides the
    mapped values).  Returns a Model
    whose `import_notes` lists what was approximated and `visuals` the geoms; errors are ModelFileError
    naming the file, line and element."""
    try:
        import mujoco
    except ImportError:
        raise ModelFileError("from_mjcf", "path", "importing MJCF needs MuJoCo's compiler: pip install mujoco "
                             "(or mbdsim[import])", str(path)) from None
    doc, index, notes = check_file(path)
    try:
        mj = mujoco.MjModel.from_xml_path(str(path))
    except Exception as exc:   # noqa: BLE001 - MuJoCo raises ValueError with its parser's message
        raise compile_error(exc, doc.source, index) from None
    b = _Builder(mujoco, mj, doc.source, index, notes)
    b.model_name = doc.root.get("model") or "mjcf"
    b.collision, b.contact = collision, contact
    return b.build(initial_displacement, initial_velocity, keyframe)


class _Builder:
    """One import: the compiled MjModel -> an mbdsim Model (see the module docstring)."""

    def __init__(self, mujoco, mj, source, index, notes):
        self.mujoco, self.mj, self.source, self.index, self.notes = mujoco, mj, source, index, notes
        self.names = Names(notes)
        self.joint_of: dict = {}    # MuJoCo joint id -> model Joint
        self.body_of: dict = {}     # MuJoCo body id -> model Body

    # ------------------------------------------------------------------ helpers
    def name(self, obj, i) -> str | None:
        return self.mujoco.mj_id2name(self.mj, getattr(self.mujoco.mjtObj, obj), i) or None

    def error(self, tag, name, field, message) -> ModelFileError:
        src, line = self.index.get((tag, name), (self.source, None))
        return ModelFileError(f"{tag} '{name}'" if name else tag, field, message, src, line)

    def jname(self, j) -> str:
        return self.name("mjOBJ_JOINT", j) or f"joint_{j}"

    # ------------------------------------------------------------------ the build
    def build(self, init_q, init_v, keyframe):
        from ..model.model import Model
        mj, mujoco = self.mj, self.mujoco
        q_init, v_init, ctrl = self.initial_state(keyframe, init_q, init_v)
        q_build = mj.qpos0.copy()
        for j in range(mj.njnt):
            if mj.jnt_type[j] == FREE:
                a = mj.jnt_qposadr[j]
                q_build[a:a + 7] = q_init[a:a + 7]
        self.data = d = mujoco.MjData(mj)
        d.qpos[:] = q_build
        mujoco.mj_kinematics(mj, d)
        disabled = mj.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_GRAVITY)
        self.model = Model(self.model_name, gravity=(0, 0, 0) if disabled else mj.opt.gravity)
        self.add_bodies()
        for body in range(1, mj.nbody):
            self.add_body_joints(body, q_init, v_init)
        self.add_equalities()
        self.add_actuators(ctrl)
        self.add_sites()
        visuals = self.visuals()
        finish(self.model, self.notes, visuals, self.source, (lambda: self.collide(visuals))
               if getattr(self, "collision", False) else None)
        return self.model

    def collide(self, visuals) -> None:
        """Contact shapes of the collidable geoms and their contacts (importers.collision)."""
        import mbdsim as mb
        from .collision import mjcf_contacts, place
        mj, d = self.mj, self.data
        drawn = {v.name: (k, v) for k, v in enumerate(visuals)}
        shape_of = {}
        paired = {int(g) for g in mj.pair_geom1[:mj.npair]} | {int(g) for g in mj.pair_geom2[:mj.npair]}
        for g in range(mj.ngeom):
            if not (mj.geom_contype[g] or mj.geom_conaffinity[g] or g in paired):
                continue
            body = self.body_of[int(mj.geom_bodyid[g])]
            label = self.name("mjOBJ_GEOM", g) or f"geom_{g}"
            R = d.geom_xmat[g].reshape(3, 3)
            if mj.geom_type[g] == 0:   # an (infinite, for collision) plane: its z axis is the normal
                shape_of[g] = mb.Plane(body, d.geom_xpos[g].copy(), R[:, 2].copy())
                continue
            k, v = drawn.get(label, (None, None))
            if v is None:
                self.notes.append(f"geom {label!r}: {int(mj.geom_type[g])} geoms do not collide in mbdsim")
                continue
            hull = None
            if v.kind == "mesh":   # MuJoCo collides a mesh as its convex hull
                m = int(mj.geom_dataid[g])
                a, n = int(mj.mesh_vertadr[m]), int(mj.mesh_vertnum[m])
                hull = mb.ConvexMesh(np.asarray(mj.mesh_vert[a:a + n], float))
            shape = place(self.model, v, f"hull_{k}" if hull is not None else f"visual_{k}", self.notes, hull)
            if shape is not None:
                shape_of[g] = shape
        mjcf_contacts(self, shape_of, self.contact)

    def initial_state(self, keyframe, init_q, init_v):
        mj = self.mj
        q, v, ctrl = mj.qpos0.copy(), np.zeros(mj.nv), np.zeros(mj.nu)
        k = None
        if keyframe is None and mj.nkey > 0:
            k = 0
        elif isinstance(keyframe, str):
            k = self.mujoco.mj_name2id(mj, self.mujoco.mjtObj.mjOBJ_KEY, keyframe)
            if k < 0:
                raise ModelFileError("from_mjcf", "keyframe", f"no keyframe named {keyframe!r}", self.source)
        elif keyframe is not None and keyframe is not False:
            if not isinstance(keyframe, int) or not 0 <= keyframe < mj.nkey:
                raise ModelFileError("from_mjcf", "keyframe", f"expected a keyframe index below {mj.nkey} or a "
                                     f"name, got {keyframe!r}", self.source)
            k = keyframe
        if k is not None:
            q, v, ctrl = mj.key_qpos[k].copy(), mj.key_qvel[k].copy(), mj.key_ctrl[k].copy()
        for fld, given, target, adr in (("initial_displacement", init_q, q, mj.jnt_qposadr),
                                        ("initial_velocity", init_v, v, mj.jnt_dofadr)):
            if given is None:
                continue
            if not isinstance(given, dict):
                raise ModelFileError("from_mjcf", fld, "expected a dict {joint name: value}", self.source)
            for key, val in given.items():
                j = self.mujoco.mj_name2id(mj, self.mujoco.mjtObj.mjOBJ_JOINT, str(key))
                if j < 0 or mj.jnt_type[j] not in (HINGE, SLIDE):
                    raise ModelFileError("from_mjcf", fld, f"{key!r} is not a hinge or slide joint of the file",
                                         self.source)
                try:
                    target[adr[j]] = float(val)
                except (TypeError, ValueError):
                    raise ModelFileError("from_mjcf", fld, f"{key!r}: expected a number, got {val!r}",
                                         self.source) from None
        return q, v, ctrl

    def add_bodies(self) -> None:
        """One model body per weld group (a body and the bodies without joints under it)."""
        mj, d, model = self.mj, self.data, self.model
        groups: dict = {}
        for b in range(1, mj.nbody):
            groups.setdefault(int(mj.body_weldid[b]), []).append(b)
        self.body_of[0] = model.ground
        for head, members in groups.items():
            if head == 0:
                for b in members:
                    self.body_of[b] = model.ground
                if any(mj.body_mass[b] > 0 for b in members):
                    self.notes.append("bodies welded to the world do not move: their mass does not enter the dynamics")
                continue
            parts = [MassPart(float(mj.body_mass[b]), d.xipos[b].copy(),
                              d.ximat[b].reshape(3, 3) @ np.diag(mj.body_inertia[b]) @ d.ximat[b].reshape(3, 3).T)
                     for b in members]
            mp = merge_mass(parts)
            R = d.xmat[head].reshape(3, 3).copy()
            name = self.names.take(self.name("mjOBJ_BODY", head), "body")
            pos = mp.com if mp.mass > 0 else d.xpos[head].copy()
            body = model.add_body(name, mass=mp.mass, inertia=R.T @ mp.inertia @ R, position=pos, orientation=R)
            for b in members:
                self.body_of[b] = body
                if b != head and self.name("mjOBJ_BODY", b):
                    bname = self.names.take(self.name("mjOBJ_BODY", b), "marker")
                    body.add_marker(bname, d.xpos[b].copy(), d.xmat[b].reshape(3, 3).copy())

    def add_body_joints(self, b, q_init, v_init) -> None:
        mj, d = self.mj, self.data
        joints = list(range(mj.body_jntadr[b], mj.body_jntadr[b] + mj.body_jntnum[b]))
        if not joints:
            return
        child = self.body_of[b]
        if mj.jnt_type[joints[0]] == FREE:
            self.free_body(b, joints[0], v_init)
            return
        parent = self.body_of[int(mj.body_parentid[b])]
        for k, j in enumerate(joints):
            if k < len(joints) - 1:   # a chain through massless bodies, one per joint but the last
                tgt = self.model.add_body(self.names.take(f"{child.name}__{self.jname(j)}", "body"), mass=0.0,
                                          position=d.xpos[b].copy(), orientation=d.xmat[b].reshape(3, 3).copy())
                self.notes.append(f"body {child.name!r} has {len(joints)} joints: chained through massless "
                                  f"body {tgt.name!r}")
            else:
                tgt = child
            self.add_joint(j, parent, tgt, q_init, v_init)
            parent = tgt

    def free_body(self, b, j, v_init) -> None:
        mj, d = self.mj, self.data
        body = self.body_of[b]
        a = mj.jnt_dofadr[j]
        R = d.xmat[b].reshape(3, 3)
        w = R @ v_init[a + 3:a + 6]
        body.velocity = v_init[a:a + 3] + np.cross(w, body.position - d.xpos[b])
        body.angular_velocity = w
        body.velocity_given = body.angular_velocity_given = True
        if mj.dof_damping[a:a + 6].any() or mj.jnt_stiffness[j] or mj.dof_armature[a:a + 6].any():
            raise self.error("joint", self.name("mjOBJ_JOINT", j), "damping",
                             "stiffness, damping and armature on a free joint are not supported")

    def add_joint(self, j, parent, child, q_init, v_init) -> None:
        mj, d, model = self.mj, self.data, self.model
        typ, qa, va = int(mj.jnt_type[j]), mj.jnt_qposadr[j], mj.jnt_dofadr[j]
        fname = self.name("mjOBJ_JOINT", j)
        name = self.names.take(fname or f"joint_{j}", "joint")
        point, axis = d.xanchor[j].copy(), d.xaxis[j].copy()
        try:
            if typ in (HINGE, SLIDE):
                x0 = float(q_init[qa] - mj.qpos0[qa])
                jt = (model.add_revolute if typ == HINGE else model.add_translational)(
                    name, parent, child, point, axis, initial_displacement=x0, initial_velocity=float(v_init[va]))
            else:
                x0, w0 = self.ball_initial(j, q_init, v_init)
                jt = model.add_spherical(name, parent, child, point, initial_displacement=x0, initial_velocity=w0)
            self.joint_of[j] = jt
            self.passive(j, jt, typ, qa, va)
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.error("joint", fname, exc.field, str(exc)) from None

    def ball_initial(self, j, q_init, v_init):
        """Rotation vector from as drawn and relative angular velocity, in the parent body's axes."""
        from scipy.spatial.transform import Rotation
        mj = self.mj
        qa, va, b = mj.jnt_qposadr[j], mj.jnt_dofadr[j], int(mj.jnt_bodyid[j])
        wxyz = lambda q: Rotation.from_quat([q[1], q[2], q[3], q[0]])   # noqa: E731 - MuJoCo is w-first
        Rb = wxyz(mj.body_quat[b])
        rel = Rb * wxyz(q_init[qa:qa + 4]) * wxyz(mj.qpos0[qa:qa + 4]).inv() * Rb.inv()
        w = (Rb * wxyz(q_init[qa:qa + 4])).apply(v_init[va:va + 3])
        return rel.as_rotvec(), w

    def passive(self, j, jt, typ, qa, va) -> None:
        """Springs, dampers, armature, limits and friction loss of MuJoCo joint j on model joint jt."""
        mj, model = self.mj, self.model
        k, c = float(mj.jnt_stiffness[j]), float(mj.dof_damping[va])
        x_free = float(mj.qpos_spring[qa] - mj.qpos0[qa])
        if typ == BALL:
            if mj.jnt_limited[j]:
                self.notes.append(f"ball joint {jt.name!r}: its cone range is not imported")
            if k or c:
                if not np.allclose(mj.qpos_spring[qa:qa + 4], mj.qpos0[qa:qa + 4]):
                    raise ModelError(f"joint '{jt.name}'", "springref", "a ball joint's spring rest position "
                                     "must be its reference position")
                model.add_bushing(f"{jt.name}_spring", (jt.body_i, jt.point), (jt.body_j, jt.point),
                                  stiffness=(0, 0, 0, k, k, k), damping=(0, 0, 0, c, c, c))
            if mj.dof_armature[va:va + 3].any() or mj.dof_frictionloss[va:va + 3].any():
                raise ModelError(f"joint '{jt.name}'", "armature", "armature and frictionloss on a ball joint "
                                 "are not supported")
            return
        if k or c:
            if typ == HINGE:
                model.add_torsion_spring(f"{jt.name}_spring", jt, k, c, free_angle=x_free)
            elif is_identifier(jt.name):
                model.add_joint_force(f"{jt.name}_spring", jt, f"-({k!r})*({jt.name} - ({x_free!r}))"
                                      f" - ({c!r})*{jt.name}_dot")
            else:
                raise ModelError(f"joint '{jt.name}'", "name", "a slide spring is an expression in the joint "
                                 "coordinate, which needs a joint name that is an identifier")
        if mj.jnt_limited[j]:
            lo, hi = (float(x) - float(mj.qpos0[qa]) for x in mj.jnt_range[j])
            model.add_stop(f"{jt.name}_range", jt, lower=lo, upper=hi, stiffness=STOP_STIFFNESS,
                           exponent=STOP_EXPONENT, damping=STOP_DAMPING, penetration=STOP_PENETRATION)
            self.notes.append(f"joint {jt.name!r}: range is a compliant stop (stiffness {STOP_STIFFNESS:g})")
        if mj.dof_frictionloss[va] > 0:
            params = {"preload": float(mj.dof_frictionloss[va])}
            if typ == HINGE:
                params["pin_radius"] = FRICTION_PIN_RADIUS
            model.add_friction(f"{jt.name}_friction", jt, 1.0, 1.0, **params)
            self.notes.append(f"joint {jt.name!r}: frictionloss is Coulomb friction (stick/slip), not "
                              "MuJoCo's soft friction constraint")
        if mj.dof_armature[va] > 0:
            self.armature(jt, typ, float(mj.dof_armature[va]))

    def armature(self, jt, typ, a) -> None:
        """MuJoCo's armature adds `a` to the joint's diagonal of the mass matrix (kinetic energy a qdot^2 / 2,
        whatever the parent body does): a massless rotor of inertia a [kg m^2] on a ground revolute, coupled
        1:1 to the joint (1 rad per rad, or per m for a slide, whose armature is in kg): no gravity and no
        coupling with the parent's rotation, so it matches mj_forward's qacc exactly."""
        model = self.model
        name = self.names.take(f"{jt.name}_rotor", "body")
        rotor = model.add_body(name, mass=0.0, inertia=(a, a, a), position=jt.point)
        rj = model.add_revolute(f"{name}_joint", model.ground, rotor, jt.point, jt.axis,
                                initial_displacement=jt.initial_displacement, initial_velocity=jt.initial_velocity)
        model.add_coupler(f"{name}_coupler", jt, rj, 1.0)

    def add_equalities(self) -> None:
        from .mjcf_equality import add_equality
        for e in range(self.mj.neq):
            add_equality(self, e)

    def add_actuators(self, ctrl) -> None:
        mj = self.mj
        for u in range(mj.nu):
            name = self.name("mjOBJ_ACTUATOR", u)
            j = int(mj.actuator_trnid[u, 0])
            if mj.actuator_trntype[u] != 0 or j not in self.joint_of or mj.jnt_type[j] not in (HINGE, SLIDE):
                raise self.error("motor", name, "joint", "a motor must drive a hinge or slide joint")
            c = float(ctrl[u])
            if mj.actuator_ctrllimited[u]:
                c = float(np.clip(c, *mj.actuator_ctrlrange[u]))
            f = float(mj.actuator_gear[u, 0] * mj.actuator_gainprm[u, 0] * c)
            if mj.actuator_forcelimited[u]:
                f = float(np.clip(f, *mj.actuator_forcerange[u]))
            self.model.add_joint_force(self.names.take(name or f"actuator_{u}", "actuator"), self.joint_of[j], f)
        if mj.nu:
            self.notes.append("motor actuators are constant joint forces gear * ctrl (the keyframe's ctrl, else 0)")

    def add_sites(self) -> None:
        mj, d = self.mj, self.data
        for s in range(mj.nsite):
            name = self.name("mjOBJ_SITE", s)
            body = self.body_of[int(mj.site_bodyid[s])]
            if name and "." not in name and name not in body.markers:
                body.add_marker(name, d.site_xpos[s].copy(), d.site_xmat[s].reshape(3, 3).copy())

    def visuals(self) -> list:
        mj, d = self.mj, self.data
        out = []
        for g in range(mj.ngeom):
            kind = GEOM_KIND.get(int(mj.geom_type[g]))
            if kind is None:
                continue
            s = mj.geom_size[g]
            size = {"sphere": (s[0],), "capsule": (s[0], 2 * s[1]), "cylinder": (s[0], 2 * s[1]),
                    "ellipsoid": tuple(s), "box": tuple(2 * s), "mesh": ()}[kind]
            mesh = self.name("mjOBJ_MESH", int(mj.geom_dataid[g])) if kind == "mesh" else None
            out.append(VisualShape(self.body_of[int(mj.geom_bodyid[g])].name, kind, tuple(float(x) for x in size),
                                   d.geom_xpos[g].copy(), d.geom_xmat[g].reshape(3, 3).copy(), mesh,
                                   role="visual", name=self.name("mjOBJ_GEOM", g) or f"geom_{g}"))
        return out
