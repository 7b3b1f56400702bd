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


# ----------------------------------------------------------------------------- motion drivers reading inputs
R_CRANK, L_ROD, W_PERIOD = 0.1, 0.3, 0.01   # crank and rod lengths [m], command period [s]


def _slider_crank(**motion):
    """A slider-crank (closed loop, driven crank `main`) whose motion is given by `motion` (add_motion's
    keywords); inputs w_cmd [rad/s or rad or rad/s^2] declared 2.0."""
    m = mb.Model("slider_crank", gravity=(0, -G, 0))
    m.add_input("w_cmd", 2.0)
    r, l = R_CRANK, L_ROD
    m.add_body("crank", mass=0.5, inertia=(1e-4, 5e-4, 5e-4), position=(r / 2, 0, 0))
    m.add_body("rod", mass=0.8, inertia=(1e-4, 6e-3, 6e-3), position=(r + l / 2, 0, 0))
    m.add_body("slider", mass=1.2, inertia=(1e-3, 1e-3, 1e-3), position=(r + l, 0, 0))
    m.add_revolute("main", "ground", "crank", (0, 0, 0), (0, 0, 1))
    m.add_revolute("b", "crank", "rod", (r, 0, 0), (0, 0, 1))
    m.add_revolute("c", "rod", "slider", (r + l, 0, 0), (0, 0, 1))
    m.add_translational("rail", "ground", "slider", (r + l, 0, 0), (1, 0, 0))
    m.add_motion("spin", "main", **motion)
    m.add_output("angle", "AZ(crank)")   # the crank angle [rad] in (-pi, pi]
    m.add_output("x", "DX(slider)")
    m.add_output("vx", "VX(slider)")
    return m


def _slider_x(theta):
    """Slider position [m] of the slider-crank at crank angle theta [rad] (closed form)."""
    return R_CRANK * np.cos(theta) + np.sqrt(L_ROD ** 2 - (R_CRANK * np.sin(theta)) ** 2)


def _commands(n, seed):
    return np.random.default_rng(seed).uniform(-6.0, 12.0, n)


@pytest.mark.filterwarnings("ignore:redundant constraints")
def test_velocity_driver_reads_an_input_continuously():
    """velocity="w_cmd" with w_cmd changed every 10 ms, stepped 5 ms at a time: the crank angle is the exact
    piecewise-linear integral at every step (1e-9), the loop stays closed, the slider's velocity follows."""
    w = _commands(12, 1)
    sim = mb.Simulator(_slider_crank(velocity="w_cmd", initial_displacement=0.3), rtol=1e-9)
    angle, worst = 0.3, 0.0
    for k, wk in enumerate(w):
        sim.set_input("w_cmd", float(wk))
        for _ in range(2):
            sim.step(W_PERIOD / 2)
            angle += wk * W_PERIOD / 2
            out = sim.outputs()
            worst = max(worst, abs(out["angle"] - angle))
            assert out["x"] == pytest.approx(_slider_x(angle), abs=1e-9)
            dxdth = -R_CRANK * np.sin(angle) - R_CRANK ** 2 * np.sin(angle) * np.cos(angle) / np.sqrt(
                L_ROD ** 2 - (R_CRANK * np.sin(angle)) ** 2)
            assert out["vx"] == pytest.approx(dxdth * wk, abs=1e-8)
    assert worst < 1e-9, worst
    assert abs(angle - 0.3) > 0.1   # the crank moved
    res = sim.result()
    assert np.allclose(res.joint_velocity("main")[1:], np.repeat(w, 2), atol=1e-9)


@pytest.mark.filterwarnings("ignore:redundant constraints")
def test_velocity_driver_with_declared_input_equals_constant_speed_driver():
    a = mb.simulate(_slider_crank(velocity="w_cmd", initial_displacement=0.3), 0.2, 0.01)
    b = mb.simulate(_slider_crank(velocity=2.0, initial_displacement=0.3), 0.2, 0.01)
    assert a.success and b.success
    assert np.abs(a.joint_coordinate("main") - b.joint_coordinate("main")).max() < 1e-12
    assert np.abs(a.position("slider") - b.position("slider")).max() < 1e-12
    assert a.joint_coordinate("main")[-1] == pytest.approx(0.3 + 2.0 * 0.2, abs=1e-12)


@pytest.mark.filterwarnings("ignore:redundant constraints")
def test_acceleration_driver_reads_an_input_continuously():
    """acceleration="w_cmd" (here an angular acceleration [rad/s^2]) changed every 10 ms: angle and rate are
    the exact piecewise quadratic and linear functions (continuous at the changes)."""
    alpha = _commands(10, 2) * 20
    sim = mb.Simulator(_slider_crank(acceleration="w_cmd", initial_displacement=0.2, initial_velocity=-1.0),
                       rtol=1e-9)
    th, om = 0.2, -1.0
    for a in alpha:
        sim.set_input("w_cmd", float(a))
        sim.step(W_PERIOD)
        th, om = th + om * W_PERIOD + 0.5 * a * W_PERIOD ** 2, om + a * W_PERIOD
        assert sim.output("angle") == pytest.approx(th, abs=1e-9)
        assert sim.output("x") == pytest.approx(_slider_x(th), abs=1e-9)
    res = sim.result()
    assert res.joint_velocity("main")[-1] == pytest.approx(om, abs=1e-8)


@pytest.mark.filterwarnings("ignore:redundant constraints")
def test_displacement_driver_reading_an_input_jumps_with_reprojection():
    """displacement="w_cmd" (an angle [rad]): at each change the crank jumps there (positions and velocities
    re-projected at the step's start), then stays: the mechanism at rest in the closed configuration."""
    sim = mb.Simulator(_slider_crank(displacement="0.5*w_cmd"))
    assert sim.output("angle") == pytest.approx(1.0, abs=1e-12)
    for a in (0.4, -0.3, 1.1):
        sim.set_input("w_cmd", a)
        sim.step(0.02)
        out = sim.outputs()
        assert out["angle"] == pytest.approx(0.5 * a, abs=1e-10)
        assert out["x"] == pytest.approx(_slider_x(0.5 * a), abs=1e-10)
        assert abs(out["vx"]) < 1e-10


@pytest.mark.filterwarnings("ignore:redundant constraints")
def test_driver_inputs_state_restore_and_errors(tmp_path):
    sim = mb.Simulator(_slider_crank(velocity="3*w_cmd + 0.5*t", initial_displacement=0.1))
    sim.set_input("w_cmd", 1.0)
    sim.step(0.01)
    saved = sim.state()

    def run():
        out = []
        for w in (4.0, -2.0, 0.5):
            sim.set_input("w_cmd", w)
            sim.step(0.01)
            out.append(sim.outputs())
        return out
    first = run()
    sim.restore(saved)
    sim.set_input("w_cmd", 9.0)
    sim.step(0.03)
    sim.restore(saved)
    assert run() == first   # bit-identical, anchors included
    # the exact integral of 3 w + 0.5 t
    assert first[-1]["angle"] == pytest.approx(0.1 + 0.01 * (3 * (1 + 4 - 2 + 0.5)) + 0.25 * 0.04 ** 2, abs=1e-9)
    # model files keep the driver's text
    m = _slider_crank(velocity="3*w_cmd + 0.5*t", initial_displacement=0.1)
    mb.save_model(m, tmp_path / "crank.yaml")
    m2 = mb.load_model(tmp_path / "crank.yaml")
    s2 = mb.Simulator(m2)
    sim.restore(saved)
    s2.set_input("w_cmd", 1.0)
    s2.step(0.01)
    assert s2.outputs() == sim.outputs()
    with pytest.raises(ModelError, match="motion 'spin'.*velocity.*closed-form"):
        _slider_crank(velocity="sin(w_cmd*t)")
    with pytest.raises(ModelError, match="motion 'spin'.*velocity"):
        _slider_crank(velocity="w_other")


def test_restore_without_inputs_gives_the_outputs_of_the_restored_state():
    m = mb.Model("free_pendulum", gravity=(0, -G, 0))
    m.add_body("rod", mass=M, inertia=(0.01, IZZ, IZZ), position=(L, 0, 0))
    m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
    m.add_output("theta", "pin")
    sim = mb.Simulator(m)
    sim.step(0.05)
    saved, before = sim.state(), sim.output("theta")
    sim.step(0.2)
    assert sim.output("theta") < before < 0.0
    sim.restore(saved)
    assert sim.output("theta") == before
