"""A four-bar of 3D revolutes carried on a driven spindle (issue 29: no hang, ever, inside the kernel).

The spindle turns about ground z at 1 rev/s; the four-bar lies in the spindle's x-z plane with its joint
axes along the spindle's y axis, so that its out-of-plane (dependent) constraint rows in ground axes
change with the turn: at a quarter turn the loop rows chosen at the start become dependent. The kernel
re-selects them (fastdyn._reselect); before it the run failed there ("step size collapsed") or hung.

Checks against closed forms, not against mbdsim's own output:
- the four-bar stays in the spindle's plane (position in spindle axes, from the spindle angle 2 pi t);
- the coupler and rocker follow the crank angle by the Freudenstein closure (solved here with numpy);
- free under gravity along the spindle axis (a governor), the Jacobi integral T - Omega H_z + V of the
  four-bar's bodies is conserved (constant Omega about z, a time-independent Lagrangian in the turning
  frame: h = T2 - T0 + V, and T - Omega dT/dOmega = T2 - T0);
- a driven rocker that cannot turn further ends the run with an error naming the time of its limit
  (crank and coupler in line, from the triangle of the links) and the loop's joints.
Every run is under a watchdog (faulthandler ends the process if a kernel spins) after a short warm-up
run that compiles the kernels outside it.
"""
import contextlib
import faulthandler
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

A_, B_, C_, D_ = 0.1, 0.3, 0.25, 0.3       # crank, coupler, rocker, base [m] (Grashof crank-rocker)
from test_core_four_bar import A_ as _A, B_ as _B, C_ as _C, D_ as _D, closure, e  # noqa: E402  (same linkage)
assert (_A, _B, _C, _D) == (A_, B_, C_, D_)   # closure() solves test_core_four_bar's link lengths
TH1_0 = np.radians(60.0)                   # crank angle in the four-bar's plane at t = 0
X0 = 0.15                                  # the four-bar's base pivot O on the spindle's x axis [m]
MASS = (0.5, 1.2, 0.9)                     # crank, coupler, rocker [kg]
INERTIA = ((1e-4, 4e-4, 4e-4), (1e-4, 9e-3, 9e-3), (1e-4, 4.7e-3, 4.7e-3))   # principal, body axes [kg m^2]
G = 9.81
OMEGA = 2 * np.pi                          # spindle rate [rad/s]
WATCHDOG_S = 120                           # [s]: a hang ends the test process instead of stalling the suite


@contextlib.contextmanager
def watchdog(seconds=WATCHDOG_S):
    faulthandler.dump_traceback_later(seconds, exit=True)
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()


def planar_points(th1):
    """Crank, coupler and rocker CMs (u, w) in the four-bar's plane for crank angle th1 [m]."""
    th2, _ = closure(th1)
    A = A_ * e(th1)
    B = A + B_ * e(th2)
    return A / 2, (A + B) / 2, (B + np.array([D_, 0.0])) / 2


def to_spindle(u):
    """Plane point (u, w) -> spindle axes (X0 + u, 0, w) [m]."""
    return (X0 + u[0], 0.0, u[1])


def carried_four_bar(drive=None, gravity=(0.0, 0.0, -G)):
    """Spindle driven at 1 rev/s about z; the four-bar's planar angle th is a rotation by -th about the
    spindle's y (x towards z). drive: None (free crank), "crank" (pi*t) or "rocker" (-2*pi*t)."""
    model = mb.Model("carried_four_bar", gravity=gravity)
    spindle = model.add_body("spindle", 2.0, inertia=(0.05, 0.05, 0.02), position=(0, 0, 0))
    model.add_motion("spin", model.add_revolute("S", model.ground, spindle, (0, 0, 0), (0, 0, 1)),
                     displacement="2*pi*t")
    th2, th3 = closure(TH1_0)
    cms = planar_points(TH1_0)
    A = A_ * e(TH1_0)
    B, C = A + B_ * e(th2), np.array([D_, 0.0])
    bodies = [model.add_body(name, m, inertia=i, position=to_spindle(cm),
                             orientation=Rotation.from_rotvec([0, -th, 0]))
              for name, m, i, cm, th in zip(("crank", "coupler", "rocker"), MASS, INERTIA, cms, (TH1_0, th2, th3))]
    crank, coupler, rocker = bodies
    y = (0, 1, 0)
    O = model.add_revolute("O", spindle, crank, to_spindle((0, 0)), y)
    model.add_revolute("A", crank, coupler, to_spindle(A), y)
    model.add_revolute("B", coupler, rocker, to_spindle(B), y)
    Cj = model.add_revolute("C", spindle, rocker, to_spindle(C), y)
    rocker.add_marker("c_end", point=to_spindle(C))
    spindle.add_marker("c", point=to_spindle(C))
    if drive == "crank":
        model.add_motion("crank_drive", O, displacement="pi*t")
    elif drive == "rocker":
        model.add_motion("rocker_drive", Cj, displacement="-2*pi*t")
    return model


def in_spindle_axes(res, p):
    """Ground vectors p (N, 3) at res.time in the spindle's axes, the spindle at angle OMEGA t (the
    driver's closed form, not the simulated spindle)."""
    phi = OMEGA * res.time
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1], p[:, 2]], axis=1)


def closed_form_deviation(res):
    """Largest distance [m] of the coupler and rocker CMs from the Freudenstein closure at the simulated
    crank angle, and the crank angles [rad]; all in the spindle's plane."""
    pc = in_spindle_axes(res, res.position("crank"))
    th1 = np.arctan2(pc[:, 2], pc[:, 0] - X0)
    dev = 0.0
    for name, k in (("coupler", 1), ("rocker", 2)):
        p = in_spindle_axes(res, res.position(name))
        ref = np.array([planar_points(a)[k] for a in th1])
        dev = max(dev, float(np.abs(p[:, [0, 2]] - (ref + [X0, 0.0])).max()))
    return dev, th1


def closure_checks(res):
    """(largest gap [m] at joint C between rocker and spindle, largest out-of-plane offset [m] of the
    four-bar's CMs in the spindle's axes)."""
    gap = res.position("rocker.c_end") - res.position("spindle.c")
    off = max(float(np.abs(in_spindle_axes(res, res.position(b))[:, 1]).max()) for b in ("crank", "coupler", "rocker"))
    return float(np.abs(gap).max()), off


def jacobi_integral(res):
    """T - OMEGA H_z + V of crank, coupler and rocker [J] at each output (ground axes, origin on the
    spindle axis)."""
    h = np.zeros(len(res.time))
    for name, m, inertia in zip(("crank", "coupler", "rocker"), MASS, INERTIA):
        r, v, w = res.position(name), res.velocity(name), res.angular_velocity(name)
        R = res.orientation(name)
        Iw = np.einsum("nij,j,nkj,nk->ni", R, np.asarray(inertia), R, w)     # R I_B R^T w
        T = 0.5 * m * np.sum(v * v, axis=1) + 0.5 * np.sum(w * Iw, axis=1)
        Hz = m * np.cross(r, v)[:, 2] + Iw[:, 2]
        h += T - OMEGA * Hz + m * G * r[:, 2]
    return h


@pytest.fixture(scope="module")
def compiled():
    """Compile the kernels (minutes on a cold cache) outside the watchdogs: short runs, before the turn."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        assert mb.simulate(carried_four_bar(), 0.02, 0.01).success
        assert mb.kinematics(carried_four_bar("crank"), 0.02, 0.01).success
        assert mb.simulate(carried_four_bar("rocker"), 0.02, 0.01).success


@pytest.fixture(scope="module")
def governor(compiled):
    model = carried_four_bar()
    with warnings.catch_warnings(), watchdog():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(model, 10.0, 0.01)     # default settings, 10 turns of the spindle
    return res


def test_governor_runs_ten_spindle_turns(governor):
    res = governor
    assert res.success, res.message
    assert res.time[-1] == pytest.approx(10.0)
    gap, off = closure_checks(res)
    assert gap < 1e-9 and off < 1e-9, (gap, off)
    dev, th1 = closed_form_deviation(res)
    assert dev < 1e-9, dev
    assert np.ptp(th1) > 0.3            # the linkage does move (centrifugal and gravity loads)


def test_governor_spindle_follows_its_driver(governor):
    """The spindle's x axis in ground is (cos 2 pi t, sin 2 pi t, 0)."""
    res = governor
    x_axis = res.orientation("spindle")[:, :, 0]
    ref = np.stack([np.cos(OMEGA * res.time), np.sin(OMEGA * res.time), 0 * res.time], axis=1)
    assert np.abs(x_axis - ref).max() < 1e-9


def test_governor_conserves_the_jacobi_integral(governor):
    h = jacobi_integral(governor)
    scale = MASS[1] * G * B_                  # the scale of the loads' work: m g l [J]
    assert np.abs(h - h[0]).max() < 1e-7 * scale, (np.abs(h - h[0]).max(), scale)


def test_driven_carried_four_bar_kinematics_ten_turns(compiled):
    model = carried_four_bar("crank")
    with warnings.catch_warnings(), watchdog():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.kinematics(model, 10.0, 0.01)
    assert res.success, res.message
    assert not res.stats.get("singular"), res.stats.get("singular")   # no false lock-up reports
    gap, off = closure_checks(res)
    assert gap < 1e-9 and off < 1e-9
    dev, th1 = closed_form_deviation(res)
    assert dev < 1e-9
    # the crank turns at -pi rad/s in the plane's angle (a positive drive about y turns x away from z)
    assert np.abs(np.angle(np.exp(1j * (th1 - (TH1_0 - np.pi * res.time))))).max() < 1e-9


def rocker_limit_time():
    """Time [s] at which the driven rocker reaches its extreme (crank and coupler folded in line,
    |OB| = B - A): the rocker's plane angle goes up from its start at 2 pi rad/s."""
    L = B_ - A_
    gamma = np.arccos((D_**2 + C_**2 - L**2) / (2 * D_ * C_))    # angle at C between C->O and C->B
    th3_lim = np.pi - gamma
    return (th3_lim - closure(TH1_0)[1]) / OMEGA


@pytest.mark.parametrize("analysis", ["simulate", "kinematics"])
def test_a_rocker_driven_past_its_limit_ends_with_an_error(compiled, analysis):
    model = carried_four_bar("rocker")
    t_lim = rocker_limit_time()
    with warnings.catch_warnings(), watchdog():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        run = mb.simulate if analysis == "simulate" else mb.kinematics
        res = run(model, 1.0, 0.01)
    assert not res.success
    err = res.error   # the compiled core's SolverError at the step, or the reference kinematic analysis's
    assert isinstance(err, (mb.SolverError, mb.AssemblyError)), err      # at the output time after it
    assert t_lim - 0.02 <= err.time <= t_lim + 0.01, (err.time, t_lim)
    assert set(err.joints) & {"O", "A", "B", "C"}, err.joints
    assert f"{err.time:.4g}"[:4] in str(err) or "t =" in str(err)
    assert res.time[-1] <= err.time and len(res.time) >= int(t_lim / 0.01) - 2   # outputs before it kept
