"""Issue 10, first list: every hostile input or fault named there now ends with a named mbdsim error (or a
Result with success=False keeping every step before the failure), never a hang or a bare traceback."""
import time
import warnings

import numpy as np
import pandas as pd
import pytest

import mbdsim as mb
from mbdsim.errors import AnalysisInterrupted, EvaluationError, ModelError, SolverError


def pendulum(name="p"):
    m = mb.Model(name, gravity=(0.0, -9.81, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.0, 0.0, 0.0))
    j = m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
    return m, b, j


# ------------------------------------------------------------------ no hang: tolerances have floors
@pytest.mark.parametrize("method", [None, "hht", "dop853", "rk45"])
def test_rtol_below_machine_precision_is_a_named_error(method):
    m, _, _ = pendulum()
    with pytest.raises(ModelError) as err:
        mb.simulate(m, 0.2, rtol=1e-30, method=method)
    assert (err.value.entity, err.value.field) == ("simulate", "rtol")


def test_hht_tolerance_floor_instead_of_endless_step_cuts():
    m, _, _ = pendulum()
    t0 = time.perf_counter()
    with pytest.raises(ModelError, match="HHT") as err:
        mb.simulate(m, 0.2, rtol=1e-13, method="hht")
    assert err.value.field == "rtol" and time.perf_counter() - t0 < 5


# ------------------------------------------------------------------ drivers: non-finite, None, raising
@pytest.mark.parametrize("driver", ["log(t)", lambda t: float("nan"), lambda t: None, "t" + "**t" * 5])
@pytest.mark.parametrize("analysis", ["kinematics", "simulate"])
def test_bad_driver_values_are_named_errors(driver, analysis):
    m, _, j = pendulum()
    m.add_motion("d", j, displacement=driver)
    with pytest.raises(EvaluationError) as err:
        getattr(mb, analysis)(m, 0.2, 0.01)
    assert err.value.entity == "motion 'd'" and err.value.field == "displacement"
    assert err.value.time == 0.0 and "at t = 0 s" in str(err.value)


def test_driver_raising_mid_run_keeps_every_sample_before():
    def drive(t):
        if t > 0.3:
            raise RuntimeError("sensor offline")
        return 0.5 * t
    m, _, j = pendulum()
    m.add_motion("d", j, displacement=drive)
    res = mb.kinematics(m, 1.0, 0.01)
    assert not res.success and isinstance(res.error, EvaluationError)
    assert res.error.entity == "motion 'd'" and res.error.field == "displacement"
    assert "RuntimeError: sensor offline" in res.message and res.error.time > 0.0
    # every sample before the failure is there and correct (the driven angle is 0.5 t exactly)
    assert len(res.time) >= 10 and res.time[-1] < res.error.time
    assert np.allclose(res.joint_coordinate("j"), 0.5 * res.time, atol=1e-9)


@pytest.mark.parametrize("kind", ["force", "torque"])
@pytest.mark.parametrize("method", ["rk45", "hht", None])
def test_load_callable_raising_mid_run_ends_the_run_named(kind, method):
    m, b, _ = pendulum()

    def load(t, state):
        if t > 0.1:
            return (0.0, 0.0, 1.0 / 0.0)
        return (0.0, 0.0, 0.0)
    getattr(m, f"add_{kind}")("ext", b, load)
    res = mb.simulate(m, 0.3, 0.01, method=method)
    assert not res.success and isinstance(res.error, EvaluationError)
    assert (res.error.entity, res.error.field) == (f"{kind} 'ext'", kind)
    assert 0.1 < res.error.time < 0.2 and "ZeroDivisionError" in res.message
    # the samples before it are the free pendulum's: energy conserved (no load acted before t = 0.1)
    assert 9 <= len(res.time) and res.time[-1] <= res.error.time
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) < 1e-4 * 9.81


def test_wrong_signature_load_callable_refused_when_added():
    m, b, _ = pendulum()
    with pytest.raises(ModelError) as err:
        m.add_torque("tq", b, lambda: (0.0, 0.0, 1.0))
    assert (err.value.entity, err.value.field) == ("torque 'tq'", "torque")
    with pytest.raises(ModelError) as err:
        m.add_force("f", b, lambda t, state, extra: (0.0, 0.0, 1.0))
    assert (err.value.entity, err.value.field) == ("force 'f'", "force")
    with pytest.raises(ModelError) as err:
        m.add_motion("d", "j", displacement=lambda: 0.0)
    assert (err.value.entity, err.value.field) == ("motion 'd'", "displacement")
    assert "tq" not in m.forces and "f" not in m.forces and "d" not in m.motions


def test_force_returning_a_string_is_named():
    m, b, _ = pendulum()
    m.add_force("f", b, lambda t, state: "abc")
    with pytest.raises(EvaluationError) as err:
        mb.simulate(m, 0.1, 0.01, method="rk45")
    assert (err.value.entity, err.value.field) == ("force 'f'", "force") and "'abc'" in str(err.value)


# ------------------------------------------------------------------ arguments
def test_output_count_against_memory_budget():
    m, _, _ = pendulum()
    with pytest.raises(ModelError, match="GiB") as err:
        mb.simulate(m, 1e6, output_step=1e-6)
    assert err.value.field == "output_step"
    with pytest.raises(ModelError, match="GiB"):
        mb.kinematics(m, 1e6, output_step=1e-6)


@pytest.mark.parametrize("value", [float("nan"), "a", float("inf"), None])
def test_start_time_checked(value):
    m, _, _ = pendulum()
    with pytest.raises(ModelError) as err:
        mb.simulate(m, 1.0, start_time=value)
    assert (err.value.entity, err.value.field) == ("simulate", "start_time")


def test_nested_expression_limits_keep_cost_bounded():
    m, _, j = pendulum()
    t0 = time.perf_counter()
    with pytest.raises(ModelError, match="operations") as err:
        m.add_motion("d", j, displacement="sin(" * 150 + "t" + ")" * 150)
    assert (err.value.entity, err.value.field) == ("motion 'd'", "displacement")
    with pytest.raises(ModelError, match="operations"):   # a power tower: refused when added, not at run time
        m.add_motion("d", j, displacement="t" + "**t" * 50)
    assert time.perf_counter() - t0 < 10
    # cost grows polynomially with depth up to the limit: depth 20 -> 40 costs far less than 2**20 times
    times = []
    for d in (10, 20):
        t0 = time.perf_counter()
        mb.parse("sin(" * d + "t" + ")" * d).derivative().derivative()
        times.append(time.perf_counter() - t0)
    assert times[1] < 2.0


def test_mass_properties():
    m = mb.Model()
    with pytest.raises(ModelError) as err:
        m.add_body("x", 1.0, inertia=(1.0, 1.0, 5.0))
    assert (err.value.entity, err.value.field) == ("body 'x'", "inertia") and "triangle" in str(err.value)
    with pytest.raises(ModelError) as err:
        m.add_body("y", True, inertia=(1.0, 1.0, 1.0))
    assert (err.value.entity, err.value.field) == ("body 'y'", "mass")
    assert not m.bodies or set(m.bodies) <= {"ground"}


def ball(z, radius=0.5):
    m = mb.Model("c", gravity=(0, 0, -9.81))
    b = m.add_body("ball", 1.0, inertia=(0.1, 0.1, 0.1), position=(0, 0, z))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(b, radius), stiffness=1e5, exponent=1.5,
                  damping=10.0, penetration=1e-3)
    return m


def test_initial_contact_penetration_refused_or_warned():
    with pytest.raises(ModelError) as err:
        mb.simulate(ball(-0.5), 0.1, 0.01)   # 1 m inside the plane: the centre is past it
    assert (err.value.entity, err.value.field) == ("contact 'c'", "initial_gap")
    from mbdsim.solvers.checks import InitialPenetrationWarning
    with pytest.warns(InitialPenetrationWarning, match=r"contact 'c'.initial_gap: .*0.05 m"):
        mb.simulate(ball(0.45), 0.01, 0.005)
    with warnings.catch_warnings():
        warnings.simplefilter("error", InitialPenetrationWarning)
        mb.simulate(ball(0.4995), 0.01, 0.005)   # a working penetration (0.5 mm) is normal


def test_result_refuses_another_models_entities_of_the_same_name():
    m, b, j = pendulum()
    s = m.add_spring_damper("s", (b, (1, 0, 0)), (m.ground, (1, 1, 0)), 10.0)
    m2, b2, j2 = pendulum()
    s2 = m2.add_spring_damper("s", (b2, (1, 0, 0)), (m2.ground, (1, 1, 0)), 10.0)
    res = mb.simulate(m, 0.05, 0.01)
    for fn in (lambda: res.joint_coordinate(j2), lambda: res.reaction_force(j2), lambda: res.position(b2),
               lambda: res.spring_force(s2), lambda: res.position(b, frame=b2)):
        with pytest.raises(ModelError, match="another model|not part of the analysed model"):
            fn()
    res.joint_coordinate(j), res.spring_force(s), res.joint_coordinate("j")   # its own, and by name, work


# ------------------------------------------------------------------ interrupts
def test_keyboard_interrupt_in_compiled_run_returns_partial_result():
    m, _, _ = pendulum()
    calls = []

    def progress(t):
        calls.append(t)
        if len(calls) == 2:
            raise KeyboardInterrupt
    res = mb.simulate(m, 50.0, 0.001, progress=progress)
    assert not res.success and isinstance(res.error, AnalysisInterrupted)
    assert 0 < res.time[-1] < 50.0 and len(res.time) > 256
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) < 1e-6 * 9.81


@pytest.mark.parametrize("method", ["rk45", "hht"])
def test_keyboard_interrupt_in_python_paths_returns_partial_result(method):
    m, b, _ = pendulum()

    def load(t, state):
        if t > 0.2:
            raise KeyboardInterrupt
        return (0.0, 0.0, 0.0)
    m.add_torque("tq", b, load)
    res = mb.simulate(m, 1.0, 0.01, method=method)
    assert not res.success and isinstance(res.error, AnalysisInterrupted)
    assert 0.15 < res.time[-1] <= 0.2 + 1e-12


def test_cli_ctrl_c_exits_130_after_writing_what_it_has(tmp_path, monkeypatch):
    """Ctrl-C arrives as KeyboardInterrupt between chunks of the compiled run (here raised from the
    progress bar's update, where Python is re-entered): the CLI writes the samples so far and exits 130."""
    from rich.progress import Progress
    from typer.testing import CliRunner
    from mbdsim.cli.app import app
    model = tmp_path / "p.yaml"
    model.write_text("name: p\ngravity: [0, -9.81, 0]\nbodies:\n  - {name: b, mass: 1, inertia: [0.01, 0.01, 0.01], "
                     "position: [1, 0, 0]}\njoints:\n  - {name: j, type: revolute, body_i: ground, body_j: b, "
                     "point: [0, 0, 0], axis: [0, 0, 1]}\n")
    out = tmp_path / "res.csv"
    calls, update = [], Progress.update

    def interrupting_update(self, task, **kw):
        calls.append(kw.get("completed"))
        if len(calls) == 3:
            raise KeyboardInterrupt
        return update(self, task, **kw)
    monkeypatch.setattr(Progress, "update", interrupting_update)
    r = CliRunner().invoke(app, ["run", str(model), "--end", "2000", "--step", "0.002", "--out", str(out)])
    assert r.exit_code == 130, r.output
    df = pd.read_csv(out)
    assert len(df) >= 256 and 0 < df["time [s]"].iloc[-1] < 2000


# ------------------------------------------------------------------ issue 34: every analysis keeps what it computed
def _raising_at(t_fail, value=lambda t: 0.5 * t):
    def f(t):
        if t > t_fail:
            raise RuntimeError("encoder lost")
        return value(t)
    return f


@pytest.mark.parametrize("wrap", ["plain", "time_function"])
def test_kinematics_driver_raising_at_0_12_keeps_the_samples_before(wrap):
    m, _, j = pendulum()
    f = _raising_at(0.12)
    drive = f if wrap == "plain" else mb.expressions.time_function(f, d1=lambda t: 0.5, d2=lambda t: 0.0)
    m.add_motion("d", j, displacement=drive)
    res = mb.kinematics(m, 1.0, 0.01)
    assert not res.success and isinstance(res.error, EvaluationError)
    assert res.error.entity == "motion 'd'" and "encoder lost" in res.message
    # the plain callable's numerical derivatives at 0.12 s need f beyond 0.12 s: the fault is at 0.12 s
    # there (12 samples kept), at 0.13 s with exact derivatives (13 samples); before issue 34 the coarse
    # steps (0.1 s) of the numerical derivatives failed already at 0.02 s and kept 2
    assert 0.12 - 1e-9 <= res.error.time <= 0.13 + 1e-9
    assert len(res.time) >= 12 and res.time[-1] < res.error.time
    assert np.allclose(res.joint_coordinate("j"), 0.5 * res.time, atol=1e-9)


def test_quasi_static_load_raising_mid_run_keeps_the_equilibria_before():
    m, b, _ = pendulum()
    f = _raising_at(0.12, lambda t: 2.0 * t)
    m.add_torque("tq", b, lambda t, state: (0.0, 0.0, f(t)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.quasi_static(m, 1.0, 0.01)
    assert not res.success and isinstance(res.error, EvaluationError)
    assert res.error.entity == "torque 'tq'" and "encoder lost" in res.message
    assert len(res.time) >= 12 and res.time[-1] < res.error.time <= 0.13 + 1e-9
    # equilibrium of the hanging rod: m g sin(th) = torque, th measured from hanging straight down
    th = res.joint_coordinate("j") + np.pi / 2
    np.testing.assert_allclose(9.81 * np.sin(th), 2.0 * res.time, atol=1e-7)


def _failing_pendulum(fail):
    m, _, j = pendulum()
    m.add_motion("d", j, displacement=_raising_at(0.12) if fail else (lambda t: 0.5 * t))
    return m


def test_study_variant_failing_mid_run_is_marked_and_the_others_kept():
    study = mb.Study(_failing_pendulum, {"fail": [0, 1, 0]}, {"last": "final(x(position('b')))"},
                     analysis={"type": "kinematics", "end_time": 0.5, "output_step": 0.01})
    df = study.run(workers=0)
    assert list(df.status) == ["ok", "failed", "ok"]
    assert "motion 'd'" in df.message[1] and "encoder lost" in df.message[1]
    assert np.isfinite(df["last"][[0, 2]]).all() and df["last"][0] == pytest.approx(np.cos(0.25), abs=1e-9)
