"""The energy bookkeeping of the compiled step loop (issue 29): the dissipated energy D and the applied loads'
work W accumulated inside fastdop.run (solvers.fastenergy, energy_run) against the independent post-run
quadrature of the dissipation power on the dense output (results.energy.dissipated_energy_reference) and
against closed forms: a damped oscillator's energy, Coulomb friction's mu N times the distance slid, a
constant force's F times the displacement, a block coasting to rest (D = its initial kinetic energy)."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.results.energy import dissipated_energy_reference

G = 9.81


def _compiled(res):
    assert res.success and "(compiled)" in res.stats["method"]
    assert res.stats.get("energy") == "compiled", res.stats.get("energy")
    return res.dissipated_energy()


def _agree(D, res, rel=1e-8):
    ref = dissipated_energy_reference(res)
    assert np.max(np.abs(D - ref)) <= rel * np.max(np.abs(ref)), (np.max(np.abs(D - ref)), ref[-1])
    return ref


def oscillator(m=2.0, k=50.0, c=1.5, x0=0.2, v0=0.5):
    mdl = mb.Model(gravity=(0, 0, 0))
    b = mdl.add_body("b", m, (0.1, 0.1, 0.1), position=(1.0 + x0, 0, 0), velocity=(v0, 0, 0))
    mdl.add_translational("p", mdl.ground, b, (0, 0, 0), (1, 0, 0))
    mdl.add_spring_damper("s", (mdl.ground, (0, 0, 0)), (b, (1.0 + x0, 0, 0)), k, c, 1.0)
    return mdl


def test_damped_oscillator_against_the_closed_form_and_the_quadrature():
    m, k, c, x0, v0 = 2.0, 50.0, 1.5, 0.2, 0.5
    res = mb.simulate(oscillator(m, k, c, x0, v0), 2.0, 0.01, method="dop853", rtol=1e-10)
    D = _compiled(res)
    _agree(D, res)
    wn, z = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    wd, t = wn * np.sqrt(1 - z * z), res.time
    B = (v0 + z * wn * x0) / wd
    x = np.exp(-z * wn * t) * (x0 * np.cos(wd * t) + B * np.sin(wd * t))
    v = np.exp(-z * wn * t) * ((-z * wn * x0 + wd * B) * np.cos(wd * t) + (-z * wn * B - wd * x0) * np.sin(wd * t))
    exact = 0.5 * (m * v0 ** 2 + k * x0 ** 2) - 0.5 * (m * v ** 2 + k * x ** 2)
    assert np.max(np.abs(D - exact)) < 1e-8 * exact[-1], np.max(np.abs(D - exact))
    assert res.diagnostics.summary()["energy_error"] < 1e-8 * exact[-1]


def test_off_without_the_monitor_and_the_same_steps():
    on = mb.simulate(oscillator(), 1.0, 0.01, method="dop853", rtol=1e-9)
    off = mb.simulate(oscillator(), 1.0, 0.01, method="dop853", rtol=1e-9, monitor=False)
    assert off.energy is None and "energy" not in off.stats
    assert on.stats["steps"] == off.stats["steps"] and np.array_equal(on.q, off.q)
    sub = on._subset(np.arange(10, 60, 7))   # a subset of the samples: served, from its first sample
    assert sub.energy is None and np.allclose(sub.dissipated_energy(),
                                              on.dissipated_energy()[10:60:7] - on.dissipated_energy()[10],
                                              rtol=0, atol=1e-15)


def test_bouncing_ball_contact_damping():
    mdl = mb.Model(gravity=(0, 0, -G))
    ball = mdl.add_body("ball", 0.5, (1e-3,) * 3, position=(0, 0, 0.12))
    mdl.add_contact("c", mb.Plane(mdl.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, 0.02, (0, 0, 0.12)),
                    1e5, 1.5, 40.0, 1e-3, mu=0.3, friction_velocity=1e-3)
    res = mb.simulate(mdl, 0.6, 0.005, method="dop853", rtol=1e-10)
    D = _compiled(res)
    ref = _agree(D, res)
    assert ref[-1] > 0.05 * 0.5 * G * 0.1   # the impacts dissipated something
    E = res.kinetic_energy() + res.potential_energy() + D
    assert np.max(np.abs(E - E[0])) < 1e-7 * E[0]


def test_box_sliding_with_friction_dissipates_mu_m_g_cos_theta_times_the_distance():
    theta, mu, mass, a, k, e = np.radians(30), 0.3, 1.0, 0.1, 1e6, 1.5
    mdl = mb.Model(gravity=(G * np.sin(theta), 0, -G * np.cos(theta)))   # the incline is the plane z = 0
    delta = (mass * G * np.cos(theta) / (4 * k)) ** (1 / e)
    b = mdl.add_body("box", mass, (mass * a * a / 6,) * 3, position=(0, 0, a / 2 - delta), velocity=(0.5, 0, 0))
    mdl.add_contact("c", mb.Plane(mdl.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("geo", mb.Box((a, a, a))),
                    k, e, 400.0, 1e-4, mu=mu, friction_velocity=1e-3)
    res = mb.simulate(mdl, 0.3, 0.005, method="dop853", rtol=1e-9)
    D = _compiled(res)
    _agree(D, res, 1e-8)
    i = np.searchsorted(res.time, 0.1)   # after the onset's transient
    s = res.position("box")[:, 0]
    slid = mu * mass * G * np.cos(theta) * (s[-1] - s[i])
    assert abs((D[-1] - D[i]) / slid - 1) < 1e-3, (D[-1] - D[i], slid)


def test_joint_friction_block_coasting_to_rest():
    """A block on a ground slide (friction mu_d, normal load m g) launched at v0: it slides v0^2 / (2 mu_d g),
    sticks, and has dissipated its kinetic energy m v0^2 / 2 (through the stick event)."""
    m, v0, mu = 2.0, 1.0, 0.4
    mdl = mb.Model("coast", gravity=(0, -G, 0))
    block = mdl.add_particle("block", m, (0, 0, 0), velocity=(v0, 0, 0))
    slide = mdl.add_translational("slide", mdl.ground, block, (0, 0, 0), (1, 0, 0))
    mdl.add_friction("friction", slide, 0.5, mu)
    res = mb.simulate(mdl, 0.4, 0.01, rtol=1e-10)
    D = _compiled(res)
    t_stop = v0 / (mu * G)
    assert res.time[-1] > t_stop
    assert abs(D[-1] / (0.5 * m * v0 ** 2) - 1) < 1e-9, D[-1]
    x = res.position("block")[:, 0]
    assert np.allclose(D, mu * m * G * x, rtol=0, atol=1e-8)
    _agree(D, res, 1e-7)
    assert res.diagnostics.energy_error is not None and res.diagnostics.summary()["energy_error"] < 1e-8


def test_friction_power_with_a_kink_inside_the_steps():
    """A block sliding on a ground slide (no gravity) pressed sideways by F_y = c (t - t_k): the normal load
    |c (t - t_k)| has a kink at t_k, inside a step (at rtol=1e-9 the step is refined: the power has a kink
    where the state's acceleration has one, which its error control sees less). Closed form: v = v0 - mu c G(t) / m, G = (t_k^2 + sgn(t - t_k) (t - t_k)^2)
    / 2, and D = m (v0^2 - v^2) / 2, at every output, also those inside the refined steps."""
    m, v0, mu, c, tk = 1.0, 1.0, 0.3, 20.0, 0.1337
    mdl = mb.Model("kink", gravity=(0, 0, 0))
    blk = mdl.add_particle("block", m, (0, 0, 0), velocity=(v0, 0, 0))
    slide = mdl.add_translational("slide", mdl.ground, blk, (0, 0, 0), (1, 0, 0))
    mdl.add_friction("friction", slide, mu, mu)
    mdl.add_force("side", (blk, (0, 0, 0)), ("0", f"{c}*(TIME-{tk})", "0"))
    for rtol, tol, tol_balance in ((None, 3e-6, 1e-8), (1e-9, 2e-10, 2e-9)):
        res = mb.simulate(mdl, 0.3, 0.0005, **({} if rtol is None else {"rtol": rtol}))
        D = _compiled(res)
        t = res.time
        v = v0 - mu * c / m * (tk ** 2 + np.sign(t - tk) * (t - tk) ** 2) / 2
        assert np.max(np.abs(D - 0.5 * m * (v0 ** 2 - v ** 2))) < tol * 0.5 * m * v0 ** 2
        E = res.kinetic_energy()
        assert np.max(np.abs(E[0] - E - D)) < tol_balance * E[0]   # the run's own balance


def test_applied_force_work_torsion_spring_and_stop():
    """A wheel on a revolute (joint coordinates) driven by a constant torque, a damped torsion spring and a
    damped stop it hits: W = T theta exactly, D against the quadrature, and the balance T + V + D - W."""
    mdl = mb.Model(gravity=(0, 0, 0))
    w = mdl.add_body("wheel", 1.0, (0.01, 0.01, 0.02))
    j = mdl.add_revolute("axle", mdl.ground, w, (0, 0, 0), (0, 0, 1))
    mdl.add_torque("T", w, (0, 0, 0.05))
    mdl.add_torsion_spring("ts", j, 0.1, 0.02)
    mdl.add_stop("st", j, upper=0.3, stiffness=50.0, exponent=1.5, damping=2.0, penetration=1e-2)
    res = mb.simulate(mdl, 2.0, 0.01, method="dop853", rtol=1e-10)
    D = _compiled(res)
    ref = _agree(D, res, 1e-8)
    assert ref[-1] > 0
    theta = res.joint_coordinate("axle")
    assert theta.max() > 0.3   # the stop was hit
    assert np.allclose(res.energy["W"], 0.05 * (theta - theta[0]), rtol=0, atol=1e-10)
    assert res.diagnostics.summary()["energy_error"] < 1e-8


def test_work_of_python_callable_force_and_torque_summed_in_the_kernel():
    """A rod pendulum braked by a drag torque -c w and pushed by an offset point force, both written as Python
    callables (called back from the step loop), plus a constant torque: the kernel sums the callables' power
    from the loads the callback writes, and W is the change of the kinetic and potential energy (nothing
    else does work or dissipates)."""
    m, c = 2.0, 0.3
    mdl = mb.Model(gravity=(0.0, -G, 0.0))
    rod = mdl.add_body("rod", m, (0.01, 2 / 12, 2 / 12), position=(0.5, 0, 0))
    mdl.add_revolute("pin", mdl.ground, rod, (0, 0, 0), (0, 0, 1))
    mdl.add_torque("drag", rod, lambda t, s: (0.0, 0.0, -c * s.angular_velocity(rod)[2]))
    mdl.add_force("push", (rod, (1.0, 0, 0)), lambda t, s: (0.0, -0.5 * np.cos(3 * t), 0.0))
    mdl.add_torque("T", rod, (0, 0, 0.4))
    res = mb.simulate(mdl, 2.0, 0.01, method="dop853", rtol=1e-10)
    assert res.success and set(res.stats["called_back"]) == {"drag", "push"}
    assert res.stats.get("energy") == "compiled", res.stats.get("energy")
    E = res.kinetic_energy() + m * G * res.position("rod")[:, 1]
    W = res.energy["W"] - res.energy["W"][0]
    assert np.max(np.abs(W)) > 0.1
    assert np.max(np.abs(W - (E - E[0]))) < 1e-8 * np.max(np.abs(W)), np.max(np.abs(W - (E - E[0])))
    assert res.diagnostics.summary()["energy_error"] < 1e-8
