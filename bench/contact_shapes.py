"""Shape contact (issue 30) against MuJoCo on the same scenes, measured in the same run.

Scenes: a box sliding down a 30 degree incline (mu 0.3), a cylinder rolling down a 15 degree incline, a
box thrown spinning onto the floor that tumbles over edges and faces to rest (the same answer where physics
fixes one: at rest a face down with the CM a/2 over the floor, no kinetic energy; how far it travels depends
on each engine's contact model and is only reported), a pile of eight boxes dropped on the floor, an eccentric cam on a flat-faced follower (mbdsim only: the
closed-form lift).  Timed: the integration call only (mb.simulate, which includes its assembly checks; the
mj_step loop), best of `REPEATS`, after a warm-up run that compiles.  Where physics allows the same
answer, the error against the closed form is given for both engines.  Writes bench/CONTACT_RESULTS.md
and the "Shape contact" section of bench/RESULTS.md.

    PYTHONPATH=src python3 bench/contact_shapes.py            # all scenes, written
    PYTHONPATH=src python3 bench/contact_shapes.py tumble     # some (slide roll tumble pile cam), printed only
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import mbdsim as mb

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))
from sections import replace_section  # noqa: E402
REPEATS = 3
G = 9.81


def _best(fn):
    fn()
    best, out = np.inf, None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _fit_acc(t, s, t0=0.1):
    keep = t >= t0
    return 2.0 * np.polyfit(t[keep], s[keep], 2)[0]


# ----------------------------------------------------------------------------- mbdsim scenes (as the tests)
def mb_box_slide(method="dop853"):
    from test_shape_contact_plane import box_on_incline
    m, t = box_on_incline(np.radians(30), "box", None, v0=0.5, mu=0.3, friction_velocity=1e-3)
    run = lambda: mb.simulate(m, 0.5, 0.005, method=method, rtol=1e-6, monitor=False)  # noqa: E731
    sec, res = _best(run)
    ref = G * (np.sin(np.radians(30)) - 0.3 * np.cos(np.radians(30)))
    return sec, abs(_fit_acc(res.time, res.position("box") @ t) / ref - 1)


def cyl_roll_model(theta=np.radians(15)):
    """(model, downhill tangent) of a solid cylinder (r 0.05 m, 1000 kg/m^3) on a theta incline, resting
    at its static penetration."""
    r, rho = 0.05, 1000.0
    from test_shape_contact_plane import K, E, incline
    n, _, t = incline(theta)
    geo = mb.Cylinder(r, 0.1, axis="y")
    mass, _ = geo.mass_properties(rho)
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("roller", 0.0, position=n * (r - (mass * G * np.cos(theta) / (2 * K)) ** (1 / E)))
    s = b.add_shape("geo", geo, density=rho)
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), n), s, K, E, 200.0, 1e-4, mu=0.5, friction_velocity=1e-4)
    return m, t


def pile_model(a=0.1):
    """Eight boxes of side a [m] over the floor (pile_positions), all pairs in one contact."""
    m = mb.Model(gravity=(0, 0, -G))
    shapes = []
    for i, (pos, rot) in enumerate(pile_positions()):
        b = m.add_body(f"b{i}", 1.0, (a * a / 6,) * 3, position=pos, orientation=rot.as_matrix())
        shapes.append(b.add_shape("geo", mb.Box((a, a, a))))
    m.add_contact("c", [mb.Plane(m.ground, (0, 0, 0), (0, 0, 1))] + shapes, shapes, 1e5, 1.5, 50.0, 1e-3, mu=0.5,
                  friction_velocity=1e-2)
    return m


def mb_cyl_roll(method="dop853"):
    theta = np.radians(15)
    m, t = cyl_roll_model(theta)
    sec, res = _best(lambda: mb.simulate(m, 0.5, 0.005, method=method, rtol=1e-6, monitor=False))
    ref = G * np.sin(theta) / 1.5
    return sec, abs(_fit_acc(res.time, res.position("roller") @ t) / ref - 1)


def pile_positions():
    from scipy.spatial.transform import Rotation
    rng = np.random.default_rng(3)
    out = []
    for i in range(8):
        layer = i // 4
        pos = (0.18 * (i % 2) + 0.09 * layer, 0.18 * ((i // 2) % 2) + 0.09 * layer, 0.1 + 0.2 * layer)
        out.append((pos, Rotation.from_rotvec(rng.uniform(-0.4, 0.4, 3))))
    return out


def mb_pile(method="dop853"):
    m = pile_model()
    sec, res = _best(lambda: mb.simulate(m, 1.5, 0.01, method=method, rtol=1e-5, monitor=False))
    ke = float(res.kinetic_energy()[-1])
    return sec, ke


# a box thrown spinning onto the floor: it lands on a corner, tumbles over edges and faces and comes to rest
TUMBLE_A, TUMBLE_T = 0.1, 2.0
TUMBLE_POS, TUMBLE_V, TUMBLE_W = (0.0, 0.0, 0.2), (3.0, 0.0, 0.0), (1.0, 25.0, -2.0)   # [m], [m/s], [rad/s]


def tumble_rotation():
    from scipy.spatial.transform import Rotation
    return Rotation.from_rotvec((0.5, 0.3, 0.2))


def tumble_model():
    """The thrown cube (side 0.1 m, 1 kg) over the floor: IMPACT 1e5 N/m^1.5, exponent 1.5, mu 0.5 (as the
    pile); velocity and angular velocity in ground."""
    a = TUMBLE_A
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("box", 1.0, (a * a / 6,) * 3, position=TUMBLE_POS, orientation=tumble_rotation().as_matrix(),
                   velocity=TUMBLE_V, angular_velocity=TUMBLE_W)
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("geo", mb.Box((a, a, a))), 1e5, 1.5,
                  50.0, 1e-3, mu=0.5, friction_velocity=1e-2)
    return m


def rest_measures(z, R, v, w, a=TUMBLE_A):
    """What physics fixes at rest, whatever the path: the CM at a/2 over the floor less the contact's
    penetration (mbdsim's IMPACT law: (m g / (4 k))^(1/e) = 8.44e-4 m on four corners; MuJoCo: its soft
    constraint's), a face down (tilt of the nearest body axis from the vertical [deg]), no kinetic energy [J]
    of the unit-mass cube (I = a^2/6)."""
    tilt = float(np.degrees(np.arccos(min(1.0, np.max(np.abs(R[2, :]))))))
    ke = 0.5 * float(v @ v) + 0.5 * a * a / 6 * float(w @ w)
    return {"z - a/2 [m]": float(z - a / 2), "tilt [deg]": tilt, "kinetic energy [J]": ke}


def mb_tumble(method="dop853"):
    m = tumble_model()
    sec, res = _best(lambda: mb.simulate(m, TUMBLE_T, 0.01, method=method, rtol=1e-5, monitor=False))
    r = rest_measures(res.position("box")[-1, 2], res.orientation("box")[-1], res.velocity("box")[-1],
                      res.angular_velocity("box")[-1])
    r["travel [m]"] = float(res.position("box")[-1, 0] - TUMBLE_POS[0])
    return sec, r


def mb_cam(method="dop853"):
    from test_shape_contact_cam import E_CAM, cam_model, lift_off_speed
    w = 0.7 * lift_off_speed()
    m, z0 = cam_model(w)
    T = 2 * np.pi / w
    sec, res = _best(lambda: mb.simulate(m, T, T / 100, method=method, rtol=1e-8, monitor=False))
    lift = res.position("follower")[:, 2] - z0
    return sec, float(np.max(np.abs(lift - E_CAM * (1 - np.cos(w * res.time)))) / E_CAM)


# ----------------------------------------------------------------------------- MuJoCo scenes
def _mj_run(xml, T, body, dt=1e-3):
    import mujoco
    model = mujoco.MjModel.from_xml_string(xml)
    model.opt.timestep = dt

    def run():
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        n = int(round(T / dt))
        every = max(int(round(0.005 / dt)), 1)
        ts, xs = [], []
        for k in range(n + 1):
            if k % every == 0:
                ts.append(data.time)
                xs.append(data.body(body).xpos.copy() if body else data.qpos.copy())
            if k < n:
                mujoco.mj_step(model, data)
        return np.array(ts), np.array(xs), data
    return _best(run)


def mj_box_slide():
    th = 30
    xml = f"""<mujoco><option gravity="0 0 -9.81" cone="elliptic" impratio="10"/>
      <worldbody><geom type="plane" size="5 5 0.1" euler="0 {-th} 0" friction="0.3 0 0"/>
      <body name="box" pos="{-0.05 * np.sin(np.radians(th)):.6f} 0 {0.05 * np.cos(np.radians(th)):.6f}" euler="0 {-th} 0">
        <freejoint/><geom type="box" size="0.05 0.05 0.05" mass="1" friction="0.3 0 0"/></body></worldbody></mujoco>"""
    from test_shape_contact_plane import incline
    _, _, t = incline(np.radians(th))
    sec, (ts, xs, _) = _mj_run(xml, 0.5, "box")
    ref = G * (np.sin(np.radians(th)) - 0.3 * np.cos(np.radians(th)))
    # starts at rest (MuJoCo's initial velocity needs qvel; the fit from 0.1 s is the same acceleration)
    return sec, abs(_fit_acc(ts, xs @ t) / ref - 1)


def mj_cyl_roll():
    th = 15
    xml = f"""<mujoco><option gravity="0 0 -9.81" cone="elliptic" impratio="10"/>
      <worldbody><geom type="plane" size="5 5 0.1" euler="0 {-th} 0" friction="0.5 0 0"/>
      <body name="roller" pos="{-0.05 * np.sin(np.radians(th)):.6f} 0 {0.05 * np.cos(np.radians(th)):.6f}">
        <freejoint/><geom type="cylinder" size="0.05 0.05" euler="90 0 0" density="1000" friction="0.5 0 0"/>
      </body></worldbody></mujoco>"""
    from test_shape_contact_plane import incline
    _, _, t = incline(np.radians(th))
    sec, (ts, xs, _) = _mj_run(xml, 0.5, "roller")
    return sec, abs(_fit_acc(ts, xs @ t) / (G * np.sin(np.radians(th)) / 1.5) - 1)


def mj_pile():
    bodies = "".join(
        f'<body pos="{p[0]} {p[1]} {p[2]}" quat="{r.as_quat()[3]} {r.as_quat()[0]} {r.as_quat()[1]} {r.as_quat()[2]}">'
        f'<freejoint/><geom type="box" size="0.05 0.05 0.05" mass="1" friction="0.5 0 0"/></body>'
        for p, r in pile_positions())
    xml = f"""<mujoco><option gravity="0 0 -9.81"/><worldbody>
      <geom type="plane" size="5 5 0.1" friction="0.5 0 0"/>{bodies}</worldbody></mujoco>"""
    import mujoco
    sec, (_, _, data) = _mj_run(xml, 1.5, None)
    model = data.model if hasattr(data, "model") else None
    _ = model, mujoco
    return sec, float(0.5 * np.sum(data.qvel ** 2))   # (unit masses; rotational part approximate)


def mj_tumble():
    """The thrown cube in MuJoCo, mj_step at 1 ms (its free joint's angular velocity is in body axes)."""
    import mujoco
    rot = tumble_rotation()
    q = rot.as_quat()
    p = TUMBLE_POS
    xml = f"""<mujoco><option gravity="0 0 -9.81"/><worldbody>
      <geom type="plane" size="5 5 0.1" friction="0.5 0 0"/>
      <body name="box" pos="{p[0]} {p[1]} {p[2]}" quat="{q[3]} {q[0]} {q[1]} {q[2]}"><freejoint/>
        <geom type="box" size="{TUMBLE_A / 2} {TUMBLE_A / 2} {TUMBLE_A / 2}" mass="1" friction="0.5 0 0"/></body>
      </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    dt = model.opt.timestep = 1e-3   # as the other scenes
    R0 = rot.as_matrix()

    def run():
        d = mujoco.MjData(model)
        d.qvel[:3], d.qvel[3:6] = TUMBLE_V, R0.T @ np.asarray(TUMBLE_W, float)
        mujoco.mj_forward(model, d)
        for _ in range(int(round(TUMBLE_T / dt))):
            mujoco.mj_step(model, d)
        return d
    sec, d = _best(run)
    R = d.body("box").xmat.reshape(3, 3)
    r = rest_measures(d.body("box").xpos[2], R, d.qvel[:3].copy(), R @ d.qvel[3:6])
    r["travel [m]"] = float(d.body("box").xpos[0] - TUMBLE_POS[0])
    return sec, r


def _fmt(x):
    if isinstance(x, dict):
        return ", ".join(f"{k} {v:.3g}" for k, v in x.items())
    return f"{x:.3g}" if np.isfinite(x) else "n/a"


def mj_cam(dt=2e-4):
    """The cam scene in MuJoCo: the eccentric disc on a hinge spun at w by a 1000 kg m^2 flywheel (the
    contact's torque leaves its speed constant to 1e-6), the follower a slide joint whose spring
    (stiffness, springref) gives the same rate and preload; stiffer contact (solref 0.002) and a 0.2 ms
    step, as its default (0.02, 1 ms) leaves the follower 19 % of the stroke off the profile."""
    import mujoco
    from test_shape_contact_cam import E_CAM, F0, KS, MASS, R_CAM, lift_off_speed
    w = 0.7 * lift_off_speed()
    T = 2 * np.pi / w
    xml = f"""<mujoco><option gravity="0 0 0" timestep="{dt}"/>
      <default><geom solref="0.002 1" friction="0 0 0"/></default>
      <worldbody>
        <body name="cam"><joint name="shaft" type="hinge" axis="0 1 0"/>
          <geom type="cylinder" size="{R_CAM} 0.01" pos="0 0 {-E_CAM}" euler="90 0 0"/>
          <inertial pos="0 0 0" mass="1" diaginertia="1000 1000 1000"/></body>
        <body name="follower" pos="0 0 {R_CAM + 0.01 - E_CAM}">
          <joint name="guide" type="slide" axis="0 0 1" stiffness="{KS}" springref="{-F0 / KS}"/>
          <geom type="box" size="0.04 0.02 0.01" mass="{MASS}"/></body>
      </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)

    def run():
        d = mujoco.MjData(model)
        d.qvel[0] = -w   # the lift's phase of mbdsim's scene (its hinge turns the other way about +y)
        mujoco.mj_forward(model, d)
        n, ts, zs = int(round(T / dt)), [], []
        for k in range(n + 1):
            if k % 10 == 0:
                ts.append(d.time)
                zs.append(d.body("follower").xpos[2])
            if k < n:
                mujoco.mj_step(model, d)
        return np.array(ts), np.array(zs)
    sec, (ts, zs) = _best(run)
    return sec, float(np.max(np.abs(zs - zs[0] - E_CAM * (1 - np.cos(w * ts)))) / E_CAM)


SCENES = {"slide": ("box sliding (30 deg, mu 0.3)", "mb_box_slide", "mj_box_slide", "acceleration error"),
          "roll": ("cylinder rolling (15 deg)", "mb_cyl_roll", "mj_cyl_roll", "acceleration error"),
          "tumble": (f"box thrown tumbling, {TUMBLE_T:g} s", "mb_tumble", "mj_tumble",
                     "at rest: CM height over a/2, tilt from face down, kinetic energy; travel (path-dependent)"),
          "pile": ("pile of 8 boxes, 1.5 s", "mb_pile", "mj_pile", "final kinetic energy [J]"),
          "cam": ("cam on flat follower, 1 turn", "mb_cam", "mj_cam", "max lift error / e")}


def main(argv=()):
    """All scenes, written into CONTACT_RESULTS.md and RESULTS.md; with scene keys (SCENES: slide, roll,
    tumble, pile, cam) on the command line, those only, printed and not written."""
    warnings.simplefilter("ignore")
    import os
    unknown = [k for k in argv if k not in SCENES]
    if unknown:
        raise SystemExit(f"unknown scene(s) {unknown}; scenes: {', '.join(SCENES)}")
    load0 = os.getloadavg()[0]
    rows = []
    for key in argv or SCENES:
        name, fm, fj, what = SCENES[key]
        fm, fj = globals()[fm], globals()[fj]
        sm, em = fm()
        sa, ea = fm("auto")   # the default method: DOP853 with the hand-over to Radau IIA on stiffness
        sj, ej = fj() if fj else (np.nan, np.nan)
        rows.append((name, what, sm, em, sa, ea, sj, ej))
        print(f"{name}: mbdsim DOP853 {sm:.4g} s ({_fmt(em)}), default {sa:.4g} s ({_fmt(ea)}), MuJoCo {sj:.4g} s "
              f"({_fmt(ej)})", flush=True)
    if argv:
        return
    lines = ["## Shape contact (issue 30)", "",
             f"Generated by `python3 bench/contact_shapes.py` on {time.strftime('%Y-%m-%d')}; best of {REPEATS} runs "
             "of the integration call each, both engines in the same run.  mbdsim: compliant IMPACT contact, "
             "DOP853 (rtol 1e-6; pile 1e-5; cam 1e-8), and the default method (`auto`: DOP853 handing over to the "
             "compiled Radau IIA where it detects stiffness) at the same rtol; MuJoCo: its soft constraints, mj_step at 1 ms (the cam: 0.2 ms, solref 0.002).  "
             f"Machine load (1-minute average) {load0:.2f} at the start, {os.getloadavg()[0]:.2f} at the end, on "
             f"{os.cpu_count()} cores: times are shared with that load.", "",
             "| scene | measure | mbdsim DOP853 time | mbdsim | default-method time | default | MuJoCo time | MuJoCo "
             "| DOP853 / MuJoCo | default / MuJoCo |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, what, sm, em, sa, ea, sj, ej in rows:
        ratio = (lambda x: f"{x / sj:.3g}x" if np.isfinite(sj) else "n/a")  # noqa: E731
        lines.append(f"| {name} | {what} | {sm:.4g} s | {_fmt(em)} | {sa:.4g} s | {_fmt(ea)} | "
                     f"{'n/a' if not np.isfinite(sj) else f'{sj:.4g} s'} | {_fmt(ej)} | {ratio(sm)} | {ratio(sa)} |")
    text = "\n".join(lines) + "\n"
    (HERE / "CONTACT_RESULTS.md").write_text(text)
    replace_section(HERE / "RESULTS.md", text)


if __name__ == "__main__":
    main(tuple(sys.argv[1:]))
