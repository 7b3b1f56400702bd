"""Every example runs, its YAML file and its Python script build the same model, and one physical fact
per example holds against a closed form (short end times keep this fast)."""
import importlib.util
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.io import model_to_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NAMES = ["pendulum", "slider_crank", "four_bar", "heavy_top", "spring_mass_chain", "quarter_car", "robot_arm",
         "contact_friction"]


def script(name):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def same(a, b, path="model"):
    """Nested dicts/lists equal, floats to 1e-12 relative (a unit string and its SI number may differ by an ulp)."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), f"{path}: keys {sorted(a)} != {sorted(b)}"
        for k in a:
            same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: {a} != {b}"
        for k, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{k}]")
    elif isinstance(a, float):
        assert b == pytest.approx(a, rel=1e-12, abs=1e-15), f"{path}: {a} != {b}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


@pytest.fixture(scope="module", params=NAMES)
def example(request):
    name = request.param
    return name, mb.load_model(EXAMPLES / f"{name}.yaml"), script(name)


def test_at_least_eight_examples_each_as_yaml_and_python():
    names = {p.stem for p in EXAMPLES.glob("*.yaml") if not p.stem.endswith("_study")}   # study files: no script
    assert set(NAMES) <= names and all((EXAMPLES / f"{n}.py").is_file() for n in names)


def test_yaml_and_python_build_the_same_model(example):
    name, from_file, mod = example
    same(model_to_dict(mod.build()), model_to_dict(from_file))


def quiet(fn, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        return fn(*args, **kwargs)


def test_pendulum_small_amplitude_period():
    m = mb.load_model(EXAMPLES / "pendulum.yaml")
    res = mb.simulate(m, end_time=3.6, output_step=0.02)
    ups = res.crossings(lambda r: r.joint_coordinate("pin"), 0.0, direction=1)
    amp = 0.1 / math.sqrt(9.81 * 0.5 / (1 / 3))                    # omega0 / natural frequency
    period = 2 * math.pi * math.sqrt(2 * 1.0 / (3 * 9.81)) * (1 + amp ** 2 / 16)
    assert ups[1] - ups[0] == pytest.approx(period, rel=2e-6)


def test_slider_crank_slider_coordinate_closed_form():
    m = mb.load_model(EXAMPLES / "slider_crank.yaml")
    res = quiet(mb.kinematics, m, end_time=1.0, output_step=0.05)
    th = 2 * math.pi * res.time
    x = 0.2 * np.cos(th) + np.sqrt(0.4 ** 2 - (0.2 * np.sin(th)) ** 2)
    assert np.allclose(res.joint_coordinate("slide"), x - 0.6, atol=1e-9)


def test_four_bar_grashof_crank_turns_and_loop_closes():
    a, b, c, d = 0.1, math.hypot(0.3, 0.3), math.hypot(0.1, 0.4), 0.4
    s, l, p, q = sorted([a, b, c, d])
    assert s + l <= p + q and s == a                                  # Grashof crank-rocker
    res = quiet(mb.kinematics, mb.load_model(EXAMPLES / "four_bar.yaml"), end_time=1.0, output_step=0.05)
    th = math.pi / 2 + 2 * math.pi * res.time                         # crank angle from +x
    A = np.stack([a * np.cos(th), a * np.sin(th)], 1)
    O4 = np.array([d, 0.0])
    e = O4 - A                                                        # circles (A, b) and (O4, c) intersect at B
    dist = np.linalg.norm(e, axis=1)
    h = (b ** 2 - c ** 2 + dist ** 2) / (2 * dist)
    k = np.sqrt(b ** 2 - h ** 2)
    u = e / dist[:, None]
    B = A + h[:, None] * u + k[:, None] * np.stack([-u[:, 1], u[:, 0]], 1)   # the branch of B = (0.3, 0.4)
    assert np.allclose(B[0], [0.3, 0.4], atol=1e-12)
    assert np.allclose(res.position("coupler.B")[:, :2], B, atol=1e-8)


def test_heavy_top_steady_precession():
    mod = script("heavy_top")
    res = mb.simulate(mb.load_model(EXAMPLES / "heavy_top.yaml"), end_time=0.5, output_step=0.05)
    tip = res.position("top.tip")
    tilt = np.arccos(tip[:, 2] / np.linalg.norm(tip, axis=1))
    assert np.allclose(tilt, math.radians(30), atol=1e-7)
    azimuth = np.unwrap(np.arctan2(tip[:, 1], tip[:, 0]))
    assert np.allclose(azimuth, mod.precession_rate() * res.time, atol=1e-7)


def test_spring_chain_static_sag():
    mod = script("spring_mass_chain")
    eq = mb.equilibrium(mb.load_model(EXAMPLES / "spring_mass_chain.yaml"))
    sag = [-eq.position(f"m{k}")[0, 1] - 0.25 * k for k in (1, 2, 3)]
    assert np.allclose(sag, mod.static_sag(), rtol=1e-9)
    assert mod.static_sag()[-1] == pytest.approx((3.5 + 2.5 + 0.5) * 9.81 / 500)


def test_quarter_car_rests_then_follows_the_road_step():
    res = mb.simulate(mb.load_model(EXAMPLES / "quarter_car.yaml"), end_time=4.0, output_step=0.05)
    z = res.joint_coordinate("body_guide")
    assert np.abs(z[res.time < 0.5]).max() < 1e-9                   # preloads balance the weights exactly
    assert z[-1] == pytest.approx(0.05, abs=1e-3)                     # settles on the raised road


def test_robot_arm_tip_forward_kinematics():
    res = mb.kinematics(mb.load_model(EXAMPLES / "robot_arm.yaml"), end_time=2.0, output_step=0.1)
    t = res.time
    q1, q2 = 0.5 * np.sin(np.pi * t), 0.8 * (1 - np.cos(np.pi * t))
    tip = res.position("forearm.tip")
    assert np.allclose(tip[:, 0], 0.5 * np.cos(q1) + 0.4 * np.cos(q1 + q2), atol=1e-9)
    assert np.allclose(tip[:, 2], 0.5 * np.sin(q1) + 0.4 * np.sin(q1 + q2), atol=1e-9)


def test_contact_friction_ball_ends_rolling_at_five_sevenths():
    res = mb.simulate(mb.load_model(EXAMPLES / "contact_friction.yaml"), end_time=0.25, output_step=0.005)
    v, w, z = res.velocity("ball")[-1, 0], res.angular_velocity("ball")[-1, 1], res.position("ball")[-1, 2]
    assert v == pytest.approx(5 / 7, rel=5e-3)                        # rigid-ball closed form; compliance ~0.2 %
    depth = 0.05 - z                                                  # static penetration (~0.3 mm)
    assert w * (0.05 - depth / 2) == pytest.approx(v, rel=1e-4)       # rolling: no slip at the contact point


@pytest.mark.parametrize("name", NAMES)
def test_example_runs_from_the_command_line(name, tmp_path):
    from typer.testing import CliRunner

    from mbdsim.cli.app import app
    out = tmp_path / "r.csv"
    r = CliRunner().invoke(app, ["run", str(EXAMPLES / f"{name}.yaml"), "--end", "0.05", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert out.is_file() and "success" in r.output
