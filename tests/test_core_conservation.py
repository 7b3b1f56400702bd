"""Core engine, must-show 4: conservation laws with the high-accuracy method (dop853).

A spatial double pendulum and a heavy symmetric top conserve total energy (drift < 1e-6 relative over
10 s); the top conserves its angular momentum about the vertical through the fixed point and its spin;
a torque-free asymmetric body spun near its intermediate axis flips with the period of Euler's
equations, integrated here independently with scipy solve_ivp at 1e-12.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import mbdsim as mb

G = 9.81
TOL = dict(method="dop853", rtol=1e-9, atol=1e-11)


def angular_momentum(res, body, J_B, point):
    """H about a fixed point [kg m^2/s] in ground: A J_B A^T w + m (r_cm - point) x v_cm, (N, 3)."""
    A, w = res.orientation(body), res.angular_velocity(body)
    spin = np.einsum("nij,jk,nlk,nl->ni", A, J_B, A, w)
    return spin + body.mass * np.cross(res.position(body) - point, res.velocity(body))


def test_spatial_double_pendulum_conserves_energy():
    """Link a swings about ground z; link b swings about a's own long axis (non-parallel revolutes)."""
    model = mb.Model("double_pendulum", gravity=(0.0, -G, 0.0))
    la, lb, ma, mb_ = 0.8, 0.6, 1.0, 0.7
    a = model.add_body("a", ma, inertia=(0.002, ma * la**2 / 12, ma * la**2 / 12), position=(la / 2, 0, 0))
    b = model.add_body("b", mb_, inertia=(mb_ * lb**2 / 12, 0.024, 0.004), position=(la, 0, lb / 2),
                       orientation=Rotation.from_rotvec([0.0, -np.pi / 2, 0.0]),
                       angular_velocity=(1.0, 0.0, 0.0))
    j1 = model.add_revolute("j1", model.ground, a, (0, 0, 0), (0, 0, 1))
    j2 = model.add_revolute("j2", a, b, (la, 0, 0), (1, 0, 0))
    res = mb.simulate(model, 10.0, output_step=0.1, **TOL)
    assert res.success, res.message
    T, V = res.kinetic_energy(), res.potential_energy()
    E = T + V
    assert np.ptp(T) > 5.0                            # it really moves (several joules exchanged)
    assert np.abs(E - E[0]).max() < 1e-6 * np.abs(T).max()
    # independent kinetic energy from the returned motion: 1/2 m v^2 + 1/2 w . (A J A^T w)
    T_ref = sum(0.5 * bd.mass * np.sum(res.velocity(bd) ** 2, 1)
                + 0.5 * np.einsum("ni,nij,jk,nlk,nl->n", res.angular_velocity(bd), res.orientation(bd),
                                  bd.inertia, res.orientation(bd), res.angular_velocity(bd)) for bd in (a, b))
    assert np.allclose(T, T_ref, rtol=1e-12, atol=1e-12)
    assert np.allclose(V, G * (ma * res.position(a)[:, 1] + mb_ * res.position(b)[:, 1]), atol=1e-12)
    # both joints keep their geometry: the j2 point stays at distance la from the origin
    tip_a = res.position(a) + np.einsum("nij,j->ni", res.orientation(a), [la / 2, 0, 0])
    assert np.abs(np.linalg.norm(tip_a, axis=1) - la).max() < 1e-9
    assert np.all(np.isfinite(res.joint_coordinate(j1))) and np.ptp(res.joint_coordinate(j2)) > 0.5


@pytest.fixture(scope="module")
def top_run():
    model = mb.Model("heavy_top", gravity=(0.0, 0.0, -G))
    mass, l, It, Ia, spin = 1.0, 0.05, 3e-3, 4e-3, 25.0
    tilt = Rotation.from_rotvec([0.3, 0.0, 0.0])
    axis = tilt.as_matrix()[:, 2]
    top = model.add_body("top", mass, inertia=(It, It, Ia), position=l * axis, orientation=tilt,
                         angular_velocity=spin * axis)
    model.add_spherical("tip", model.ground, top, (0, 0, 0))
    res = mb.simulate(model, 10.0, output_step=0.05, **TOL)
    assert res.success, res.message
    return res, top, np.diag([It, It, Ia])


def test_heavy_top_conserves_energy_vertical_momentum_and_spin(top_run):
    res, top, J = top_run
    E = res.kinetic_energy() + res.potential_energy()
    assert np.abs(E - E[0]).max() < 1e-6 * abs(E[0])
    H = angular_momentum(res, top, J, np.zeros(3))
    assert np.abs(H[:, 2] - H[0, 2]).max() < 1e-6 * np.linalg.norm(H[0])
    assert np.ptp(H[:, 0]) > 1e-3 * np.linalg.norm(H[0])   # the horizontal part precesses (gravity torque)
    w_B = res.angular_velocity(top, frame=top)
    assert np.abs(w_B[:, 2] - w_B[0, 2]).max() < 1e-6 * abs(w_B[0, 2])   # symmetric top: spin constant
    # it nutates and precesses: the symmetry axis leaves the initial tilt and goes round the vertical
    axis = res.orientation(top)[:, :, 2]
    assert np.ptp(axis[:, 2]) > 1e-3
    assert np.ptp(np.unwrap(np.arctan2(axis[:, 1], axis[:, 0]))) > np.pi
    # the fixed point stays fixed (constraint drift)
    tip = res.position(top) - axis * 0.05
    assert np.abs(tip).max() < 1e-9


def euler_period(J, w0):
    """Flip period of the torque-free body from Euler's equations (solve_ivp, 1e-12): time between
    successive downward zero crossings of w_2 (body axes)."""
    I1, I2, I3 = J

    def rhs(t, w):
        return [(I2 - I3) * w[1] * w[2] / I1, (I3 - I1) * w[2] * w[0] / I2, (I1 - I2) * w[0] * w[1] / I3]

    def down(t, w):
        return w[1]
    down.direction = -1
    sol = solve_ivp(rhs, (0, 60), w0, method="DOP853", rtol=1e-12, atol=1e-12, events=down, dense_output=True)
    t = sol.t_events[0]
    return t[1] - t[0], t[0], sol


def test_intermediate_axis_flip_period_matches_euler_equations():
    J = np.array([1.0, 2.0, 3.0]) * 0.01
    w0_B = np.array([0.02, 2.0, 0.03])
    period, t_first, sol = euler_period(J, w0_B)
    assert 1.0 < period < 20.0
    orient = Rotation.from_rotvec([0.4, -0.7, 1.1])      # a general orientation of the body axes
    model = mb.Model("flip")
    body = model.add_body("body", 0.3, inertia=J, position=(1.0, 2.0, 3.0), orientation=orient,
                          velocity=(0.1, 0.0, -0.2), angular_velocity=orient.apply(w0_B))
    res = mb.simulate(model, t_first + 1.2 * period, output_step=0.05, **TOL)
    assert res.success, res.message
    downs = res.crossings(lambda r: r.angular_velocity(body, frame=body)[:, 1], 0.0, direction=-1)
    assert len(downs) == 2
    assert downs[0] == pytest.approx(t_first, rel=1e-6)
    assert downs[1] - downs[0] == pytest.approx(period, rel=1e-6)
    # whole history of the body-axes angular velocity against Euler's equations
    w_ref = sol.sol(res.time).T
    assert np.allclose(res.angular_velocity(body, frame=body), w_ref, rtol=0, atol=1e-6)
    # torque-free: the angular momentum in ground is constant, and the CM moves uniformly
    H = angular_momentum(res, body, np.diag(J), np.zeros(3))
    assert np.abs(H - H[0]).max() < 1e-8 * np.linalg.norm(H[0])
    t = res.time[:, None]
    assert np.allclose(res.position(body), [1.0, 2.0, 3.0] + t * [0.1, 0.0, -0.2], rtol=0, atol=1e-9)
