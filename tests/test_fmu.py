"""FMI 2.0 co-simulation (issue 33): the exported FMU run by fmpy against the Simulator loop, its model
description, parameters, the CLI; an FMU controller (built here with pythonfmu) closing the loop through
Model.add_fmu against the same controller written in the Simulator loop."""
import textwrap

import fmpy
import numpy as np
import pytest
from pythonfmu.builder import FmuBuilder
from typer.testing import CliRunner

import mbdsim as mb
from mbdsim.errors import ModelError

from test_simulator import KD, KP, PERIOD, REF, _arm, _pd

H = 0.01   # communication step [s]


def _step_signal(t_step, value, t_end):
    return np.array([(0.0, 0.0), (t_step, 0.0), (t_step, value), (t_end, value)], dtype=[("time", float), ("u", float)])


def _loop_with_step(sim, n, t_step, value):
    out = []
    for _ in range(n):
        sim.set_input("u", value if sim.time >= t_step - 1e-12 else 0.0)
        sim.step(H)
        out.append((sim.output("theta"), sim.output("omega")))
    return np.array(out)


def test_exported_fmu_matches_simulator(tmp_path):
    m = _arm(0.3)
    path = mb.export_fmu(m, tmp_path / "arm.fmu", step_size=H)
    md = fmpy.read_model_description(str(path))
    var = {v.name: v for v in md.modelVariables}
    assert var["u"].causality == "input" and var["theta"].causality == "output" and var["omega"].causality == "output"
    assert var["bodies.rod.mass"].causality == "parameter" and float(var["bodies.rod.mass"].start) == 1.3
    assert md.coSimulation is not None and md.fmiVersion == "2.0"
    n = 40
    r = fmpy.simulate_fmu(str(path), stop_time=n * H, step_size=H, output_interval=H,
                          input=_step_signal(0.1, 2.0, n * H), output=["theta", "omega"])
    ref = _loop_with_step(mb.Simulator(m), n, 0.1, 2.0)
    assert np.allclose(r["time"][1:], H * np.arange(1, n + 1))
    assert np.abs(r["theta"][1:] - ref[:, 0]).max() < 1e-8
    assert np.abs(r["omega"][1:] - ref[:, 1]).max() < 1e-8
    assert abs(ref[-1, 0]) > 0.01
    # a parameter changed by the importer: the model with that value
    r2 = fmpy.simulate_fmu(str(path), stop_time=n * H, step_size=H, output_interval=H, start_values={"bodies.rod.mass": 2.0},
                           input=_step_signal(0.1, 2.0, n * H), output=["theta"])
    ref2 = _loop_with_step(mb.Simulator(_heavier(m)), n, 0.1, 2.0)
    assert np.abs(r2["theta"][1:] - ref2[:, 0]).max() < 1e-8
    assert np.abs(r2["theta"][1:] - r["theta"][1:]).max() > 1e-3


def _heavier(m):
    from mbdsim.io import model_from_dict, model_to_dict
    data = model_to_dict(m)
    data["bodies"][0]["mass"] = 2.0
    return model_from_dict(data)


def test_cli_export_fmu(tmp_path):
    from mbdsim.cli.app import app
    mb.save_model(_arm(), tmp_path / "arm.yaml")
    out = CliRunner().invoke(app, ["export-fmu", str(tmp_path / "arm.yaml"), str(tmp_path / "arm.fmu")])
    assert out.exit_code == 0, out.output
    names = {v.name: v.causality for v in fmpy.read_model_description(str(tmp_path / "arm.fmu")).modelVariables}
    assert names["u"] == "input" and names["omega"] == "output"
    bad = CliRunner().invoke(app, ["export-fmu", str(tmp_path / "arm.yaml"), str(tmp_path / "arm.zip")])
    assert bad.exit_code == 2 and "fmu" in bad.output


_CONTROLLER = textwrap.dedent(f'''
    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

    class PDController(Fmi2Slave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.theta = self.omega = self.tau = 0.0
            self.kp, self.kd, self.ref = {KP!r}, {KD!r}, {REF!r}
            self.register_variable(Real("theta", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous, start=0.0))
            self.register_variable(Real("omega", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous, start=0.0))
            self.register_variable(Real("tau", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous))

        def do_step(self, t, dt):
            self.tau = -self.kp * (self.theta - self.ref) - self.kd * self.omega
            return True
''')


def test_fmu_controller_closes_the_loop(tmp_path):
    (tmp_path / "pdcontroller.py").write_text(_CONTROLLER)
    fmu = FmuBuilder.build_FMU(tmp_path / "pdcontroller.py", dest=tmp_path)
    m = _arm(0.2)
    m.add_fmu("pd", str(fmu), inputs={"theta": "pin", "omega": "pin_dot"}, outputs={"tau": "u"}, step=PERIOD)
    sim = mb.Simulator(m, rtol=1e-10)
    th_fmu = []
    for _ in range(40):
        sim.step(PERIOD)
        th_fmu.append(sim.output("theta"))
    ref = mb.Simulator(_arm(0.2), rtol=1e-10)
    th_py = []
    for _ in range(40):
        ref.set_input("u", _pd(ref.output("theta"), ref.output("omega")))
        ref.step(PERIOD)
        th_py.append(ref.output("theta"))
    assert np.abs(np.array(th_fmu) - th_py).max() < 1e-12
    assert abs(th_fmu[-1]) > 0.3
    # a longer step() crosses several communication points: the same samples
    sim2 = mb.Simulator(m, rtol=1e-10)
    sim2.step(20 * PERIOD)
    assert sim2.output("theta") == pytest.approx(th_fmu[19], abs=1e-12)


def test_add_fmu_errors(tmp_path):
    (tmp_path / "pdcontroller.py").write_text(_CONTROLLER)
    fmu = str(FmuBuilder.build_FMU(tmp_path / "pdcontroller.py", dest=tmp_path))
    m = _arm()
    with pytest.raises(ModelError, match="fmu 'c'.*path"):
        m.add_fmu("c", str(tmp_path / "missing.fmu"), step=0.01)
    with pytest.raises(ModelError, match="fmu 'c'.*inputs.*'speed' is not an input"):
        m.add_fmu("c", fmu, inputs={"speed": "pin"}, step=0.01)
    with pytest.raises(ModelError, match="fmu 'c'.*outputs.*not an input of the model"):
        m.add_fmu("c", fmu, outputs={"tau": "torque"}, step=0.01)
    with pytest.raises(ModelError, match="fmu 'c'.*step"):
        m.add_fmu("c", fmu, outputs={"tau": "u"})
    m.add_fmu("c", fmu, outputs={"tau": "u"}, step=0.01)
    with pytest.raises(ModelError, match="fmu 'c'.*model files"):
        mb.save_model(m, tmp_path / "m.yaml")
