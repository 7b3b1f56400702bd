"""Issue 29's cost ratios: an element of the model vocabulary against the compiled baseline that makes the
same motion, measured in one process run (ratios count; absolute times on this machine move by 30 %).

    python3 bench/vocabulary.py            # writes bench/VOCABULARY.md
    python3 bench/vocabulary.py gear       # only the cases whose name contains "gear": their rows replaced

Each case (name, element's model, baseline's model, analysis, joints compared[, method]): the median wall time of `REPEAT` calls of `mb.simulate` / `mb.kinematics` after one warm-up
call (the Model is built once; the first call assembles and compiles it), the method each ran
(res.stats["method"]) and the largest difference between the two runs' joint coordinates (the same motion,
so the difference is the accuracy check of the cheaper formulation).
"""
from __future__ import annotations

import statistics
import sys
import time
import warnings
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
import mbdsim as mb  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sections import replace_section  # noqa: E402

REPEAT = 7


def carousel(**drive):
    """Arm driven about z, pendulum hinged at its tip about the arm (1 free DOF), gravity -z."""
    m = mb.Model("carousel", gravity=(0.0, 0.0, -9.81))
    arm = m.add_body("arm", 2.0, inertia=(0.002, 0.02, 0.02), position=(0.15, 0, 0))
    pend = m.add_body("pend", 1.2, inertia=(0.025, 0.025, 1e-3), position=(0.3, 0, -0.25))
    hub = m.add_revolute("hub", m.ground, arm, (0, 0, 0), (0, 0, 1))
    m.add_revolute("tip", arm, pend, (0.3, 0, 0), (1, 0, 0))
    m.add_motion("spin", hub, **drive)
    return m


def slider_crank(**drive):
    """Zero-DOF slider-crank (r = 0.1 m, l = 0.35 m), crank driven."""
    r, l_ = 0.1, 0.35
    m = mb.Model("sc")
    crank = m.add_body("crank", 1.0, inertia=(1e-4, 1e-3, 1e-3), position=(r / 2, 0, 0))
    rod = m.add_body("rod", 1.0, inertia=(1e-4, 1e-2, 1e-2), position=(r + l_ / 2, 0, 0))
    slider = m.add_body("slider", 0.5, inertia=(1e-3, 1e-3, 1e-3), position=(r + l_, 0, 0))
    o = m.add_revolute("O", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_revolute("A", crank, rod, (r, 0, 0), (0, 0, 1))
    m.add_spherical("B", rod, slider, (r + l_, 0, 0))
    m.add_translational("slide", m.ground, slider, (r + l_, 0, 0), (1, 0, 0))
    m.add_motion("drive", o, **drive)
    return m


def rod(axial):
    """The README's rod (2 kg, 1 m) on a pin with a torsion spring, axial inertia `axial` [kg m^2]."""
    m = mb.Model("rod", gravity=(0.0, -9.81, 0.0))
    b = m.add_body("rod", 2.0, inertia=(axial, 2.0 / 12, 2.0 / 12), position=(0.5, 0, 0))
    pin = m.add_revolute("pin", m.ground, b, (0, 0, 0), (0, 0, 1))
    m.add_torsion_spring("spring", pin, stiffness=5.0)
    return m


def pendulum(torque):
    """Rod pendulum with a drag torque -0.3 w_z, written as given."""
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 2.0, inertia=(0.01, 2 / 12, 2 / 12), position=(0.5, 0, 0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    m.add_torque("drag", rod, torque(rod))
    return m


def callable_drag(rod):
    return lambda t, s: (0.0, 0.0, -0.3 * s.angular_velocity(rod)[2])


@numba.njit
def _drag(w):
    return -0.3 * w


@numba.njit
def _spin(t):
    return 3 * t + 2 * np.sin(t)


def pendulum_njit():
    """pendulum() with the drag torque -0.3 w_z computed by an njit function called from the kernel."""
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 2.0, inertia=(0.01, 2 / 12, 2 / 12), position=(0.5, 0, 0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    m.add_function("drag", _drag)
    m.add_torque("drag", rod, (0, 0, "drag(WZ(rod))"))
    return m


def gears(geared):
    """Gear pair (ratio -1/2) driven by a torque on gear 1, torsion spring on gear 2's shaft; baseline: the
    equivalent single shaft (inertia J1 + J2 r^2, spring k r^2)."""
    J1, J2, r, k = 0.01, 0.04, -0.5, 2.0
    m = mb.Model("gears", gravity=(0.0, 0.0, 0.0))
    if geared:
        m.add_body("g1", 1.0, inertia=(0.02, 0.02, J1))
        m.add_body("g2", 1.0, inertia=(0.05, 0.05, J2), position=(0.3, 0, 0))
        m.add_revolute("p1", "ground", "g1", (0, 0, 0), (0, 0, 1), initial_velocity=5.0)
        p2 = m.add_revolute("p2", "ground", "g2", (0.3, 0, 0), (0, 0, 1), initial_velocity=5.0 * r)
        m.add_gear("mesh", "p1", "p2", r)
        m.add_torsion_spring("spring", p2, stiffness=k)
    else:
        m.add_body("g1", 1.0, inertia=(0.02, 0.02, J1 + J2 * r * r))
        p1 = m.add_revolute("p1", "ground", "g1", (0, 0, 0), (0, 0, 1), initial_velocity=5.0)
        m.add_torsion_spring("spring", p1, stiffness=k * r * r)
    return m


def gear_train(geared):
    """Two-stage gear train (theta_2 = -2.5 theta_1, theta_3 = -0.4 theta_2) with a torsion spring on the
    output shaft, from rest at a spring deflection; baseline: one shaft with the reflected inertia
    J3 + J2 / r2^2 + J1 / (r1 r2)^2 and the same spring."""
    J1, J2, J3, r1, r2 = 0.02, 0.05, 0.03, -2.5, -0.4
    m = mb.Model("train", gravity=(0.0, 0.0, 0.0))
    if geared:
        for n, (J, x) in enumerate(((J1, 0.0), (J2, 0.3), (J3, 0.5)), start=1):
            m.add_body(f"s{n}", 1.0, inertia=(0.03, 0.03, J), position=(x, 0, 0))
            m.add_revolute(f"p{n}", "ground", f"s{n}", (x, 0, 0), (0, 0, 1))
        m.add_gear("mesh1", "p1", "p2", r1)
        m.add_gear("mesh2", "p2", "p3", r2)
        m.add_torsion_spring("spring", "p3", 3.0, free_angle=0.4)
    else:
        m.add_body("s3", 1.0, inertia=(0.2, 0.2, J3 + J2 / r2**2 + J1 / (r1 * r2) ** 2), position=(0.5, 0, 0))
        m.add_revolute("p3", "ground", "s3", (0.5, 0, 0), (0, 0, 1))
        m.add_torsion_spring("spring", "p3", 3.0, free_angle=0.4)
    return m


def geared_four_bar(geared):
    """Four-bar of 3D revolutes (crank 0.1, coupler 0.3, rocker 0.25, ground link 0.3 m; a closed loop: absolute
    coordinates) falling under gravity -y with the crank geared (ratio -2) to a flywheel of axial inertia Jf;
    baseline: the same four-bar with the flywheel's reflected inertia r^2 Jf added to the crank (same motion)."""
    from scipy.spatial.transform import Rotation
    A_, B_, C_, D_, th1, r, Jf = 0.1, 0.3, 0.25, 0.3, np.radians(60.0), -2.0, 2e-4
    e = lambda a: np.array([np.cos(a), np.sin(a)])  # noqa: E731
    Ap, Cp = A_ * e(th1), np.array([D_, 0.0])
    d = np.linalg.norm(Cp - Ap)
    x = (B_**2 - C_**2 + d**2) / (2 * d)
    u = (Cp - Ap) / d
    Bp = Ap + x * u + np.sqrt(B_**2 - x**2) * np.array([-u[1], u[0]])
    th2, th3 = np.arctan2(*(Bp - Ap)[::-1]), np.arctan2(*(Bp - Cp)[::-1])
    m = mb.Model("four_bar", gravity=(0.0, -9.81, 0.0))
    p3 = lambda v: (v[0], v[1], 0.0)  # noqa: E731
    extra = 0.0 if geared else r * r * Jf
    for name, mass, L, cm, th in (("crank", 0.5, A_, Ap / 2, th1), ("coupler", 1.2, B_, (Ap + Bp) / 2, th2),
                                  ("rocker", 0.9, C_, (Bp + Cp) / 2, th3)):
        izz = mass * L * L / 12 + (extra if name == "crank" else 0.0)
        m.add_body(name, mass, inertia=(izz / 20 + (extra if name == "crank" else 0.0), izz, izz),
                   position=p3(cm), orientation=Rotation.from_rotvec([0, 0, th]))
    z = (0, 0, 1)
    m.add_revolute("O", m.ground, "crank", (0, 0, 0), z)
    m.add_revolute("A", "crank", "coupler", p3(Ap), z)
    m.add_revolute("B", "coupler", "rocker", p3(Bp), z)
    m.add_revolute("C", m.ground, "rocker", p3(Cp), z)
    if geared:
        m.add_body("fly", 1.0, inertia=(Jf, Jf, Jf), position=(0.0, 0.0, 0.1))
        m.add_revolute("F", m.ground, "fly", (0, 0, 0.1), z)
        m.add_gear("g", "O", "F", r)
    return m


def planetary(geared):
    """Planetary gear set with a fixed ring (sun r_s 0.03, planet r_p 0.015, ring 0.06 m) swinging under gravity
    -y about its vertical z axis: the sun on a revolute and a coaxial cylindrical joint (a closed loop: absolute
    coordinates), the carrier (0.1 kg, CM on the planet's pin radius a) on a revolute, the planet pinned on it;
    the sun mesh r_s (theta_s - theta_c) + r_p phi = 0 moves three bodies (sun, carrier, planet), the ring mesh
    r_p phi + r_r theta_c = 0 two; torque 0.02 N m on the sun. Baseline: the carrier alone (on a revolute and
    a cylindrical joint) with the planet's mass and the reflected inertia J = n^2 J_s + J_c + m_p a^2 + J_p
    (1 - r_r / r_p)^2 about its axis (n = 1 + r_r / r_s), torque n T_s: the same motion of the carrier.
    (Gravity, not a spring: a torsion spring in a loop is called back through Python and would dominate; a
    spring-damper's dissipation is accumulated by the compiled run itself, bench/energy_monitor.py.)"""
    rs, rp = 0.03, 0.015
    rr, a = rs + 2 * rp, rs + rp
    Js, Jc, Jp, mp, mc, Ts = 2e-4, 5e-4, 3e-5, 0.2, 0.1, 0.02
    n = 1 + rr / rs
    z = (0, 0, 1)
    m = mb.Model("planetary", gravity=(0.0, -9.81, 0.0))
    if not geared:
        J = n * n * Js + Jc + mp * a * a + Jp * (1 - rr / rp) ** 2 - (mc + mp) * a * a   # about the CM
        m.add_body("carrier", mc + mp, inertia=(J, J, J), position=(a, 0.0, 0.01))
        m.add_revolute("Rc", m.ground, "carrier", (0, 0, 0.01), z)
        m.add_cylindrical("Cc", m.ground, "carrier", (0, 0, 0.01), z)
        m.add_torque("T", "carrier", (0.0, 0.0, n * Ts))
        return m
    J = Jc - mc * a * a
    m.add_body("carrier", mc, inertia=(J, J, J), position=(a, 0.0, 0.01))
    m.add_revolute("Rc", m.ground, "carrier", (0, 0, 0.01), z)
    m.add_body("sun", 0.3, inertia=(Js, Js, Js), position=(0.0, 0.0, 0.0))
    m.add_body("planet", mp, inertia=(Jp, Jp, Jp), position=(a, 0.0, 0.0))
    m.add_revolute("Rs", m.ground, "sun", (0, 0, 0), z)
    m.add_cylindrical("Cs", m.ground, "sun", (0, 0, 0), z)
    m.add_revolute("Rp", "carrier", "planet", (a, 0, 0), z)
    m.add_user_constraint("sun_mesh", f"{rs}*(Rs - Rc) + {rp}*Rp")
    m.add_user_constraint("ring_mesh", f"{rp}*Rp + {rr}*Rc")
    m.add_torque("T", "sun", (0.0, 0.0, Ts))
    return m


def bead(curve, s0, velocity):
    """A 0.2 kg bead on a fixed curve, gravity -z (2 s: a helix in s runs to s = -15 rad, a line 17 m)."""
    m = mb.Model("bead", gravity=(0.0, 0.0, -9.81))
    b = m.add_particle("bead", 0.2, position=curve.point(s0), velocity=velocity)
    m.add_point_on_curve("path", b.add_marker("c"), m.ground, curve)
    return m


def helix_bead():
    """Bead on the helix (0.3 cos s, 0.3 sin s, 0.1 s) written as expression strings in s."""
    c = mb.Curve(("0.3*cos(s)", "0.3*sin(s)", "0.1*s"), (-20.0, 3.0))
    return bead(c, 0.5, 2.0 * np.array([-0.3 * np.sin(0.5), 0.3 * np.cos(0.5), 0.1]))


def helix_py_bead():
    """The same helix as a Python function of s (tabulated as a spline to the run's tolerance: system.pathtable)."""
    c = mb.Curve(lambda s: np.array([0.3 * np.cos(s), 0.3 * np.sin(s), 0.1 * s]), (-20.0, 3.0))
    return bead(c, 0.5, 2.0 * np.array([-0.3 * np.sin(0.5), 0.3 * np.cos(0.5), 0.1]))


def line_bead():
    """Bead on a straight 7-point Spline along (0.6, 0, -0.8)."""
    u = np.array([0.6, 0.0, -0.8])
    return bead(mb.Spline([k * u for k in np.linspace(-1.0, 20.0, 7)]), 1.0 / 6.0, 0.5 * u)


def line_expr_bead():
    """Bead on the same straight line written as expression strings in s (compiled, as the helix)."""
    u = np.array([0.6, 0.0, -0.8])
    return bead(mb.Curve(("0.6*s", "0*s", "-0.8*s"), (-1.0, 20.0)), 1.0, 0.5 * u)


def coasting_slider_crank(bore=0.0, pins=0.0):
    """Vertical-plane slider-crank (crank 0.1 m, rod 0.35 m) released spinning at 2 rev/s, Coulomb friction
    mu = `bore` in the slider's guide and mu = `pins` in the crank and rod pins (pin radius 5 mm); no
    friction element where mu = 0 (the baseline: the same machine without friction)."""
    R_, L_, th0 = 0.1, 0.35, np.pi / 3
    m = mb.Model("coast", gravity=(0.0, -9.81, 0.0))
    A = R_ * np.array([np.cos(th0), np.sin(th0), 0.0])
    B = np.array([R_ * np.cos(th0) + np.sqrt(L_**2 - (R_ * np.sin(th0)) ** 2), 0.0, 0.0])
    from scipy.spatial.transform import Rotation
    rz = lambda a: Rotation.from_rotvec([0.0, 0.0, a])  # noqa: E731
    crank = m.add_body("crank", 1.5, (1e-3, 1.25e-3, 1.25e-3), position=A / 2, orientation=rz(th0))
    rod = m.add_body("rod", 2.0, (2e-3, 0.02, 0.02), position=(A + B) / 2,
                     orientation=rz(-np.arcsin(R_ * np.sin(th0) / L_)))
    slider = m.add_body("slider", 0.8, (0.01, 0.01, 0.01), position=B)
    z = (0, 0, 1)
    o = m.add_revolute("O", m.ground, crank, (0, 0, 0), z, initial_velocity=[4 * np.pi])
    a = m.add_revolute("A", crank, rod, A, z)
    m.add_revolute("B", rod, slider, B, z)
    guide = m.add_translational("guide", m.ground, slider, B, (1, 0, 0))
    if bore:
        m.add_friction("bore", guide, bore, bore)
    for jt in (o, a) if pins else ():
        m.add_friction("f_" + jt.name, jt, pins, pins, pin_radius=0.005)
    return m


def coasting_four_bar(mu=0.0):
    """Crank-rocker (crank 0.1 m, coupler 0.35 m, rocker 0.3 m, ground link 0.4 m) in a vertical plane,
    released at 1 rev/s; pin friction mu (pin radius 0.05 m) in all four pins: it comes to rest with the
    four pins stuck as one held group (their locks dependent); no friction element where mu = 0."""
    a4, b4, c4, d4, th = 0.1, 0.35, 0.3, 0.4, 0.3
    A = a4 * np.array([np.cos(th), np.sin(th), 0.0])
    O4 = np.array([d4, 0.0, 0.0])
    dist = np.linalg.norm(O4 - A)
    ex = (O4 - A) / dist
    x = (b4**2 - c4**2 + dist**2) / (2 * dist)
    B = A + x * ex + np.sqrt(b4**2 - x**2) * np.array([-ex[1], ex[0], 0.0])
    from scipy.spatial.transform import Rotation
    ang = lambda v: Rotation.from_rotvec([0.0, 0.0, np.arctan2(v[1], v[0])])  # noqa: E731
    m = mb.Model("four_bar", gravity=(0.0, -9.81, 0.0))
    crank = m.add_body("crank", 0.5, (1e-4, 4e-4, 4e-4), position=A / 2, orientation=ang(A))
    coupler = m.add_body("coupler", 1.0, (1e-4, 0.01, 0.01), position=(A + B) / 2, orientation=ang(B - A))
    rocker = m.add_body("rocker", 0.8, (1e-4, 6e-3, 6e-3), position=(B + O4) / 2, orientation=ang(B - O4))
    z = (0, 0, 1)
    joints = [m.add_revolute("O2", m.ground, crank, (0, 0, 0), z, initial_velocity=[2 * np.pi]),
              m.add_revolute("A", crank, coupler, A, z), m.add_revolute("B", coupler, rocker, B, z),
              m.add_revolute("O4", m.ground, rocker, O4, z)]
    for jt in joints if mu else ():
        m.add_friction("f_" + jt.name, jt, mu, mu, pin_radius=0.05)
    return m


def timed(fn):
    fn()
    ts = []
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        res = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), res


CASES = [
    ("velocity driver (carousel, 1 DOF free, 2 s)", lambda: carousel(velocity="18.85"),
     lambda: carousel(displacement="18.85*t"), "simulate", ("hub", "tip")),
    ("acceleration driver (carousel)", lambda: carousel(acceleration="8 - 3*t", initial_velocity=1.5),
     lambda: carousel(displacement="1.5*t + 4*t**2 - t**3/2"), "simulate", ("hub", "tip")),
    ("velocity driver, STEP ramp (carousel)", lambda: carousel(velocity="STEP(t, 0, 0, 0.5, 18.85)"),
     lambda: carousel(displacement="18.85*(0.5*((abs(2*t) - abs(2*t - 1) + 1)/2)**3 - 0.25*((abs(2*t) - "
                                   "abs(2*t - 1) + 1)/2)**4) + 18.85*(t - 0.5 + abs(t - 0.5))/2"),
     "simulate", ("hub", "tip")),
    ("velocity driver (slider-crank kinematics, 0 DOF)", lambda: slider_crank(velocity="18.85"),
     lambda: slider_crank(displacement="18.85*t"), "kinematics", ("O", "slide")),
    ("slender rod, axial inertia 0 (torsion spring)", lambda: rod(0.0), lambda: rod(1e-6), "simulate", ("pin",)),
    ("Python-callable drag torque (pendulum)", lambda: pendulum(callable_drag),
     lambda: pendulum(lambda rod: (0, 0, "-0.3*WZ(rod)")), "simulate", ("pin",)),
    ("numba.njit drag torque via Model.add_function (pendulum)", pendulum_njit,
     lambda: pendulum(lambda rod: (0, 0, "-0.3*WZ(rod)")), "simulate", ("pin",)),
    ("numba.njit driver, derivatives by the kernel's central differences (carousel)",
     lambda: carousel(displacement=_spin), lambda: carousel(displacement="3*t + 2*sin(t)"), "simulate",
     ("hub", "tip")),
    ("Python-callable driver, exact derivatives (carousel)",
     lambda: carousel(displacement=mb.expressions.time_function(lambda t: 3 * t + 2 * np.sin(t),
                                                                d1=lambda t: 3 + 2 * np.cos(t),
                                                                d2=lambda t: -2 * np.sin(t))),
     lambda: carousel(displacement="3*t + 2*sin(t)"), "simulate", ("hub", "tip")),
    ("Python-callable driver, numerical derivatives (carousel)",
     lambda: carousel(displacement=lambda t: 3 * t + 2 * np.sin(t)),
     lambda: carousel(displacement="3*t + 2*sin(t)"), "simulate", ("hub", "tip")),
    ("gear pair + torsion spring vs the equivalent shaft", lambda: gears(True),
     lambda: gears(False), "simulate", ("p1",)),
    ("two-stage gear train + torsion spring vs the equivalent shaft", lambda: gear_train(True),
     lambda: gear_train(False), "simulate", ("p3",)),
    ("four-bar crank geared to a flywheel (closed loop) vs the four-bar with its reflected inertia",
     lambda: geared_four_bar(True), lambda: geared_four_bar(False), "simulate", ("O", "C")),
    ("planetary gear set, sun mesh moving three bodies (closed loop) vs the carrier with its reflected inertia",
     lambda: planetary(True), lambda: planetary(False), "simulate", ("Rc",)),
    ("joint friction, bore + two pins (coasting slider-crank, slipping through dead centres) vs none",
     lambda: coasting_slider_crank(0.02, 0.02), coasting_slider_crank, "simulate", ()),   # different motions
    ("joint friction, bore (coasting slider-crank comes to rest and sticks) vs none",
     lambda: coasting_slider_crank(0.4), coasting_slider_crank, "simulate", ()),
    ("joint friction, all four pins (coasting four-bar comes to rest, held as one group) vs none",
     lambda: coasting_four_bar(0.3), coasting_four_bar, "simulate", ()),
    ("joint friction, bore + two pins, HHT (coasting slider-crank, slipping through dead centres) vs none, HHT",
     lambda: coasting_slider_crank(0.02, 0.02), coasting_slider_crank, "simulate", (), "hht"),
    ("joint friction, bore + two pins, Radau (coasting slider-crank, slipping through dead centres) vs none, "
     "Radau", lambda: coasting_slider_crank(0.02, 0.02), coasting_slider_crank, "simulate", (), "radau"),
    ("joint friction, bore, HHT (coasting slider-crank comes to rest and sticks) vs none, HHT",
     lambda: coasting_slider_crank(0.4), coasting_slider_crank, "simulate", (), "hht"),
    ("joint friction, bore, Radau (coasting slider-crank comes to rest and sticks) vs none, Radau",
     lambda: coasting_slider_crank(0.4), coasting_slider_crank, "simulate", (), "radau"),
    ("helix (expression curve) vs straight spline (bead, point-on-curve)", helix_bead, line_bead,
     "simulate", ()),   # different motions: no coordinate difference
    ("helix as a Python-callable curve (tabulated) vs straight spline (bead, point-on-curve)", helix_py_bead,
     line_bead, "simulate", ()),
    ("helix vs straight line, both expression curves (bead, point-on-curve, compiled)", helix_bead,
     line_expr_bead, "simulate", ()),
]


def main(only=None):
    warnings.simplefilter("ignore")
    out = Path(__file__).with_name("VOCABULARY.md")
    old = out.read_text().splitlines() if only and out.exists() else None
    lines = ["# Model vocabulary against its compiled baseline (issue 29)", "",
             "Written by `python3 bench/vocabulary.py`: median of %d calls after a warm-up, same process." % REPEAT,
             "", "| case | element | baseline | ratio | element's method | max joint-coordinate difference |",
             "|---|---|---|---|---|---|"]
    for name, make, make_base, analysis, joints, *method in CASES:   # (an optional 6th field: the method)
        if only and only not in name:
            continue
        opts = {"method": method[0]} if method else {}
        run = (lambda m: mb.simulate(m, end_time=2.0, output_step=0.01, **opts)) if analysis == "simulate" else \
            (lambda m: mb.kinematics(m, end_time=2.0, output_step=0.01))
        m, mb_ = make(), make_base()
        te, re = timed(lambda: run(m))
        tb, rb = timed(lambda: run(mb_))
        diff = max((float(np.max(np.abs(re.joint_coordinate(j) - rb.joint_coordinate(j)))) for j in joints),
                   default=float("nan"))
        lines.append(f"| {name} | {te * 1e3:.2f} ms | {tb * 1e3:.2f} ms | {te / tb:.2f}x | "
                     f"{re.stats.get('method', '?')} | {diff:.1e} |")
        print(lines[-1], flush=True)
    if old is not None:   # the other cases' rows kept (a case's row found by its name, else appended)
        new = {ln.split(" | ")[0]: ln for ln in lines[6:]}
        merged = [new.pop(ln.split(" | ")[0], ln) for ln in old]
        lines = merged + list(new.values())
    out.write_text("\n".join(lines) + "\n")
    replace_section(out.with_name("RESULTS.md"), "\n".join(
        ["## Model vocabulary against its compiled baseline (issue 29)"] + lines[1:]))
    print("wrote", out)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
