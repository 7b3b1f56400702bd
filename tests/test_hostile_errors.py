"""Issue 35, never a bare exception: bad inputs that used to end in ZeroDivisionError, IndexError,
TypeError, RecursionError or ValueError (or in a message that named nothing) now raise one error naming
the entity and field (and for files, the file and line). API and model-file cases that fit the
catalogue are in tests/bad_inputs; these need a run, a file written by hand, or a message checked."""
import json

import pytest

import mbdsim as mb
from mbdsim.errors import EvaluationError, ModelError, ModelFileError, SolverError
from mbdsim.solvers import kinematic


def pendulum():
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 1.0, inertia=(0.08, 1e-4, 0.08), position=(0.0, -0.5, 0.0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    return m


# ----------------------------------------------------------------------------- results
def test_to_dataframe_of_a_result_without_outputs(monkeypatch):
    m = pendulum()
    m.add_motion("d", "pin", displacement="t")

    def fails(*args, **kwargs):
        raise RuntimeError("no solution")
    monkeypatch.setattr(kinematic, "_compiled_sweep", lambda *a: None)   # the Python path, failing at t = 0
    monkeypatch.setattr(kinematic, "solve_at", fails)
    res = mb.kinematics(m, 1.0, 0.1)
    assert not res.success and len(res.time) == 0
    with pytest.raises(ModelError) as err:
        res.to_dataframe()
    assert (err.value.entity, err.value.field) == ("to_dataframe", "result")
    assert "no outputs" in str(err.value) and "no solution" in str(err.value)


@pytest.mark.parametrize("euler", ["XYZW", "XXY", "xYz", 3, ""])
def test_to_dataframe_refuses_a_bad_euler_sequence(euler):
    res = mb.simulate(pendulum(), 0.1, 0.05)
    with pytest.raises(ModelError) as err:
        res.to_dataframe(euler=euler)
    assert (err.value.entity, err.value.field) == ("to_dataframe", "euler") and repr(euler) in str(err.value)
    assert "rod.ZYX_1 [rad]" in res.to_dataframe(euler="ZYX").columns


# ----------------------------------------------------------------------------- messages that name the culprit
@pytest.mark.parametrize("method", [None, "hht"])
def test_a_massless_body_is_named_in_the_singular_message(method):
    m = pendulum()
    tip = m.add_body("tip", 0.0, inertia=(0, 0, 0), position=(0.0, -1.0, 0.0))
    m.add_revolute("pin2", m.bodies["rod"], tip, (0, -1, 0), (0, 0, 1))
    try:
        res = mb.simulate(m, 0.1, 0.05, method=method)
        assert not res.success
        text = str(res.error)
    except SolverError as exc:   # (the reference path fails while starting, before its first output)
        text = str(exc)
    assert "singular equations of motion" in text and "zero mass: body 'tip'" in text


@pytest.mark.parametrize("method", [None, "hht"])
@pytest.mark.parametrize("expr", ["log(pin)", "sqrt(0.1 - t)"])
def test_a_non_finite_expression_load_is_named(method, expr):
    m = pendulum()
    m.add_force("push", (m.bodies["rod"], (0, 0, 0)), (expr, "0", "0"))
    try:
        res = mb.simulate(m, 0.3, 0.05, method=method)
        assert not res.success
        err = res.error
    except EvaluationError as exc:
        err = exc
    assert isinstance(err, EvaluationError) and (err.entity, err.field) == ("force 'push'", "force"), err
    assert "evaluates to" in str(err) and "non-finite state" not in str(err)


# ----------------------------------------------------------------------------- model files
def _load_error(tmp_path, name, text):
    (tmp_path / name).write_text(text)
    with pytest.raises(ModelFileError) as err:
        mb.load_model(tmp_path / name)
    assert err.value.file == name
    return err.value


@pytest.mark.parametrize("name", ["m.json", "m.yaml"])
@pytest.mark.parametrize("depth", [100, 100_000])
def test_deeply_nested_files_are_refused(tmp_path, name, depth):
    text = '{"name": "x", "bodies": ' + "[" * depth + "]" * depth + "}\n"
    err = _load_error(tmp_path, name, text)
    assert "nested deeper than 64 levels" in str(err)


def test_save_model_refuses_what_is_not_a_model(tmp_path):
    deep = []
    for _ in range(100_000):
        deep = [deep]
    for junk in (deep, {"name": "x"}):
        with pytest.raises(ModelError) as err:
            mb.save_model(junk, tmp_path / "m.yaml")
        assert (err.value.entity, err.value.field) == ("save_model", "model")
    assert not (tmp_path / "m.yaml").exists()


@pytest.mark.parametrize("name", ["m.json", "m.yaml"])
def test_a_5000_digit_integer_is_refused_naming_the_field(tmp_path, name):
    text = json.dumps({"name": "x", "bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1]}]}, indent=1)
    err = _load_error(tmp_path, name, text.replace('"mass": 1', '"mass": ' + "9" * 5000))
    assert (err.entity, err.field, err.line) == ("body 'b'", "mass", 6)
    assert "an integer of 5000 digits" in str(err)


# ----------------------------------------------------------------------------- Python API
def test_empty_model_is_refused_before_any_work():
    for run in (lambda m: mb.simulate(m, 1.0), lambda m: mb.simulate(m, 1.0, method="hht"),
                lambda m: mb.kinematics(m, 1.0, 0.1)):
        with pytest.raises(ModelError) as err:
            run(mb.Model("empty"))
        assert (err.value.entity, err.value.field) == ("model 'empty'", "bodies")


def test_json_duplicate_keys_are_refused_naming_file_line_and_key(tmp_path):
    text = '{"name": "x",\n "bodies": [{"name": "b", "mass": 1,\n   "inertia": [1, 1, 1],\n   "mass": 2}]}\n'
    err = _load_error(tmp_path, "m.json", text)
    assert (err.field, err.line) == ("mass", 4) and "duplicate key 'mass'" in str(err)
    err = _load_error(tmp_path, "t.json", '{"name": "x",\t"name": "y", "bodies": []}')   # (not YAML: no line)
    assert err.field == "name" and "duplicate key 'name'" in str(err)


# ----------------------------------------------------------------------------- silently accepted before
@pytest.mark.parametrize("returned", [("1", "0", "0"), (1.0, "0", 0.0), [True, 0, 0]])
def test_a_load_callable_returning_text_fails_the_run_naming_it(returned):
    m = pendulum()
    m.add_force("f", (m.bodies["rod"], (0, 0, 0)), lambda t, s: (0.0, 0.0, 0.0) if t < 0.05 else returned)
    try:
        res = mb.simulate(m, 0.2, 0.05)
        assert not res.success
        err = res.error
    except EvaluationError as exc:
        err = exc
    assert isinstance(err, EvaluationError) and (err.entity, err.field) == ("force 'f'", "force")


def test_a_zero_length_spring_between_coincident_points_runs():
    m = pendulum()   # free length and preload zero: force stiffness * (p_j - p_i), continuous at zero length
    m.add_spring_damper("s", (m.bodies["rod"], (0, -1, 0)), (m.ground, (0, -1, 0)), stiffness=50.0)
    res = mb.simulate(m, 0.5, 0.1)
    assert res.success and abs(res.joint_coordinate("pin")).max() < 1e-9   # (at rest: hanging, unstretched)


# ----------------------------------------------------------------------------- initial velocities of welded bodies
def _welded(**given):
    m = mb.Model("weld", gravity=(0.0, -9.81, 0.0))
    base = m.add_body("base", 2.0, inertia=(0.1, 0.1, 0.1), **given)
    m.add_fixed("weld", m.ground, base, (0, 0, 0))
    rod = m.add_body("rod", 1.0, inertia=(0.08, 1e-4, 0.08), position=(0.3, -0.5, 0.0))
    m.add_revolute("pin", base, rod, (0.3, 0, 0), (0, 0, 1), initial_velocity=1.0)
    return m


@pytest.mark.parametrize("given", [dict(angular_velocity=(0.0, 0.0, 5.0)), dict(velocity=(1.0, 2.0, 0.0)),
                                   dict(angular_velocity=(3.0, -1.0, 5.0), velocity=(0.0, 0.0, 4.0))])
def test_a_welded_body_given_velocities_takes_the_welds(given):
    ref = mb.simulate(_welded(), 1.0, 0.05)
    with pytest.warns(mb.InitialConditionWarning, match="body 'base'"):
        res = mb.simulate(_welded(**given), 1.0, 0.05)
    assert res.success, res.message   # (before: the child started at 1e15 m/s and the run failed at t = 0)
    assert abs(res.angular_velocity("base")).max() < 1e-9 and abs(res.velocity("base")).max() < 1e-9
    assert abs(res.joint_coordinate("pin") - ref.joint_coordinate("pin")).max() < 1e-8


# ----------------------------------------------------------------------------- dissipated energy, reference path
def test_dissipated_energy_of_an_hht_run_is_quick_and_balances():
    import time
    m = mb.Model("fourbar", gravity=(0.0, -9.81, 0.0), planar=True)
    crank = m.add_body("crank", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.0, 0.5, 0.0))
    coupler = m.add_body("coupler", 1.0, inertia=(0.1, 0.1, 0.1), position=(1.0, 1.0, 0.0))
    rocker = m.add_body("rocker", 1.0, inertia=(0.1, 0.1, 0.1), position=(2.0, 0.5, 0.0))
    m.add_revolute("A", m.ground, crank, (0, 0, 0), (0, 0, 1), initial_velocity=3.0)
    m.add_revolute("B", crank, coupler, (0, 1, 0), (0, 0, 1))
    m.add_revolute("C", coupler, rocker, (2, 1, 0), (0, 0, 1))
    m.add_revolute("D", rocker, m.ground, (2, 0, 0), (0, 0, 1))
    m.add_spring_damper("k", (coupler, (1.0, 1.0, 0)), (m.ground, (1.0, -1.0, 0)), stiffness=50.0, damping=2.0,
                        free_length=1.5)
    res = mb.simulate(m, 1.0, 0.01, method="hht")
    assert res.success and res.stats["method"].startswith("HHT")
    t0 = time.process_time()
    D = res.dissipated_energy()   # (before: every Chebyshev point a Newton solve through Result.at, ~60 s)
    # issue 35: within 2 s. CPU time of this process (not wall time: the machine is shared), so the bound
    # is the issue's own and still guards the 60 s of the re-integrating version
    assert time.process_time() - t0 < 2.0
    E = res.kinetic_energy() + res.potential_energy()
    assert D[-1] > 1.0 and abs((E[0] - E[-1]) - D[-1]) < 1e-3 * D[-1]
