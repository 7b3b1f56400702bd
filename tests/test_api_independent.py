"""Independent checks of the public API (issues 2 and 3) on mechanisms the other test files do not use.

Every expected value is derived here from a closed form, a conservation law or an independent
numpy/scipy computation - never from numbers printed by mbdsim.  The mechanisms deliberately use
axes that are not coordinate axes, orientations given as scipy Rotations, full 3x3 inertia matrices
and markers with their own orientation used as `frame=`.
"""
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, fsolve
from scipy.spatial.transform import Rotation
from scipy.special import ellipk

import mbdsim as mb

G = 9.81
TIGHT = dict(method="dop853", rtol=1e-11, atol=1e-13)


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def rot_about(n, ang):
    """(N, 3, 3) rotation matrices about unit axis n by angles ang."""
    return Rotation.from_rotvec(np.outer(np.atleast_1d(ang), n)).as_matrix()


def apply(R, v):
    """R (N,3,3) applied to v (3,) or (N,3)."""
    return np.einsum("nij,nj->ni", R, np.broadcast_to(v, (len(R), 3)))


def in_axes(R, v):
    """Components of ground vectors v (N,3) in the axes R (N,3,3) (frame->ground)."""
    return np.einsum("nji,nj->ni", R, v)


# ----------------------------------------------------------------------------- skew-axis pendulum
N_AX = unit((1.0, 1.0, 1.0))
P_PIV = np.array([0.1, -0.2, 0.3])
E_DOWN = unit(-np.array([0, 0, 1.0]) + N_AX[2] * N_AX)   # lowest direction in the swing plane
E_2 = np.cross(N_AX, E_DOWN)
G_PERP = G * np.sqrt(1.0 - N_AX[2] ** 2)                 # gravity component in the swing plane
J_B = np.array([[0.05, 0.01, -0.005], [0.01, 0.08, 0.002], [-0.005, 0.002, 0.06]])
A0 = Rotation.from_rotvec([0.3, -0.7, 0.2])
M_P, D_P, AX_OFF, TH0 = 1.5, 0.5, 0.15, 1.2


def skew_pendulum():
    model = mb.Model("skew_pendulum", gravity=(0.0, 0.0, -G))
    C0 = P_PIV + AX_OFF * N_AX + D_P * (np.cos(TH0) * E_DOWN + np.sin(TH0) * E_2)
    bob = model.add_body("bob", M_P, inertia=J_B, position=C0, orientation=A0)
    pin = model.add_revolute("pin", model.ground, bob, P_PIV, N_AX)
    mk = bob.add_marker("mk", point=C0 + 0.2 * E_2, orientation=Rotation.from_rotvec([0.4, 0.1, -0.9]))
    return model, bob, pin, mk, C0


def pivot_inertia():
    """Inertia about the axis through the pivot (constant along the motion)."""
    Jg = A0.as_matrix() @ J_B @ A0.as_matrix().T
    return float(N_AX @ Jg @ N_AX) + M_P * D_P**2


@pytest.fixture(scope="module")
def pendulum_run():
    model, bob, pin, mk, C0 = skew_pendulum()
    I_P = pivot_inertia()
    T = 4 * np.sqrt(I_P / (M_P * G_PERP * D_P)) * ellipk(np.sin(TH0 / 2) ** 2)
    res = mb.simulate(model, 0.6 * T, 0.6 * T / 150, **TIGHT)
    assert res.success, res.message
    return res, bob, pin, mk, C0, T


def test_skew_axis_pendulum_half_period_and_amplitude(pendulum_run):
    """Physical pendulum about (1,1,1)/sqrt3: half period from the complete elliptic integral with the
    gravity component normal to the axis, and the swing reaches -2 theta0 (energy)."""
    res, bob, pin, mk, C0, T = pendulum_run
    ups = res.crossings(lambda r: r.joint_velocity(pin), 0.0, direction=+1)
    ups = ups[ups > 1e-6]
    assert ups[0] == pytest.approx(T / 2, abs=1e-8)
    t_min, th_min = res.minimum(lambda r: r.joint_coordinate(pin))
    assert t_min == pytest.approx(T / 2, abs=1e-5)       # flat minimum: time to ~sqrt(eps)
    assert th_min == pytest.approx(-2 * TH0, abs=1e-9)
    # the CM stays on its circle about the axis, at a fixed height along the axis
    rho = res.position(bob) - P_PIV
    assert np.allclose(rho @ N_AX, AX_OFF, atol=1e-10)
    assert np.allclose(np.linalg.norm(rho - np.outer(rho @ N_AX, N_AX), axis=1), D_P, atol=1e-10)
    # the default (HHT) method gives the same half period to a looser tolerance
    model = skew_pendulum()[0]
    hht = mb.simulate(model, 0.6 * T, 0.6 * T / 150)
    assert hht.success, hht.message
    j = hht.system.model.joints["pin"]
    up = hht.crossings(lambda r: r.joint_velocity(j), 0.0, direction=+1)
    assert up[up > 1e-6][0] == pytest.approx(T / 2, rel=1e-3)


def test_skew_axis_pendulum_orientation_rates_and_marker_frames(pendulum_run):
    """A(t) = R_n(theta) A0; omega = theta_dot n; alpha from the equation of motion; frame= a marker."""
    res, bob, pin, mk, C0, T = pendulum_run
    th = res.joint_coordinate(pin)
    Rn = rot_about(N_AX, th)
    assert np.allclose(res.orientation(bob), Rn @ A0.as_matrix(), atol=1e-10)
    phi = TH0 + th                                            # angle from the lowest direction
    I_P = pivot_inertia()
    phid2 = 2 * M_P * G_PERP * D_P * (np.cos(phi) - np.cos(TH0)) / I_P   # energy
    phidd = -M_P * G_PERP * D_P * np.sin(phi) / I_P
    w = res.angular_velocity(bob)
    assert np.allclose(w, np.outer(res.joint_velocity(pin), N_AX), atol=1e-9)
    assert np.allclose(res.joint_velocity(pin) ** 2, phid2, atol=1e-8)
    assert np.allclose(res.angular_acceleration(bob), np.outer(phidd, N_AX), atol=1e-8)
    assert np.allclose(res.joint_acceleration(pin), phidd, atol=1e-8)
    # marker measures in the marker's own (rotating) axes
    R_mk = Rn @ (Rotation.from_rotvec([0.4, 0.1, -0.9]).as_matrix())
    p_mk = P_PIV + apply(Rn, C0 + 0.2 * E_2 - P_PIV)
    assert np.allclose(res.position(mk), p_mk, atol=1e-10)
    assert np.allclose(res.angular_velocity(bob, frame=mk), in_axes(R_mk, w), atol=1e-12)
    v_mk = np.cross(w, p_mk - P_PIV)
    assert np.allclose(res.velocity(mk, frame=mk), in_axes(R_mk, v_mk), atol=1e-9)
    a_mk = np.cross(res.angular_acceleration(bob), p_mk - P_PIV) + np.cross(w, v_mk)
    assert np.allclose(res.acceleration(mk, frame=mk), in_axes(R_mk, a_mk), atol=1e-8)
    # position of the CM relative to the marker, in marker axes: constant
    assert np.allclose(res.position(bob, frame=mk), res.position(bob, frame=mk)[0], atol=1e-10)


def test_skew_axis_pendulum_pin_reaction_force_and_torque(pendulum_run):
    """Newton-Euler about the fixed pivot with the full inertia tensor: F = m a_C - m g and
    T_P = J_P alpha + w x (J_P w) - (C - P) x m g, with zero component along the pin axis."""
    res, bob, pin, mk, C0, T = pendulum_run
    th = res.joint_coordinate(pin)
    Rn = rot_about(N_AX, th)
    phi = TH0 + th
    I_P = pivot_inertia()
    phid2 = 2 * M_P * G_PERP * D_P * (np.cos(phi) - np.cos(TH0)) / I_P
    phidd = -M_P * G_PERP * D_P * np.sin(phi) / I_P
    phid = res.joint_velocity(pin)
    g = np.array([0, 0, -G])
    rho = apply(Rn, C0 - P_PIV)
    a_C = np.cross(np.outer(phidd, N_AX), rho) - phid2[:, None] * (rho - np.outer(rho @ N_AX, N_AX))
    F = M_P * a_C - M_P * g
    assert np.allclose(res.reaction_force(pin), F, atol=1e-7)
    A = Rn @ A0.as_matrix()
    J_P = A @ J_B @ np.swapaxes(A, 1, 2) + M_P * (np.einsum("ni,ni->n", rho, rho)[:, None, None] * np.eye(3)
                                                 - np.einsum("ni,nj->nij", rho, rho))
    Jn = np.einsum("nij,j->ni", J_P, N_AX)
    T_P = phidd[:, None] * Jn + phid[:, None] ** 2 * np.cross(N_AX, Jn) - np.cross(rho, M_P * g)
    assert np.allclose(T_P @ N_AX, 0.0, atol=1e-9)
    assert np.allclose(res.reaction_torque(pin), T_P, atol=1e-7)
    # on ground: the opposite load at the same point; frame=marker: rotated components
    assert np.allclose(res.reaction_force(pin, on=res.system.model.ground), -F, atol=1e-7)
    assert np.allclose(res.reaction_torque(pin, on=res.system.model.ground), -T_P, atol=1e-7)
    R_mk = Rn @ (Rotation.from_rotvec([0.4, 0.1, -0.9]).as_matrix())
    assert np.allclose(res.reaction_force(pin, frame=mk), in_axes(R_mk, F), atol=1e-7)
    assert np.allclose(res.reaction_torque(pin, frame=mk), in_axes(R_mk, T_P), atol=1e-7)


# ----------------------------------------------------------------------------- statics of a welded beam
def test_cantilever_with_tip_force_in_marker_axes_and_body_torque():
    """A rotated beam welded to ground: T_P = -[(C-P) x m g + (tip-P) x F + T] on the beam."""
    g = unit((1.0, -2.0, 0.5)) * G
    m_, P, C = 2.5, np.array([0.0, 0.3, -0.1]), np.array([0.6, 0.5, 0.2])
    rot = Rotation.from_rotvec([-0.5, 0.8, 0.3])
    Rm = Rotation.from_rotvec([1.1, 0.0, -0.4]).as_matrix()
    f_local, tq_body = np.array([3.0, -7.0, 2.0]), np.array([0.4, 1.5, -0.8])
    tip_pt = np.array([1.2, 0.45, 0.35])
    model = mb.Model("beam", gravity=g)
    beam = model.add_body("beam", m_, inertia=[[0.2, 0.01, 0.0], [0.01, 0.3, 0.02], [0.0, 0.02, 0.25]],
                          position=C, orientation=rot)
    tip = beam.add_marker("tip", point=tip_pt, orientation=Rm)
    weld = model.add_fixed("weld", model.ground, beam, point=P)
    model.add_force("load", tip, f_local, frame=tip)
    model.add_torque("twist", beam, tq_body, frame=beam)
    F_g, T_g = Rm @ f_local, rot.apply(tq_body)
    F_exp = -(m_ * g + F_g)
    T_exp = -(np.cross(C - P, m_ * g) + np.cross(tip_pt - P, F_g) + T_g)
    for res in (mb.equilibrium(model), mb.simulate(model, 0.05, 0.05, **TIGHT), mb.simulate(model, 0.05, 0.05)):
        assert res.success, res.message
        assert np.allclose(res.reaction_force(weld)[0], F_exp, atol=1e-9)
        assert np.allclose(res.reaction_torque(weld)[0], T_exp, atol=1e-9)
        assert np.allclose(res.reaction_torque(weld, frame=tip)[0], Rm.T @ T_exp, atol=1e-9)
        assert np.allclose(res.reaction_force(weld, on=model.ground)[0], -F_exp, atol=1e-9)
        assert np.allclose(res.position(tip)[0], tip_pt, atol=1e-12)


# ----------------------------------------------------------------------------- rotating arm with a slider
def test_translational_joint_on_a_driven_skew_arm_coriolis_kinematics():
    """Arm turned about a skew axis by theta(t), slider driven along the arm by s(t): closed-form
    position, velocity, Coriolis acceleration, joint measures and the slider's Newton-Euler reactions."""
    n, P = unit((0.2, -0.4, 1.0)), np.array([0.3, 0.1, -0.2])
    u = unit(np.cross(n, (1.0, 0.3, 0.0)) + 0.3 * n)    # slide direction fixed on the arm (not normal to n)
    Q = P + 0.25 * unit(np.cross(n, u))                   # slide joint point
    C_arm, C_sl = P + 0.4 * u, Q + np.array([0.05, -0.02, 0.03])
    model = mb.Model("arm_slider", gravity=(0.0, -G, 0.0))
    arm = model.add_body("arm", 2.0, inertia=(0.01, 0.1, 0.1), position=C_arm,
                         orientation=Rotation.from_rotvec([0.1, 0.2, 0.3]))
    J_sl = np.array([[0.004, 0.001, 0.0], [0.001, 0.006, -0.0005], [0.0, -0.0005, 0.005]])
    m_sl = 0.7
    sl = model.add_body("slider", m_sl, inertia=J_sl, position=C_sl)
    hub = model.add_revolute("hub", model.ground, arm, P, n)
    rail = model.add_translational("rail", arm, sl, Q, u)
    model.add_motion("turn", hub, displacement="0.4*sin(1.3*t) + 0.5*t")
    model.add_motion("feed", rail, velocity="0.4*t + 0.3*cos(3*t)", initial_displacement=0.05)
    res = mb.kinematics(model, 1.5, 0.05)
    assert res.success, res.message
    t = res.time
    th, thd, thdd = 0.4 * np.sin(1.3 * t) + 0.5 * t, 0.52 * np.cos(1.3 * t) + 0.5, -0.676 * np.sin(1.3 * t)
    s, sd, sdd = 0.05 + 0.2 * t**2 + 0.1 * np.sin(3 * t), 0.4 * t + 0.3 * np.cos(3 * t), 0.4 - 0.9 * np.sin(3 * t)
    assert np.allclose(res.joint_coordinate(rail), s, atol=1e-9)
    assert np.allclose(res.joint_velocity(rail), sd, atol=1e-9)
    assert np.allclose(res.joint_acceleration(rail), sdd, atol=1e-8)
    # the assembly applied s(0) = 0.05 (the joint coordinate is zero in the model's configuration)
    R = rot_about(n, th)
    rho = apply(R, C_sl - P) + s[:, None] * apply(R, u)
    W, Wd = np.outer(thd, n), np.outer(thdd, n)
    ru = apply(R, u)
    v = np.cross(W, rho) + sd[:, None] * ru
    a = np.cross(Wd, rho) + np.cross(W, np.cross(W, rho)) + 2 * sd[:, None] * np.cross(W, ru) + sdd[:, None] * ru
    assert np.allclose(res.position(sl), P + rho, atol=1e-9)
    assert np.allclose(res.velocity(sl), v, atol=1e-9)
    assert np.allclose(res.acceleration(sl), a, atol=1e-8)
    assert np.allclose(res.angular_acceleration(sl), Wd, atol=1e-8)
    # slider loads (the motion on `rail` is part of the joint's load): F = m a - m g, torque from Euler
    g = np.array([0, -G, 0])
    F = m_sl * a - m_sl * g
    assert np.allclose(res.reaction_force(rail), F, atol=1e-7)
    Jg = R @ J_sl @ np.swapaxes(R, 1, 2)
    dH = np.einsum("nij,nj->ni", Jg, Wd) + np.cross(W, np.einsum("nij,nj->ni", Jg, W))
    P_j = P + apply(R, Q - P) + s[:, None] * ru        # joint point fixed on the slider
    assert np.allclose(res.reaction_torque(rail), dH + np.cross(P + rho - P_j, F), atol=1e-7)
    # in the slider's axes too
    assert np.allclose(res.reaction_force(rail, frame=sl), in_axes(R, F), atol=1e-7)
    # on the arm: the opposite wrench, reduced to the joint point fixed on the arm
    P_i = P + apply(R, Q - P)
    assert np.allclose(res.reaction_force(rail, on=arm), -F, atol=1e-7)
    assert np.allclose(res.reaction_torque(rail, on=arm),
                       -(res.reaction_torque(rail) + np.cross(P_j - P_i, F)), atol=1e-7)


# ----------------------------------------------------------------------------- particle on an inclined plane
def inclined_projectile():
    n = unit((0.3, 1.0, 0.2))
    P0 = np.array([0.2, 0.1, -0.3])
    v0 = np.array([1.0, 3.0, -0.5])
    v0 = v0 - (v0 @ n) * n
    model = mb.Model("incline", gravity=(0.0, -G, 0.0))
    p = model.add_particle("p", 0.8, position=P0, velocity=v0)
    pl = model.add_planar("plane", model.ground, p, (1.0, -2.0, 0.5), n)
    return model, p, pl, n, P0, v0


@pytest.mark.parametrize("method", ["dop853", "hht"])
def test_projectile_on_an_inclined_plane_at_crossings_maximum(method):
    """r = r0 + v0 t + g_par t^2 / 2 with g_par the in-plane gravity; the apex and the return to the
    start height come out of res.maximum / res.crossings; the plane pushes with -m (g.n) n."""
    model, p, pl, n, P0, v0 = inclined_projectile()
    g = np.array([0, -G, 0])
    gp = g - (g @ n) * n
    kw = TIGHT if method == "dop853" else dict(method="hht")
    res = mb.simulate(model, 1.0, 0.01, **kw)
    assert res.success, res.message
    tol = 1e-9 if method == "dop853" else 1e-6
    t = res.time
    assert np.allclose(res.position(p), P0 + np.outer(t, v0) + 0.5 * np.outer(t**2, gp), atol=tol)
    assert np.allclose(res.velocity(p), v0 + np.outer(t, gp), atol=tol)
    assert np.allclose(res.acceleration(p), np.broadcast_to(gp, (len(t), 3)), atol=100 * tol)
    assert np.allclose(res.reaction_force(pl), np.broadcast_to(-0.8 * (g @ n) * n, (len(t), 3)), atol=100 * tol)
    t_apex = -v0[1] / gp[1]
    ta, ya = res.maximum(lambda r: r.position(p)[:, 1])
    assert ta == pytest.approx(t_apex, abs=1e-5)
    assert ya == pytest.approx(P0[1] + v0[1] * t_apex + 0.5 * gp[1] * t_apex**2, abs=tol)
    back = res.crossings(lambda r: r.position(p)[:, 1], P0[1], direction=-1)
    assert back[-1] == pytest.approx(2 * t_apex, abs=10 * tol)
    sub = res.at([0.123, 0.777])
    assert np.allclose(sub.position(p), P0 + np.outer(sub.time, v0) + 0.5 * np.outer(sub.time**2, gp), atol=tol)


# ----------------------------------------------------------------------------- two-body oscillator
def test_spring_damper_between_two_free_particles_reduced_mass_and_centre_of_mass():
    m1, m2, k, c, L0 = 0.6, 1.4, 250.0, 1.5, 0.4
    e = unit((1.0, 2.0, -0.7))
    r1, r2 = np.array([0.1, 0.2, 0.3]), np.array([0.1, 0.2, 0.3]) + 0.5 * e
    vt = np.array([0.3, -0.1, 0.2])                       # common velocity; relative velocity along e
    v1, v2 = vt - 0.4 * e, vt + 0.2 * e
    g = np.array([0.0, 0.0, -G])
    model = mb.Model("two_body", gravity=g)
    a, b = model.add_particle("a", m1, r1, v1), model.add_particle("b", m2, r2, v2)
    sp = model.add_spring_damper("s", a, b, k, damping=c, free_length=L0)
    res = mb.simulate(model, 2.0, 0.01, **TIGHT)
    assert res.success, res.message
    t = res.time
    mu = m1 * m2 / (m1 + m2)
    sig, wd = c / (2 * mu), np.sqrt(k / mu - (c / (2 * mu)) ** 2)
    x0, xd0 = 0.5 - L0, 0.6
    x = np.exp(-sig * t) * (x0 * np.cos(wd * t) + (xd0 + sig * x0) / wd * np.sin(wd * t))
    xd = np.exp(-sig * t) * (xd0 * np.cos(wd * t) - (sig * xd0 + (sig**2 + wd**2) * x0) / wd * np.sin(wd * t))
    assert np.allclose(res.spring_length(sp), L0 + x, atol=1e-9)
    assert np.allclose(res.spring_velocity(sp), xd, atol=1e-8)
    assert np.allclose(res.spring_force(sp), k * x + c * xd, atol=1e-6)
    rc0, vc0 = (m1 * r1 + m2 * r2) / (m1 + m2), (m1 * v1 + m2 * v2) / (m1 + m2)
    rc = (m1 * res.position(a) + m2 * res.position(b)) / (m1 + m2)
    assert np.allclose(rc, rc0 + np.outer(t, vc0) + 0.5 * np.outer(t**2, g), atol=1e-9)
    assert np.allclose(res.position(b) - res.position(a), np.outer(L0 + x, e), atol=1e-9)
    # energy: kinetic + potential + dissipated is constant
    E = res.kinetic_energy() + res.potential_energy() + res.dissipated_energy()
    assert np.ptp(E) < 1e-8 * abs(E[0])
    # the default method agrees to a looser tolerance
    hht = mb.simulate(model, 2.0, 0.01)
    assert np.allclose(hht.spring_length("s"), L0 + x, atol=2e-4)


# ----------------------------------------------------------------------------- state-dependent loads
def test_force_callable_of_time_and_position_in_rotated_marker_axes():
    """F = -k r + F0 sin(W t) e, written by the callable in the axes of a rotated ground marker:
    the undamped forced oscillator from rest at the origin, x = F0/m/(w0^2-W^2) (sin Wt - W/w0 sin w0 t)."""
    m_, k, F0, W = 0.5, 20.0, 1.3, 3.0
    e = unit((0.5, -1.0, 2.0))
    Rm = Rotation.from_rotvec([0.7, -0.3, 1.2]).as_matrix()
    model = mb.Model("forced")
    p = model.add_particle("p", m_, position=(0, 0, 0))
    mk = model.ground.add_marker("axes", point=(1.0, 1.0, 1.0), orientation=Rm)
    seen = []

    def force(t, state):
        r = state.position(p)
        seen.append(np.shape(r))
        return Rm.T @ (-k * r + F0 * np.sin(W * t) * e)
    model.add_force("drive", p, force, frame=mk)
    res = mb.simulate(model, 3.0, 0.01, **TIGHT)
    assert res.success, res.message
    assert seen and all(s == (3,) for s in seen)
    t = res.time
    w0 = np.sqrt(k / m_)
    x = F0 / m_ / (w0**2 - W**2) * (np.sin(W * t) - W / w0 * np.sin(w0 * t))
    assert np.allclose(res.position(p), np.outer(x, e), atol=1e-9)


def test_body_fixed_torque_on_a_spinning_symmetric_body_full_inertia_matrix():
    """Symmetric body (I, I, I3) spun about its symmetry axis, constant torque along a transverse principal
    axis (given in a marker's axes): Euler's equations give w1 = T/(I Om) sin Om t,
    w2 = T/(I Om)(1 - cos Om t), w3 constant, Om = (I3 - I)/I w3.  The principal axes are rotated relative
    to the body axes (full 3x3 inertia), the body orientation is a scipy Rotation."""
    I, I3, w3, Tq = 0.2, 0.35, 10.0, 0.3   # I3 < 2 I: a physical body (triangle inequality)
    Rp = Rotation.from_rotvec([0.3, 0.5, -0.2]).as_matrix()          # principal axes in body axes
    J = Rp @ np.diag([I, I, I3]) @ Rp.T
    A = Rotation.from_rotvec([-0.6, 0.2, 0.9])
    Ap = A.as_matrix() @ Rp                                           # principal axes -> ground
    model = mb.Model("spin")
    body = model.add_body("top", 3.0, inertia=J, position=(0.1, 0.2, 0.3), orientation=A,
                          velocity=(0.5, 0, 0), angular_velocity=Ap @ [0, 0, w3])
    pa = body.add_marker("principal", orientation=Ap)
    model.add_torque("kick", body, (Tq, 0.0, 0.0), frame=pa)
    res = mb.simulate(model, 1.0, 0.01, **TIGHT)
    assert res.success, res.message
    t = res.time
    Om = (I3 - I) / I * w3
    ref = np.stack([Tq / (I * Om) * np.sin(Om * t), Tq / (I * Om) * (1 - np.cos(Om * t)), w3 + 0 * t], -1)
    assert np.allclose(res.angular_velocity(body, frame=pa), ref, atol=1e-9)
    assert np.allclose(res.position(body), np.array([0.1, 0.2, 0.3]) + np.outer(t, [0.5, 0, 0]), atol=1e-10)
    # angular momentum in ground changes at the rate of the (rotating) applied torque: H(t) - H(0) = int T dt
    Rt = res.orientation(body) @ Rp
    Hg = np.einsum("nij,j,nj->ni", Rt, [I, I, I3], res.angular_velocity(body, frame=pa))
    Tg = Rt[:, :, 0] * Tq
    integral = np.concatenate([[np.zeros(3)], np.cumsum(0.5 * (Tg[1:] + Tg[:-1]) * np.diff(t)[:, None], 0)])
    assert np.allclose(Hg - Hg[0], integral, atol=2e-4)   # trapezoid rule on 0.01 s samples
    # kinetic energy grows by the torque's power
    Ek = res.kinetic_energy()
    assert Ek[0] == pytest.approx(0.5 * 3.0 * 0.25 + 0.5 * I3 * w3**2, rel=1e-12)


# ----------------------------------------------------------------------------- assembly
def test_assemble_moves_a_slider_crank_to_the_driver_angle():
    """The crank driver asks for 0.3 rad more than the model's configuration at t = 0: assembly turns the
    crank, moves the rod and slider to the closed-form slider position, and the velocities follow."""
    R_, L_, th0 = 0.12, 0.35, 0.7
    x_of = lambda th: R_ * np.cos(th) + np.sqrt(L_**2 - (R_ * np.sin(th)) ** 2)  # noqa: E731
    A_pt = np.array([R_ * np.cos(th0), R_ * np.sin(th0), 0.0])
    B_pt = np.array([x_of(th0), 0.0, 0.0])
    model = mb.Model("crank", gravity=(0, -G, 0))
    crank = model.add_body("crank", 1.0, inertia=(1e-4, 1e-3, 1e-3), position=A_pt / 2,
                           orientation=Rotation.from_rotvec([0, 0, th0]))
    rod = model.add_body("rod", 0.5, inertia=(1e-4, 5e-3, 5e-3), position=(A_pt + B_pt) / 2)
    slider = model.add_body("slider", 0.8, inertia=(1e-3, 1e-3, 1e-3), position=B_pt)
    o = model.add_revolute("O", model.ground, crank, (0, 0, 0), (0, 0, 1))
    model.add_spherical("A", crank, rod, A_pt)
    model.add_universal("B", rod, slider, B_pt, (0, 0, 1), (0, 1, 0))
    model.add_translational("slide", model.ground, slider, B_pt, (1, 0, 0))
    model.add_motion("drive", o, displacement="0.3 + 2*t")
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # no redundancy in this topology
        rep = mb.assemble(model)
    assert rep.dof == 0 and rep.residual < 1e-10
    th1 = th0 + 0.3
    assert set(rep.moved) == {"crank", "rod", "slider"}
    assert rep.moved["slider"][0] == pytest.approx(abs(x_of(th1) - x_of(th0)), abs=1e-10)
    assert rep.moved["crank"][0] == pytest.approx(2 * (R_ / 2) * np.sin(0.15), abs=1e-10)
    assert rep.moved["crank"][1] == pytest.approx(0.3, abs=1e-9)
    assert "moved slider" in str(rep)
    res = mb.kinematics(model, 0.4, 0.1)
    th = th1 + 2 * res.time
    xs = x_of(th)
    assert np.allclose(res.position(slider)[:, 0] - res.position(slider)[0, 0], xs - xs[0], atol=1e-10)
    assert np.allclose(res.position(slider)[:, 0], xs, atol=1e-10)
    xdot = -2 * R_ * np.sin(th) * (1 + R_ * np.cos(th) / np.sqrt(L_**2 - (R_ * np.sin(th)) ** 2))
    assert np.allclose(res.velocity(slider)[:, 0], xdot, atol=1e-9)


# ----------------------------------------------------------------------------- statics: two springs
def test_equilibrium_of_a_particle_hung_on_two_skew_springs():
    m_, g = 1.2, np.array([0.0, 0.0, -G])
    A1, A2 = np.array([-0.5, 0.1, 1.0]), np.array([0.6, -0.2, 1.2])
    k1, k2, L1, L2 = 150.0, 90.0, 0.7, 0.9
    start = np.array([0.0, 0.3, 0.3])
    model = mb.Model("hang", gravity=g)
    p = model.add_particle("p", m_, position=start)
    s1 = model.add_spring_damper("s1", (model.ground, A1), p, k1, free_length=L1, damping=2.0)
    s2 = model.add_spring_damper("s2", (model.ground, A2), p, k2, free_length=L2, preload=1.5)

    def net(x):
        F = m_ * g
        for A, k, L0, pre in ((A1, k1, L1, 0.0), (A2, k2, L2, 1.5)):
            d = A - x
            L = np.linalg.norm(d)
            F = F + (k * (L - L0) + pre) * d / L
        return F
    x_eq = fsolve(net, start, xtol=1e-14)
    assert np.linalg.norm(net(x_eq)) < 1e-10
    res = mb.equilibrium(model)
    assert res.success
    assert np.allclose(res.position(p)[0], x_eq, atol=1e-9)
    L1e, L2e = np.linalg.norm(A1 - x_eq), np.linalg.norm(A2 - x_eq)
    assert res.spring_force(s1)[0] == pytest.approx(k1 * (L1e - L1), abs=1e-7)
    assert res.spring_force(s2)[0] == pytest.approx(k2 * (L2e - L2) + 1.5, abs=1e-7)
    V = -m_ * g @ x_eq + 0.5 * k1 * (L1e - L1) ** 2 + 0.5 * k2 * (L2e - L2) ** 2
    # potential: gravity + springs, the preload's tension doing work like a constant force
    assert res.potential_energy()[0] == pytest.approx(V + 1.5 * (L2e - L2), abs=1e-9)


# ----------------------------------------------------------------------------- kinematics: at / crossings / max
def test_kinematics_at_crossings_and_maximum_on_a_driven_skew_crank():
    n = unit((0.0, 1.0, 1.0))
    model = mb.Model("crank", gravity=(0, -G, 0))
    arm = model.add_body("arm", 1.0, inertia=(0.01, 0.02, 0.03), position=(0.3, 0.0, 0.0))
    pin = model.add_revolute("pin", model.ground, arm, (0, 0, 0), n)
    model.add_motion("m", pin, displacement=lambda t: np.sin(2 * t) + 0.3 * t)
    res = mb.kinematics(model, 1.5, 0.1)
    assert res.success, res.message
    th = lambda t: np.sin(2 * t) + 0.3 * t  # noqa: E731
    t_max = 0.5 * np.arccos(-0.15)
    tm, vm = res.maximum(lambda r: r.joint_coordinate(pin))
    assert tm == pytest.approx(t_max, abs=1e-6) and vm == pytest.approx(th(t_max), abs=1e-10)
    t_cross = brentq(lambda t: th(t) - 0.5, 0.0, t_max)
    assert res.crossings(lambda r: r.joint_coordinate(pin), 0.5, direction=+1) == pytest.approx([t_cross], abs=1e-9)
    # position of the arm's CM at off-grid times: rotation of (0.3, 0, 0) about n
    ts = np.array([0.0123, 0.456, 1.3333])
    sub = res.at(ts)
    assert np.allclose(sub.position(arm), apply(rot_about(n, th(ts)), [0.3, 0.0, 0.0]), atol=1e-10)
    assert np.allclose(sub.joint_velocity(pin), 2 * np.cos(2 * ts) + 0.3, atol=1e-8)
    # the CM reaches its lowest point (min y) where the rotated x-axis points most downwards
    y = lambda t: apply(rot_about(n, th(np.atleast_1d(t))), [0.3, 0.0, 0.0])[:, 1]  # noqa: E731
    tn, yn = res.minimum(lambda r: r.position(arm)[:, 1])
    grid = np.linspace(0, 1.5, 15001)
    assert yn == pytest.approx(y(grid).min(), abs=1e-8)


# ----------------------------------------------------------------------------- torsion spring on a cylinder
def test_torsion_spring_on_a_skew_cylindrical_joint_slides_freely():
    """Rotation: I theta'' + c theta' + k theta = 0 with I about the axis (full inertia, CM off the axis);
    the slide is free: s = v_s t (centripetal loads are normal to the axis)."""
    n, P = unit((1.0, -0.5, 0.8)), np.array([0.2, 0.0, 0.1])
    J = np.array([[0.03, 0.004, 0.0], [0.004, 0.05, -0.002], [0.0, -0.002, 0.04]])
    rot = Rotation.from_rotvec([0.2, 0.3, -0.1])
    m_, rC, w0, vs, k, c = 1.1, 0.15, 4.0, 0.3, 12.0, 0.05
    off = rC * unit(np.cross(n, (0, 0, 1.0)))
    C = P + 0.1 * n + off
    model = mb.Model("cyl")
    b = model.add_body("b", m_, inertia=J, position=C, orientation=rot,
                       velocity=w0 * np.cross(n, C - P) + vs * n, angular_velocity=w0 * n)
    cyl = model.add_cylindrical("cyl", model.ground, b, P, n)
    ts = model.add_torsion_spring("ts", cyl, k, damping=c)
    res = mb.simulate(model, 2.0, 0.01, **TIGHT)
    assert res.success, res.message
    Ia = float(n @ rot.as_matrix() @ J @ rot.as_matrix().T @ n) + m_ * rC**2
    sig = c / (2 * Ia)
    wd = np.sqrt(k / Ia - sig**2)
    t = res.time
    th = w0 / wd * np.exp(-sig * t) * np.sin(wd * t)
    thd = w0 * np.exp(-sig * t) * (np.cos(wd * t) - sig / wd * np.sin(wd * t))
    q = res.joint_coordinate(cyl)
    assert q.shape == (len(t), 2)
    assert np.allclose(q[:, 0], th, atol=1e-9)
    assert np.allclose(q[:, 1], vs * t, atol=1e-9)
    assert np.allclose(res.joint_velocity(cyl), np.stack([thd, vs + 0 * t], -1), atol=1e-8)
    assert np.allclose(res.spring_length(ts), th, atol=1e-9)
    assert np.allclose(res.spring_force(ts), k * th + c * thd, atol=1e-7)
    E = res.kinetic_energy() + res.potential_energy() + res.dissipated_energy()
    assert np.ptp(E) < 1e-8 * E[0]
    df = res.to_dataframe()
    assert np.allclose(df["cyl.angle [rad]"], th, atol=1e-9)
    assert np.allclose(df["cyl.displacement [m]"], vs * t, atol=1e-9)
    assert np.allclose(df["cyl.displacement_rate [m/s]"], vs, atol=1e-9)
    assert np.allclose(df["cyl.angle_rate [rad/s]"], thd, atol=1e-8)


# ----------------------------------------------------------------------------- sphere-sphere impact
def test_sphere_sphere_head_on_impact_restitution_against_scipy():
    """Two particles carrying spheres meet head-on along a skew line.  The relative coordinate obeys
    mu delta'' = -Fn(delta, delta') with the IMPACT law; scipy integrates it independently and gives the
    exit relative speed; momentum is conserved exactly; the onset time is gap / closing speed."""
    m1, m2, r1, r2 = 1.0, 2.0, 0.1, 0.15
    k, ex, cmax, d = 1e5, 1.5, 40.0, 1e-3
    e = unit((1.0, 0.5, -0.3))
    gap0, v1, v2 = 0.05, 2.0, -0.5
    p1 = np.zeros(3)
    p2 = p1 + (r1 + r2 + gap0) * e
    model = mb.Model("spheres")
    a = model.add_particle("a", m1, p1, v1 * e)
    b = model.add_particle("b", m2, p2, v2 * e)
    model.add_contact("hit", mb.Sphere(a, r1), mb.Sphere(b, r2), k, ex, cmax, d)
    res = mb.simulate(model, 0.1, 0.001, **TIGHT)
    assert res.success, res.message
    mu = m1 * m2 / (m1 + m2)

    def rhs(t, y):
        dl, dld = y
        u = min(max(dl, 0.0) / d, 1.0)
        F = max(0.0, k * max(dl, 0.0) ** ex + cmax * u * u * (3 - 2 * u) * dld) if dl > 0 else 0.0
        return [dld, -F / mu]
    sep = lambda t, y: y[0]  # noqa: E731
    sep.terminal, sep.direction = True, -1
    sol = solve_ivp(rhs, (0, 1.0), [0.0, v1 - v2], rtol=1e-12, atol=1e-14, events=sep, max_step=1e-5)
    t_on = gap0 / (v1 - v2)
    t_off = t_on + sol.t_events[0][0]
    vrel_out = -sol.y_events[0][0][1]                    # separating speed
    assert 0 < vrel_out < v1 - v2
    on = res.crossings(lambda r: r.spring_length("hit"), 0.0)
    assert on[0] == pytest.approx(t_on, abs=1e-9)
    assert on[1] == pytest.approx(t_off, abs=1e-7)
    vc = (m1 * v1 + m2 * v2) / (m1 + m2)
    end = res.at(res.time[-1])
    assert end.velocity(a)[0] == pytest.approx((vc - m2 / (m1 + m2) * vrel_out) * e, abs=1e-6)
    assert end.velocity(b)[0] == pytest.approx((vc + m1 / (m1 + m2) * vrel_out) * e, abs=1e-6)
    mom = m1 * res.velocity(a) + m2 * res.velocity(b)
    assert np.allclose(mom, (m1 * v1 + m2 * v2) * e, atol=1e-9)
    KE0 = 0.5 * m1 * v1**2 + 0.5 * m2 * v2**2
    lost = 0.5 * mu * ((v1 - v2) ** 2 - vrel_out**2)
    assert res.dissipated_energy()[-1] == pytest.approx(lost, rel=1e-6)
    assert res.kinetic_energy()[-1] == pytest.approx(KE0 - lost, rel=1e-7)


# ----------------------------------------------------------------------------- bushing with rotated axes
def test_bushing_with_rotated_marker_axes_static_deflection_and_vibration():
    """Translational stiffness diag(k) in marker_i axes R: K_ground = R diag(k) R^T, so the static
    deflection under gravity is K_ground^-1 m g; a velocity along a marker axis vibrates at sqrt(k/m)."""
    kx, ky, kz, m_ = 4000.0, 2500.0, 9000.0, 2.0
    R = Rotation.from_rotvec([0.5, -0.4, 0.8]).as_matrix()
    P = np.array([0.3, -0.1, 0.2])
    g = np.array([0.0, -G, 0.0])

    def build(grav, vel=(0, 0, 0)):
        model = mb.Model("bush", gravity=grav)
        body = model.add_body("b", m_, inertia=(0.01, 0.02, 0.03), position=P, velocity=vel,
                              orientation=Rotation.from_rotvec([0.1, 0.1, 0.1]))
        mi = model.ground.add_marker("mi", point=P, orientation=R)
        mj = body.add_marker("mj", point=P, orientation=R)
        model.add_bushing("bush", mi, mj, stiffness=(kx, ky, kz, 50, 60, 70), damping=(0,) * 6)
        return model, body
    model, body = build(g)
    res = mb.equilibrium(model)
    Kg = R @ np.diag([kx, ky, kz]) @ R.T
    assert np.allclose(res.position(body)[0], P + np.linalg.solve(Kg, m_ * g), atol=1e-10)
    assert np.allclose(res.orientation(body)[0], Rotation.from_rotvec([0.1, 0.1, 0.1]).as_matrix(), atol=1e-9)
    v0 = 0.2
    model, body = build((0, 0, 0), vel=v0 * R[:, 1])
    res = mb.simulate(model, 0.2, 0.002, **TIGHT)
    w = np.sqrt(ky / m_)
    assert np.allclose(res.position(body), P + np.outer(v0 / w * np.sin(w * res.time), R[:, 1]), atol=1e-9)


# ----------------------------------------------------------------------------- export
def test_to_dataframe_units_for_a_translational_joint_on_a_particle_and_a_spherical_joint():
    model = mb.Model("df", gravity=(0, 0, -G))
    p = model.add_particle("bead", 0.3, position=(1.0, 0.0, 0.0), velocity=(0.0, 0.0, 2.0))
    rail = model.add_translational("rail", model.ground, p, (1, 0, 0), (0, 0, 1))
    ball = model.add_body("ball", 1.0, inertia=(0.1, 0.1, 0.1), position=(0, 0, -1.0),
                          angular_velocity=(0.0, 0.0, 3.0))
    model.add_spherical("socket", model.ground, ball, (0, 0, 0))
    res = mb.simulate(model, 0.3, 0.1, **TIGHT)
    df = res.to_dataframe()
    t = res.time
    assert np.allclose(df["rail.displacement [m]"], 2 * t - 0.5 * G * t**2, atol=1e-10)
    assert np.allclose(df["rail.displacement_rate [m/s]"], 2 - G * t, atol=1e-10)
    assert np.allclose(df["bead.z [m]"], 2 * t - 0.5 * G * t**2, atol=1e-10)
    assert np.allclose(df["ball.wz [rad/s]"], 3.0, atol=1e-10)      # hanging ball keeps spinning
    assert {"socket.rx [rad]", "socket.wz [rad/s]", "socket.Fz [N]"} <= set(df.columns)   # every joint kind
    assert not any(c.startswith("bead.w") for c in df.columns)
    for c in df.columns:
        assert c.endswith(("[m]", "[m/s]", "[m/s^2]", "[rad]", "[rad/s]", "[rad/s^2]", "[s]", "[-]", "[N]",
                           "[N m]")), c


# ----------------------------------------------------------------------------- universal joint (Cardan shaft)
def test_cardan_joint_between_skew_shafts_output_angle_and_speed_ratio():
    """Input shaft driven at phi1 = 2t; the output shaft (angle beta to it) turns so that the cross
    stays perpendicular: (R(a1, phi1) e_i) . (R(a2, phi2) e_j) = 0, solved here with brentq; the speed
    ratio swings between cos(beta) and 1/cos(beta)."""
    beta = 0.5
    O = np.array([0.1, 0.2, 0.3])
    a1 = unit((1.0, 0.2, 0.1))
    p = unit(np.cross(a1, (0, 0, 1.0)))                       # normal of the plane of the shafts
    a2 = Rotation.from_rotvec(beta * p).apply(a1)
    e_i, e_j = p, unit(np.cross(a2, p))
    model = mb.Model("cardan", gravity=(0, 0, -G))
    s1 = model.add_body("in", 1.0, inertia=(0.01, 0.1, 0.1), position=O - 0.3 * a1,
                        orientation=Rotation.from_rotvec([0.2, 0.0, 0.1]))
    s2 = model.add_body("out", 1.5, inertia=[[0.02, 0.001, 0], [0.001, 0.1, 0], [0, 0, 0.1]], position=O + 0.4 * a2)
    r1 = model.add_revolute("bearing_in", model.ground, s1, O - 0.3 * a1, a1)
    r2 = model.add_revolute("bearing_out", model.ground, s2, O + 0.4 * a2, a2)
    model.add_universal("cross", s1, s2, O, e_i, e_j)
    model.add_motion("drive", r1, displacement="2*t")
    T0 = 3.0
    model.add_torque("load", s2, -T0 * a2)                  # a resisting torque on the output shaft
    with warnings.catch_warnings():     # the cross and two bearings close a loop: 3 redundant rows
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.kinematics(model, 2.0, 0.05)
    assert res.success, res.message

    def phi2(phi1):
        f = lambda x: float(rot_about(a1, phi1)[0] @ e_i @ rot_about(a2, x)[0] @ e_j)  # noqa: E731
        return brentq(f, phi1 - 0.5, phi1 + 0.5, xtol=1e-15)
    ref = np.array([phi2(x) for x in 2 * res.time])
    assert np.allclose(res.joint_coordinate(r2), ref, atol=1e-9)
    h = 1e-6
    ratio = np.array([(phi2(x + h) - phi2(x - h)) / (2 * h) for x in 2 * res.time])
    assert np.allclose(res.joint_velocity(r2), 2 * ratio, atol=1e-7)
    w2 = res.joint_velocity(r2) / 2
    assert w2.min() == pytest.approx(np.cos(beta), abs=1e-3) and w2.max() == pytest.approx(1 / np.cos(beta), abs=2e-3)
    assert np.allclose(res.angular_velocity(s2), np.outer(res.joint_velocity(r2), a2), atol=1e-9)
    # power balance (determinate despite the redundancy): T_drive w1 = T0 w2 + I2 w2 alpha2, the output
    # shaft's CM on its axis, I2 its inertia about the axis; alpha2 = w1^2 phi2''(phi1)
    h = 1e-4
    curv = np.array([(phi2(x + h) - 2 * phi2(x) + phi2(x - h)) / h**2 for x in 2 * res.time])
    w2, al2 = 2 * ratio, 4 * curv
    assert np.allclose(res.joint_acceleration(r2), al2, atol=1e-5)
    I2 = float(a2 @ np.array([[0.02, 0.001, 0], [0.001, 0.1, 0], [0, 0, 0.1]]) @ a2)
    assert np.allclose(res.reaction_torque(r1) @ a1, (T0 * w2 + I2 * w2 * al2) / 2.0, atol=1e-6)
    assert np.allclose(res.reaction_torque(r2) @ a2, 0.0, atol=1e-9)       # a free bearing passes no torque


# ----------------------------------------------------------------------------- spherical joint: conical pendulum
def test_conical_pendulum_on_a_spherical_joint_steady_precession():
    """A body with isotropic central inertia hanging from a spherical joint, turning rigidly about the vertical
    through the pivot on a cone of half-angle a: the gyroscopic term of an isotropic body vanishes, so
    Omega^2 = g / (L cos a) as for a point mass; the joint force is m g / cos a along the link, no torque."""
    L, a, m_, j = 0.8, 0.6, 0.9, 0.02
    Om = np.sqrt(G / (L * np.cos(a)))
    piv = np.array([0.2, -0.1, 1.5])
    r0 = piv + L * np.array([np.sin(a), 0.0, -np.cos(a)])
    A0 = Rotation.from_rotvec([0.3, -0.2, 0.5])
    model = mb.Model("cone", gravity=(0, 0, -G))
    bob = model.add_body("bob", m_, inertia=(j, j, j), position=r0, orientation=A0,
                         velocity=(0.0, Om * L * np.sin(a), 0.0), angular_velocity=(0.0, 0.0, Om))
    sph = model.add_spherical("socket", model.ground, bob, piv)
    res = mb.simulate(model, 2.0, 0.02, **TIGHT)
    assert res.success, res.message
    t = res.time
    ref = piv + L * np.stack([np.sin(a) * np.cos(Om * t), np.sin(a) * np.sin(Om * t), -np.cos(a) + 0 * t], -1)
    assert np.allclose(res.position(bob), ref, atol=1e-8)
    assert np.allclose(res.orientation(bob), rot_about([0, 0, 1.0], Om * t) @ A0.as_matrix(), atol=1e-8)
    d = (piv - res.position(bob)) / L
    assert np.allclose(res.reaction_force(sph), (m_ * G / np.cos(a)) * d, atol=1e-7)
    assert np.allclose(res.reaction_torque(sph), 0.0, atol=1e-7)
    hht = mb.simulate(model, 2.0, 0.02)
    assert hht.success, hht.message
    assert np.allclose(hht.position(bob), ref, atol=1e-3)


# ----------------------------------------------------------------------------- angle continuation
def test_joint_angle_is_unwrapped_even_with_more_than_pi_per_output_step():
    """A free wheel spinning at 20 rad/s sampled every 0.25 s (5 rad per sample): the joint coordinate is
    20 t in every analysis, in the DataFrame and from res.at."""
    w = 20.0
    model = mb.Model("wheel")
    wheel = model.add_body("wheel", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.5, 0, 0), velocity=(0, 0.5 * w, 0),
                           angular_velocity=(0, 0, w))
    axle = model.add_revolute("axle", model.ground, wheel, (0, 0, 0), (0, 0, 1))
    for res, tol in ((mb.simulate(model, 1.0, 0.25, **TIGHT), 1e-8), (mb.simulate(model, 1.0, 0.25), 1e-3)):
        assert np.allclose(res.joint_coordinate(axle), w * res.time, atol=tol)
        assert np.allclose(res.to_dataframe()["axle.angle [rad]"], w * res.time, atol=tol)
        assert np.allclose(res.at([0.3, 0.9]).joint_coordinate(axle), [6.0, 18.0], atol=tol)
    model = mb.Model("driven")
    wheel = model.add_body("wheel", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.5, 0, 0))
    axle = model.add_revolute("axle", model.ground, wheel, (0, 0, 0), (0, 0, 1))
    model.add_motion("spin", axle, displacement=lambda t: w * t)
    res = mb.kinematics(model, 1.0, 0.25)
    assert np.allclose(res.joint_coordinate(axle), w * res.time, atol=1e-9)


def test_torsion_spring_wound_beyond_half_a_turn_in_kinematics_and_statics():
    """A motor winds a torsion spring (k = 2 N m/rad) 4 rad/s for 1.5 s: the drive torque is k theta past pi
    (no 2 pi k jump); a constant torque of 10 N m winds it to the static angle 5 rad."""
    k = 2.0
    model = mb.Model("wind")
    drum = model.add_body("drum", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.3, 0, 0))
    axle = model.add_revolute("axle", model.ground, drum, (0, 0, 0), (0, 0, 1))
    ts = model.add_torsion_spring("clock", axle, k)
    model.add_motion("motor", axle, displacement="4*t")
    res = mb.kinematics(model, 1.5, 0.1)
    th = 4 * res.time
    assert np.allclose(res.spring_length(ts), th, atol=1e-12)
    assert np.allclose(res.spring_force(ts), k * th, atol=1e-12)
    assert np.allclose(res.reaction_torque(axle)[:, 2], k * th, atol=1e-9)      # the motor holds the spring
    sub = res.at([1.23])
    assert sub.reaction_torque(axle)[0, 2] == pytest.approx(k * 4 * 1.23, abs=1e-9)
    model = mb.Model("wound")
    drum = model.add_body("drum", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.3, 0, 0))
    axle = model.add_revolute("axle", model.ground, drum, (0, 0, 0), (0, 0, 1))
    ts = model.add_torsion_spring("clock", axle, k, free_angle=0.5)
    model.add_torque("load", drum, (0.0, 0.0, 10.0))
    res = mb.equilibrium(model)
    assert res.joint_coordinate(axle)[0] == pytest.approx(10.0 / k + 0.5, abs=1e-9)
    assert res.spring_length(ts)[0] == pytest.approx(10.0 / k + 0.5, abs=1e-9)
    assert res.spring_force(ts)[0] == pytest.approx(10.0, abs=1e-8)


@pytest.mark.parametrize("method", ["dop853", "hht"])
def test_pd_controller_through_state_to_a_target_beyond_pi(method):
    """state.joint_coordinate continues past +-pi like Result.joint_coordinate: a PD controller drives the
    wheel to 4 rad and holds it (with a wrapped angle it would chase -2.28 rad forever)."""
    model = mb.Model("pd")
    wheel = model.add_body("wheel", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.3, 0, 0))
    axle = model.add_revolute("axle", model.ground, wheel, (0, 0, 0), (0, 0, 1))
    model.add_torque("pd", wheel, lambda t, s: (0, 0, -5.0 * (s.joint_coordinate(axle) - 4.0)
                                                  - 2.0 * s.joint_velocity(axle)))
    res = mb.simulate(model, 8.0, 0.5, method=method)
    assert res.success, res.message
    # I_axis = 0.1 + 1 * 0.3^2 = 0.19: theta'' = (-5 (theta - 4) - 2 theta') / 0.19, from rest at 0
    sol = solve_ivp(lambda t, y: [y[1], (-5 * (y[0] - 4) - 2 * y[1]) / 0.19], (0, 8), [0.0, 0.0],
                    t_eval=res.time, rtol=1e-12, atol=1e-12)
    assert np.allclose(res.joint_coordinate(axle), sol.y[0], atol=1e-7 if method == "dop853" else 1e-3)


# ----------------------------------------------------------------------------- more input errors
def test_torque_on_a_particle_and_fixed_joint_by_body_names():
    model = mb.Model("e")
    p = model.add_particle("p", 1.0, position=(0, 1, 0))
    with pytest.raises(mb.ModelError) as ei:
        model.add_torque("spin", p, (0.0, 0.0, 1.0))
    assert (ei.value.entity, ei.value.field) == ("torque 'spin'", "body") and "particle" in str(ei.value)
    assert "spin" not in model.forces
    b = model.add_body("b", 2.0, inertia=(1, 1, 1), position=(0.4, 0.2, 0.0))
    weld = model.add_fixed("weld", "ground", "b")          # bodies by name, point defaults to b's CM
    assert np.allclose(weld.point, (0.4, 0.2, 0.0))


def test_maximum_of_a_plateau_and_of_a_peak_between_two_equal_samples():
    """A block thrown up a rough slope stops at s = v0^2 / (2 g (sin + mu cos)) and sticks: res.maximum
    finds that value on the plateau (it used to raise from the bracket search); a projectile whose apex lies
    exactly midway between two samples is refined to the apex."""
    th, mu, v0 = np.radians(15), 0.5, 3.0
    up = np.array([np.cos(th), np.sin(th), 0.0])
    model = mb.Model("rough", gravity=(0, -G, 0))
    blk = model.add_particle("block", 2.0, velocity=v0 * up)
    slope = model.add_translational("slope", model.ground, blk, (0, 0, 0), up)
    model.add_friction("friction", slope, 0.6, mu)
    res = mb.simulate(model, 1.0, 0.01, method="dop853")
    assert res.success, res.message
    a = G * (np.sin(th) + mu * np.cos(th))
    t_stop = v0 / a
    tm, xm = res.maximum(lambda r: r.joint_coordinate(slope))
    assert xm == pytest.approx(v0**2 / (2 * a), abs=1e-9)
    assert t_stop - 1e-9 <= tm <= t_stop + 0.01 + 1e-9
    tmin, xmin = res.minimum(lambda r: -r.joint_coordinate(slope))
    assert xmin == pytest.approx(-v0**2 / (2 * a), abs=1e-9) and abs(tmin - tm) < 0.02
    # apex at t = 0.305 s, samples at 0.30 and 0.31 s
    vy = 0.305 * G
    model = mb.Model("apex", gravity=(0, -G, 0))
    ball = model.add_particle("ball", 1.0, position=(0, 0, 0), velocity=(1.0, vy, 0))
    res = mb.simulate(model, 0.6, 0.01, **TIGHT)
    ta, ya = res.maximum(lambda r: r.position(ball)[:, 1])
    assert ta == pytest.approx(0.305, abs=1e-6) and ya == pytest.approx(vy**2 / (2 * G), abs=1e-12)


def test_follower_force_in_the_axes_of_a_marker_on_a_spinning_body():
    """A constant force F along a body-fixed direction through the CM of a body spinning at w about n (no
    torque, so the spin stays): the CM moves on x = F/(m w^2)(1 - cos wt), y = F/(m w)(t - sin(wt)/w)
    in the (e1, e2) plane normal to n."""
    F, m_, w = 2.0, 1.5, 3.0
    n = unit((0.2, 0.3, 1.0))
    e1 = unit(np.cross(n, (1.0, 0.0, 0.0)))
    e2 = np.cross(n, e1)
    model = mb.Model("follower")
    b = model.add_body("b", m_, inertia=(0.1, 0.1, 0.1), position=(0, 0, 0),
                       orientation=Rotation.from_rotvec([0.3, 0.2, -0.4]), angular_velocity=w * n)
    mk = b.add_marker("mk", orientation=np.column_stack([e1, e2, n]))
    model.add_force("push", mk, (F, 0.0, 0.0), frame=mk)
    res = mb.simulate(model, 2.0, 0.05, **TIGHT)
    t = res.time
    ref = np.outer(F / (m_ * w**2) * (1 - np.cos(w * t)), e1) + np.outer(F / (m_ * w) * (t - np.sin(w * t) / w), e2)
    assert np.allclose(res.position(b), ref, atol=1e-9)
    assert np.allclose(res.acceleration(mk, frame=mk), np.broadcast_to([F / m_, 0, 0], (len(t), 3)), atol=1e-8)
    assert np.allclose(res.angular_velocity(b), np.broadcast_to(w * n, (len(t), 3)), atol=1e-10)


def test_assembly_projects_an_inconsistent_velocity_onto_a_skew_slide():
    """Minimum-norm velocity correction on a particle sliding along u: v -> (v.u) u."""
    u = unit((1.0, 2.0, -0.5))
    v0 = np.array([0.3, -1.0, 2.0])
    model = mb.Model("slide", gravity=(0.0, -G, 0.0))
    p = model.add_particle("p", 1.0, position=(0.1, 0.2, 0.3), velocity=v0)
    model.add_translational("rail", model.ground, p, (0.1, 0.2, 0.3), u)
    rep = mb.assemble(model)
    assert rep.dof == 1 and not rep.moved
    assert rep.velocity_changed["p"] == pytest.approx(np.linalg.norm(v0 - (v0 @ u) * u), abs=1e-12)
    res = mb.simulate(model, 0.5, 0.05, **TIGHT)
    gu = np.array([0.0, -G, 0.0]) @ u
    t = res.time
    assert np.allclose(res.velocity(p), np.outer((v0 @ u) + gu * t, u), atol=1e-10)


@pytest.mark.parametrize("method", ["dop853", "hht"])
def test_solver_settings_are_checked_naming_the_field(method):
    """Negative tolerances or step limits used to hang HHT (atol < 0) or run it backwards in time
    (max_step < 0); each now raises a ModelError naming simulate.<field>."""
    model = mb.Model("args", gravity=(0, -G, 0))
    model.add_particle("p", 1.0)
    cases = [(dict(rtol=-1e-6), "rtol"), (dict(rtol=0.0), "rtol"), (dict(atol=-1.0), "atol"), (dict(atol=0.0), "atol"),
             (dict(max_step=-0.1), "max_step"), (dict(max_step=float("nan")), "max_step"),
             (dict(rtol="tight"), "rtol")]
    for kw, field in cases:
        with pytest.raises(mb.ModelError) as ei:
            mb.simulate(model, 1.0, 0.1, method=method, **kw)
        assert (ei.value.entity, ei.value.field) == ("simulate", field), str(ei.value)
    for kw, field in ((dict(output_step=float("nan")), "output_step"), (dict(output_step=float("inf")), "output_step"),
                      (dict(output_step="fine"), "output_step"), (dict(end_time="end"), "end_time")):
        kw = dict(dict(end_time=1.0, output_step=0.1), **kw)
        with pytest.raises(mb.ModelError) as ei:
            mb.simulate(model, method=method, **kw)
        assert (ei.value.entity, ei.value.field) == ("analysis", field), str(ei.value)
    with pytest.raises(mb.ModelError, match="simulate.method"):
        mb.simulate(model, 1.0, 0.1, method=3)
    res = mb.simulate(model, 0.2, 0.1, method=method, atol=1e-12, max_step=float("inf"))
    assert res.success and np.allclose(res.position("p")[:, 1], -0.5 * G * res.time**2, atol=1e-8)
    with pytest.raises(ValueError, match="outside"):
        res.at(float("nan"))


def test_cylindrical_joint_on_a_turning_arm_driven_in_both_coordinates():
    """Arm turned about n by a(t); a sleeve on a cylindrical joint along u (fixed on the arm) driven in rotation
    phi(t) and translation s(t): w_j = a' n + phi' u(t), alpha_j = a'' n + phi'' u(t) + a' phi' n x u(t),
    and the sleeve CM follows the rotated, slid point."""
    n, u = unit((0.0, 0.3, 1.0)), unit((1.0, -0.2, 0.4))
    P, Q = np.array([0.0, 0.1, 0.0]), np.array([0.3, 0.2, -0.1])
    C = Q + np.array([0.0, 0.05, 0.02])
    model = mb.Model("sleeve", gravity=(0, 0, -G))
    arm = model.add_body("arm", 1.0, inertia=(0.01, 0.05, 0.05), position=(Q + P) / 2)
    sleeve = model.add_body("sleeve", 0.4, inertia=[[2e-3, 1e-4, 0], [1e-4, 3e-3, 0], [0, 0, 2.5e-3]], position=C,
                            orientation=Rotation.from_rotvec([0.5, 0.0, 0.2]))
    hub = model.add_revolute("hub", model.ground, arm, P, n)
    cyl = model.add_cylindrical("cyl", arm, sleeve, Q, u)
    model.add_motion("turn", hub, displacement="0.8*t")
    model.add_motion("spin", cyl, displacement="3*t + 0.5*sin(2*t)", dof="rotation")
    model.add_motion("lift", cyl, acceleration="-0.6*cos(t)", initial_displacement=0.0, initial_velocity=0.2,
                     dof="translation")
    res = mb.kinematics(model, 2.0, 0.1)
    assert res.success, res.message
    t = res.time
    a, ad = 0.8 * t, 0.8 + 0 * t
    ph, phd, phdd = 3 * t + 0.5 * np.sin(2 * t), 3 + np.cos(2 * t), -2 * np.sin(2 * t)
    s, sd, sdd = 0.2 * t + 0.6 * (np.cos(t) - 1), 0.2 - 0.6 * np.sin(t), -0.6 * np.cos(t)
    q = res.joint_coordinate(cyl)
    assert np.allclose(q, np.stack([ph, s], -1), atol=1e-9)
    assert np.allclose(res.joint_velocity(cyl), np.stack([phd, sd], -1), atol=1e-9)
    assert np.allclose(res.joint_acceleration(cyl), np.stack([phdd, sdd], -1), atol=1e-8)
    Ra = rot_about(n, a)
    ut = apply(Ra, u)
    assert np.allclose(res.angular_velocity(sleeve), np.outer(ad, n) + phd[:, None] * ut, atol=1e-9)
    assert np.allclose(res.angular_acceleration(sleeve),
                       phdd[:, None] * ut + (ad * phd)[:, None] * np.cross(n, ut), atol=1e-8)
    # sleeve CM: rotate about the sleeve axis (through Q on the arm), slide along it, then turn with the arm
    Rs = rot_about(u, ph)
    local = Q - P + s[:, None] * u + apply(Rs, C - Q)
    assert np.allclose(res.position(sleeve), P + apply(Ra, local), atol=1e-9)
    assert np.allclose(res.orientation(sleeve), Ra @ Rs @ Rotation.from_rotvec([0.5, 0.0, 0.2]).as_matrix(),
                       atol=1e-9)


def test_spinning_puck_on_an_inclined_planar_joint_gyroscopic_reaction_torque():
    """A rigid puck (full inertia tensor, principal axes not along the plane normal) spinning at w about the
    normal n of an inclined planar joint: its CM follows the in-plane projectile, the spin stays, and the
    joint supplies F = m g_par - m g and, about the CM, the gyroscopic torque w x (J_g w)."""
    n = unit((0.3, 1.0, 0.2))
    g = np.array([0.0, -G, 0.0])
    gp = g - (g @ n) * n
    C0, v0 = np.array([0.2, 0.1, -0.3]), np.array([1.0, 3.0, -0.5])
    v0 = v0 - (v0 @ n) * n
    w, m_ = 7.0, 0.8
    J = np.array([[0.02, 0.003, -0.001], [0.003, 0.03, 0.002], [-0.001, 0.002, 0.025]])
    A0 = Rotation.from_rotvec([0.4, -0.3, 0.2]).as_matrix()
    P0 = C0 + np.array([0.05, -0.02, 0.04])
    P0 = P0 - ((P0 - C0) @ n) * n
    model = mb.Model("puck", gravity=g)
    puck = model.add_body("puck", m_, inertia=J, position=C0, orientation=A0, velocity=v0, angular_velocity=w * n)
    ice = model.add_planar("ice", model.ground, puck, P0, n)
    res = mb.simulate(model, 1.0, 0.05, **TIGHT)
    assert res.success, res.message
    t = res.time
    C = C0 + np.outer(t, v0) + 0.5 * np.outer(t**2, gp)
    assert np.allclose(res.position(puck), C, atol=1e-10)
    assert np.allclose(res.angular_velocity(puck), np.broadcast_to(w * n, (len(t), 3)), atol=1e-10)
    R = rot_about(n, w * t)
    A = R @ A0
    Wv = np.broadcast_to(w * n, (len(t), 3))
    T_cm = np.cross(Wv, np.einsum("nij,nj->ni", A @ J @ np.swapaxes(A, 1, 2), Wv))
    F = np.broadcast_to(m_ * gp - m_ * g, (len(t), 3))
    P_j = C + apply(R, P0 - C0)                    # the joint point moves with the puck
    assert np.allclose(res.reaction_force(ice), F, atol=1e-9)
    assert np.allclose(res.reaction_torque(ice), T_cm + np.cross(C - P_j, F), atol=1e-9)
