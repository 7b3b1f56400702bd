"""Step-by-step Simulator (issue 33): a sampled PD loop against the exact zero-order-hold solution,
state()/restore() bit-identical, inputs in loads, sensors and outputs, model files, bad input."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbdsim as mb
from mbdsim.errors import ModelError

M, L, IZZ, G = 1.3, 0.4, 0.02, 9.81       # rod mass [kg], pin-to-CM [m], inertia about the CM [kg m^2]
KP, KD, REF, PERIOD = 30.0, 3.0, 0.8, 0.01   # PD gains [N m/rad, N m s/rad], target [rad], sample period [s]


def _arm(c=0.0, name="arm"):
    m = mb.Model(name, gravity=(0, -G, 0))
    m.add_input("u", 0.0)
    m.add_body("rod", mass=M, inertia=(0.01, IZZ, IZZ), position=(L, 0, 0))
    m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
    m.add_joint_force("motor", "pin", f"u - {c}*pin_dot")
    m.add_output("theta", "pin")
    m.add_output("omega", "pin_dot")
    return m


def _pd(theta, omega):
    return -KP * (theta - REF) - KD * omega


def _zoh_reference(n, c=0.0):
    """Angle at each sample of the sampled PD loop: I theta'' = -m g L cos(theta) - c theta' + u_k on each
    period, u_k from the state at its start (scipy DOP853 at 1e-12, piece by piece)."""
    J = IZZ + M * L ** 2
    y, out = np.zeros(2), []
    for k in range(n):
        u = _pd(*y)
        sol = solve_ivp(lambda t, s: [s[1], (-M * G * L * np.cos(s[0]) - c * s[1] + u) / J], (0, PERIOD), y,
                        method="DOP853", rtol=1e-12, atol=1e-12)
        y = sol.y[:, -1]
        out.append(y[0])
    return np.array(out)


def _loop(sim, n):
    out = []
    for _ in range(n):
        sim.set_input("u", _pd(sim.output("theta"), sim.output("omega")))
        sim.step(PERIOD)
        out.append(sim.output("theta"))
    return out


def test_pd_loop_matches_zero_order_hold_solution():
    n = 60
    sim = mb.Simulator(_arm(0.2), rtol=1e-10)
    theta = np.array(_loop(sim, n))
    ref = _zoh_reference(n, 0.2)
    assert abs(sim.time - n * PERIOD) < 1e-12
    assert np.abs(theta - ref).max() < 1e-8, np.abs(theta - ref).max()
    assert abs(theta[-1]) > 0.3   # the loop moved the arm (not a trivial comparison)
    res = sim.result()
    assert len(res) == n + 1 and np.allclose(res.time, PERIOD * np.arange(n + 1))
    assert np.allclose(res.joint_coordinate("pin")[1:], theta, atol=1e-12, rtol=0)
    u = res.stats["inputs"]["u"]
    assert u[0] == 0.0 and u[1] == pytest.approx(_pd(0.0, 0.0))
    # the accelerations at a sample use the input held over the step that ended there
    J = IZZ + M * L ** 2
    th, om = res.joint_coordinate("pin")[5], res.joint_velocity("pin")[5]
    acc = (-M * G * L * np.cos(th) - 0.2 * om + u[5]) / J
    assert res.angular_acceleration("rod")[5, 2] == pytest.approx(acc, rel=1e-8)


def test_state_restore_is_bit_identical():
    sim = mb.Simulator(_arm(0.1))
    _loop(sim, 7)
    saved = sim.state()
    first = _loop(sim, 15) + [sim.outputs()]
    sim.restore(saved)
    assert sim.time == pytest.approx(7 * PERIOD)
    sim.set_input("u", 50.0)   # a trial move, thrown away
    sim.step(0.05)
    sim.restore(saved)
    again = _loop(sim, 15) + [sim.outputs()]
    assert first == again   # bit-identical
    assert len(sim.result()) == 7 + 15 + 1


def test_inputs_in_sensors_outputs_and_simulate():
    m = _arm()
    m.add_output("effort", "2*u + 0*pin")
    m.add_sensor("reach", "pin - u", value=0.0, direction=-1, action="stop")
    sim = mb.Simulator(m)
    sim.set_input("u", -0.05)   # the arm falls through the angle u (a threshold read from an input)
    assert sim.output("effort") == pytest.approx(-0.1)
    sim.step(0.01)
    assert sim.stopped is None and sim.output("theta") < 0
    sim.step(0.5)
    assert sim.stopped is not None and sim.stopped.name == "reach"
    assert sim.output("theta") == pytest.approx(-0.05, abs=1e-9)
    assert sim.time == pytest.approx(sim.stopped.time) and sim.time < 0.3
    with pytest.raises(ModelError, match="stopped by sensor"):
        sim.step(0.1)
    # simulate() reads the input's declared value: the same motion as a constant torque
    a, b = _arm(), _arm()
    a.inputs["u"].value = 2.0
    b.forces["motor"].value = mb.model.loadexpr.parse_load(b, "2.0", "x", "y")
    ra, rb = mb.simulate(a, 0.3, 0.01), mb.simulate(b, 0.3, 0.01)
    assert np.abs(ra.joint_coordinate("pin") - rb.joint_coordinate("pin")).max() < 1e-12


def test_model_file_carries_inputs_and_outputs(tmp_path):
    m = _arm()
    m.inputs["u"].value = 1.5
    mb.save_model(m, tmp_path / "arm.yaml")
    text = (tmp_path / "arm.yaml").read_text()
    assert "inputs:" in text and "outputs:" in text
    m2 = mb.load_model(tmp_path / "arm.yaml")
    assert m2.inputs["u"].value == 1.5 and m2.outputs["theta"].text == "pin"
    s1, s2 = mb.Simulator(m), mb.Simulator(m2)
    s1.step(0.2), s2.step(0.2)
    assert s1.outputs() == s2.outputs()


def test_bad_input_is_named():
    m = _arm()
    with pytest.raises(ModelError, match="input 'u'.*name"):
        m.add_input("u")
    with pytest.raises(ModelError, match="input 't'"):
        m.add_input("t")
    with pytest.raises(ModelError, match="output 'y'.*expression"):
        m.add_output("y", "pin + nothing")
    with pytest.raises(ModelError, match="input 'v'.*value"):
        m.add_input("v", "fast")
    with pytest.raises(ModelError, match="input 'u'.*value"):
        mb.Simulator(m).set_input("u", float("nan"))
    sim = mb.Simulator(m)
    with pytest.raises(ModelError, match="no input 'w'"):
        sim.set_input("w", 1.0)
    with pytest.raises(ModelError, match="no output 'x'"):
        sim.output("x")
    with pytest.raises(ModelError, match="dt"):
        sim.step(-1.0)
    sim.step(0.01)
    with pytest.raises(ModelError, match="before the current time"):
        sim.advance_to(0.0)
    with pytest.raises(ModelError, match="state"):
        sim.restore("nope")
