"""Engine adapters: build the same model in each engine, run it, return (seconds, trajectory, info).

Only the integration call is timed (mbdsim: ``mb.simulate`` / ``mb.kinematics``, which include
mbdsim's own assembly; MuJoCo: the ``mj_step`` loop; Exudyn: ``mbs.SolveDynamic``).  Model
construction/compilation and the conversion of engine output to the standard trajectory are not timed.
"""
from __future__ import annotations

import time
import warnings

import numpy as np

from problems import G, rz  # noqa: F401

# --------------------------------------------------------------------------- mbdsim
import mbdsim as mb


def _free_slider_crank(p, model):
    """Crank (revolute to ground), rod, slider (translational along x): a non-redundant joint set
    (spherical at the crank pin, universal at the slider) so that no engine needs redundancy handling."""
    (cc, rc, B), ph = p.positions(np.array(p.th0))
    th, z = p.th0, (0, 0, 1)
    rod_J = lambda L: (p.m * 0.02 ** 2 / 6, p.m * L * L / 12, p.m * L * L / 12)  # noqa: E731
    crank = model.add_body("crank", p.m, inertia=rod_J(p.r), position=cc, orientation=rz(th))
    rod = model.add_body("rod", p.m, inertia=rod_J(p.l), position=rc, orientation=rz(float(ph)))
    slider = model.add_body("slider", p.m, inertia=(1e-3, 1e-3, 1e-3), position=B)
    model.add_revolute("O", model.ground, crank, (0, 0, 0), z)
    model.add_spherical("A", crank, rod, 2 * cc)
    model.add_universal("B", rod, slider, B, axis_i=z, axis_j=(0, 1, 0))
    model.add_translational("slide", model.ground, slider, B, (1, 0, 0))
    return model, [crank, rod, slider]


def mbdsim_model(p):
    model = mb.Model(p.key, gravity=(0.0, -G, 0.0))
    if p.key == "slider_crank_free":
        return _free_slider_crank(p, model)
    if p.key == "slider_crank":
        th, ph = p.angles(np.array(0.0))
        A = p.r * np.array([np.cos(th), np.sin(th), 0.0])
        B = A + p.l * np.array([np.cos(ph), np.sin(ph), 0.0])
        I1, I2, I3 = p.m1 * p.r ** 2 / 12, p.m2 * p.l ** 2 / 12, 0.01
        crank = model.add_body("crank", p.m1, inertia=(I1 / 10, I1, I1), position=A / 2, orientation=rz(th))
        rod = model.add_body("rod", p.m2, inertia=(I2 / 10, I2, I2), position=(A + B) / 2, orientation=rz(ph))
        slider = model.add_body("slider", p.m3, inertia=(I3, I3, I3), position=B)
        z = (0, 0, 1)
        o = model.add_revolute("O", model.ground, crank, (0, 0, 0), z)
        model.add_spherical("A", crank, rod, A)                       # non-redundant joint set
        model.add_universal("B", rod, slider, B, axis_i=z, axis_j=(0, 1, 0))
        model.add_translational("slide", model.ground, slider, B, (1, 0, 0))
        model.add_motion("drive", o, displacement=p.drive)
        return model, [crank, rod, slider]
    if p.key == "heavy_top":
        top = model.add_body("top", p.m, inertia=tuple(p.J_cm), position=p.cm0(), orientation=p.R0,
                             velocity=np.cross(p.w0(), p.cm0()), angular_velocity=p.w0())
        model.add_spherical("pivot", model.ground, top, (0, 0, 0))
        return model, [top]
    bodies, prev = [], model.ground
    for k, r in enumerate(p.rods):
        b = model.add_body(f"b{k}", r.m, inertia=tuple(r.J), position=r.cm, orientation=r.R)
        if p.key == "chain":
            model.add_spherical(f"j{k}", prev, b, r.origin)
        else:
            model.add_revolute(f"j{k}", prev, b, r.origin, (0, 0, 1))
        bodies.append(b)
        prev = b
    return model, bodies


_MODELS: dict = {}   # problem key -> (mbdsim Model, bodies)


def run_mbdsim(p, method, tol):
    """method: 'auto' (the default: only rtol given), 'hht', 'dop853' (tol = rtol, atol = 1e-2 rtol) or
    'kinematics'."""
    # the model is built once per problem, outside the timing, and reused: its first call assembles and
    # compiles it, later calls reuse that (as MuJoCo's MjModel and Exudyn's Assemble, outside their timings)
    model, bodies = _MODELS[p.key] if p.key in _MODELS else _MODELS.setdefault(p.key, mbdsim_model(p))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        if method == "kinematics":
            res = mb.kinematics(model, p.t_end, output_step=p.out_dt)
        elif method == "auto":
            res = mb.simulate(model, p.t_end, output_step=p.out_dt, rtol=tol)
        else:
            res = mb.simulate(model, p.t_end, output_step=p.out_dt, method=method, rtol=tol, atol=tol * 1e-2)
        el = time.perf_counter() - t0
    if not res.success:
        return el, None, {"message": res.message}
    traj = {"t": res.time, "cm": np.stack([res.position(b) for b in bodies], 1)}
    if p.key == "chain":
        traj["ke"] = res.kinetic_energy()
        traj["energy"] = traj["ke"] + res.potential_energy()
    return el, traj, {"steps": res.stats.get("steps")}


# --------------------------------------------------------------------------- MuJoCo
try:
    import mujoco
    MUJOCO = mujoco.__version__
except Exception as exc:  # pragma: no cover
    mujoco, MUJOCO = None, f"not importable: {exc}"


def _quat(R):
    from scipy.spatial.transform import Rotation
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return f"{w:.17g} {x:.17g} {y:.17g} {z:.17g}"


def _mujoco_slider_crank_xml(p, dt):
    """Crank and rod on hinges, slider on a slide joint, the loop closed by an equality `connect`
    (MuJoCo's loop constraints are soft: solref time constant 2 dt, the stiffest it accepts)."""
    (cc, rc, B), ph = p.positions(np.array(p.th0))
    A = 2 * cc
    Jr = lambda L: f"{p.m * 0.02 ** 2 / 6:.17g} {p.m * L * L / 12:.17g} {p.m * L * L / 12:.17g}"  # noqa: E731
    return (f'<mujoco><option gravity="0 {-G} 0" integrator="RK4" timestep="{dt:.17g}">'
            f'<flag contact="disable"/></option><worldbody>'
            f'<body name="crank" quat="{_quat(rz(p.th0))}"><joint name="O" type="hinge" axis="0 0 1"/>'
            f'<inertial pos="{p.r / 2:.17g} 0 0" mass="{p.m}" diaginertia="{Jr(p.r)}"/>'
            f'<body name="rod" pos="{p.r:.17g} 0 0" quat="{_quat(rz(float(ph) - p.th0))}">'
            f'<joint name="A" type="hinge" axis="0 0 1"/>'
            f'<inertial pos="{p.l / 2:.17g} 0 0" mass="{p.m}" diaginertia="{Jr(p.l)}"/></body></body>'
            f'<body name="slider" pos="{B[0]:.17g} 0 0"><joint name="s" type="slide" axis="1 0 0"/>'
            f'<inertial pos="0 0 0" mass="{p.m}" diaginertia="1e-3 1e-3 1e-3"/></body></worldbody>'
            f'<equality><connect body1="rod" body2="slider" anchor="{p.l:.17g} 0 0" '
            f'solref="{2 * dt:.17g} 1"/></equality></mujoco>')


def mujoco_xml(p, dt):
    """Same rods, same inertias; hinge (planar) or ball (chain) joints at each rod's start, minimal coords."""
    if p.key == "slider_crank_free":
        return _mujoco_slider_crank_xml(p, dt)
    kind = "ball" if p.key == "chain" else "hinge"
    body_xml, close, Rp, op = "", "", np.eye(3), np.zeros(3)
    for k, r in enumerate(p.rods):
        pos = Rp.T @ (r.origin - op)            # in the parent body's frame
        Rrel = Rp.T @ r.R
        axis = "" if kind == "ball" else ' axis="0 0 1"'
        body_xml += (f'<body name="b{k}" pos="{pos[0]:.17g} {pos[1]:.17g} {pos[2]:.17g}" quat="{_quat(Rrel)}">'
                     f'<joint name="j{k}" type="{kind}"{axis} pos="0 0 0" damping="0" armature="0"/>'
                     f'<inertial pos="{r.L / 2:.17g} 0 0" mass="{r.m:.17g}" '
                     f'diaginertia="{r.J[0]:.17g} {r.J[1]:.17g} {r.J[2]:.17g}"/>')
        close += "</body>"
        Rp, op = r.R, r.origin
    return (f'<mujoco><option gravity="0 {-G} 0" integrator="RK4" timestep="{dt:.17g}">'
            f'<flag contact="disable" energy="enable"/></option>'
            f'<worldbody>{body_xml}{close}</worldbody></mujoco>')


def run_mujoco(p, dt):
    m = mujoco.MjModel.from_xml_string(mujoco_xml(p, dt))
    d = mujoco.MjData(m)
    n_out = int(round(p.t_end / p.out_dt))
    nstep = int(round(p.out_dt / dt))
    assert abs(nstep * dt - p.out_dt) < 1e-12 * p.out_dt + 1e-15, "timestep must divide the output step"
    qp, qv = np.empty((n_out + 1, m.nq)), np.empty((n_out + 1, m.nv))
    t0 = time.perf_counter()
    qp[0], qv[0] = d.qpos, d.qvel
    for k in range(n_out):
        mujoco.mj_step(m, d, nstep=nstep)
        qp[k + 1], qv[k + 1] = d.qpos, d.qvel
    el = time.perf_counter() - t0
    # untimed post-processing: CM positions and energy at the samples
    e = mujoco.MjData(m)
    nb = m.nbody - 1
    cm, E = np.empty((n_out + 1, nb, 3)), np.empty(n_out + 1)
    for k in range(n_out + 1):
        e.qpos[:], e.qvel[:] = qp[k], qv[k]
        mujoco.mj_forward(m, e)
        mujoco.mj_energyVel(m, e)
        cm[k] = e.xipos[1:]
        E[k] = e.energy[0] + e.energy[1]
    traj = {"t": np.linspace(0, p.t_end, n_out + 1), "cm": cm, "energy": E}
    return el, traj, {"steps": n_out * nstep}


# --------------------------------------------------------------------------- Exudyn
try:
    import exudyn as exu
    from exudyn.utilities import RigidBodyInertia, SensorBody
    EXUDYN = exu.config.Version() if hasattr(exu, "config") and hasattr(exu.config, "Version") \
        else exu.__version__
except Exception as exc:  # pragma: no cover
    exu, EXUDYN = None, f"not importable: {exc}"

EXUDYN_RHO = 0.905   # spectral radius at infinity = (1 + alpha) / (1 - alpha) of mbdsim's HHT alpha = -0.05


def run_exudyn(p, nsteps):
    """Exudyn redundant coordinates (Euler-parameter rigid bodies, index-3 generalized-alpha, fixed step)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.CreateGround()
    prev, sens = ground, []
    OV = exu.OutputVariableType
    for r in p.rods:
        b = mbs.CreateRigidBody(inertia=RigidBodyInertia(mass=r.m, inertiaTensor=np.diag(r.J)),
                                referencePosition=list(r.cm), referenceRotationMatrix=r.R,
                                gravity=[0.0, -G, 0.0])
        if p.key == "chain":
            mbs.CreateSphericalJoint(bodyNumbers=[prev, b], position=list(r.origin))
        else:
            mbs.CreateRevoluteJoint(bodyNumbers=[prev, b], position=list(r.origin), axis=[0, 0, 1])
        kinds = (OV.Position, OV.Velocity, OV.AngularVelocityLocal) if p.key == "chain" else (OV.Position,)
        sens.append([mbs.AddSensor(SensorBody(bodyNumber=b, localPosition=[0, 0, 0], storeInternal=True,
                                              outputVariableType=ov)) for ov in kinds])
        prev = b
    mbs.Assemble()
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps, ti.endTime, ti.verboseMode = int(nsteps), p.t_end, 0
    ti.generalizedAlpha.spectralRadius = EXUDYN_RHO
    # Newton tolerances: Exudyn's defaults (tightening them to 1e-12 changed errors by < 0.2 % and cost ~25 %)
    if len(p.rods) > 2:   # Exudyn's default dense solver is ~3x slower on the 10-body chain
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.solutionSettings.writeSolutionToFile = False
    s.solutionSettings.sensorsWritePeriod = p.out_dt
    s.displayComputationTime = False
    s.displayStatistics = False
    t0 = time.perf_counter()
    ok = mbs.SolveDynamic(s, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    el = time.perf_counter() - t0
    if ok is False:
        return el, None, {"message": "SolveDynamic failed"}
    data = [[mbs.GetSensorStoredData(x) for x in row] for row in sens]
    t = data[0][0][:, 0]
    n_out = int(round(p.t_end / p.out_dt))
    if len(t) != n_out + 1:      # keep the samples that fall on the output grid
        grid = np.linspace(0, p.t_end, n_out + 1)
        idx = [int(np.argmin(np.abs(t - g))) for g in grid]
        if np.max(np.abs(t[idx] - grid)) > 1e-9:
            return el, None, {"message": f"sensor times do not match the output grid ({len(t)} samples)"}
        data = [[d[idx] for d in row] for row in data]
        t = grid
    cm = np.stack([row[0][:, 1:4] for row in data], 1)
    traj = {"t": t, "cm": cm}
    if p.key == "chain":
        v = np.stack([row[1][:, 1:4] for row in data], 1)
        w = np.stack([row[2][:, 1:4] for row in data], 1)
        traj["energy"] = p.energy(cm, v, w)[0]
    return el, traj, {"steps": int(nsteps)}
