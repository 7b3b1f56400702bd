"""FMI 2.0 co-simulation export (issue 33): `export_fmu(model, path)` and `mbdsim export-fmu`.

The FMU is packaged with pythonfmu: its resources hold the model as model-file data (mbdsim.io, JSON) and
a small slave class (`_SLAVE` below) that builds the model and an `mbdsim.Simulator` at initialisation
and advances it by one communication step per fmi2DoStep, the FMU's inputs held over the step.

FMU variables: one input per model input (causality input, start = its value), one output per model
output (causality output), and one parameter (causality parameter, variability fixed, start = the
model's value) per numeric field of the model file that a study could vary, named by its path with
list items by name and vector components in brackets ("bodies.rod.mass", "gravity[1]",
"forces.k.stiffness"), SI units. The importing side needs a Python 3 with mbdsim (and pythonfmu's
runtime, which the FMU's binary embeds) installed: the FMU's binary runs the slave in that Python, as
every pythonfmu FMU does; the numba kernels compile on first use there (cached afterwards).
"""
from __future__ import annotations

import json
import re
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Union

from ..errors import ModelError

if TYPE_CHECKING:
    from .._types import PathLike
    from ..model.model import Model

_SKIP = ("inputs", "outputs", "name", "planar")   # sections and fields that are not parameters


def parameters(data: dict) -> dict:
    """{FMI name: (model-data path as studies.variant.apply_path takes it, value)} of every numeric field of
    model-file data `data` (booleans and texts are not parameters; inputs are the FMU's inputs)."""
    out = {}

    def walk(node, fmi, path):
        if isinstance(node, bool) or node is None:
            return
        if isinstance(node, (int, float)):
            out[fmi] = (path, float(node))
        elif isinstance(node, dict):
            for k, v in node.items():
                if not path and k in _SKIP or k in ("name", "type"):
                    continue
                walk(v, f"{fmi}.{k}" if fmi else str(k), f"{path}.{k}" if path else str(k))
        elif isinstance(node, list):
            for k, v in enumerate(node):
                key = v.get("name") if isinstance(v, dict) else None
                if isinstance(key, str) and key.isidentifier():
                    walk(v, f"{fmi}.{key}", f"{path}.{key}")
                else:
                    walk(v, f"{fmi}[{k}]", f"{path}.{k}")
    walk(data, "", "")
    return out


def _identifier(name: str) -> str:
    """A Python class name (the FMU's model identifier) from the model's name."""
    s = re.sub(r"\W", "_", str(name)) or "model"
    return "Mbdsim_" + s


def export_fmu(model: Union[Model, PathLike], path: PathLike, rtol: float | None = None, step_size: float = 1e-3) -> Path:
    """Write an FMI 2.0 co-simulation FMU of `model` (a Model or a model file path) to `path` (.fmu) and
    return its path. rtol: the Simulator's tolerance inside the FMU (default: simulate's "auto"; an
    importer's relative tolerance from fmi2SetupExperiment overrides it); step_size [s]: the default
    experiment's communication step. Needs pythonfmu (pip install pythonfmu, or mbdsim[fmi]); the
    importing side needs a Python with mbdsim (see the module docstring). ModelError for a model that
    cannot be stored in a model file (Python callables, FMUs) or a bad path."""
    from ..io import load_model, model_to_dict
    from ..model._check import scalar
    from ..model.model import Model
    if not isinstance(model, Model):
        model = load_model(model)
    out = Path(path)
    if out.suffix.lower() != ".fmu":
        raise ModelError("export_fmu", "path", f"expected a .fmu file name, got {str(path)!r}")
    if not out.parent.is_dir():
        raise ModelError("export_fmu", "path", f"the folder {str(out.parent)!r} does not exist")
    h = scalar("export_fmu", "step_size", step_size, 0.0, strict=True)
    if rtol is not None:
        scalar("export_fmu", "rtol", rtol, 0.0, strict=True)
    data = model_to_dict(model)
    try:
        from pythonfmu.builder import FmuBuilder
    except ImportError:
        raise ModelError("export_fmu", "path", "FMU export needs pythonfmu (pip install pythonfmu)") from None
    params = parameters(data)
    meta = {"model": data, "rtol": rtol, "step_size": h,
            "inputs": [[i.name, i.value] for i in getattr(model, "inputs", {}).values()],
            "outputs": list(getattr(model, "outputs", {})),
            "parameters": [[k, p, v] for k, (p, v) in params.items()]}
    clash = set(params) & ({n for n, _ in meta["inputs"]} | set(meta["outputs"]))
    if clash:
        raise ModelError("export_fmu", "model", f"inputs or outputs named like parameters: {sorted(clash)}")
    cls = _identifier(model.name)
    with tempfile.TemporaryDirectory(prefix="mbdsim_fmu_") as tmp:
        script = Path(tmp) / f"{cls.lower()}.py"
        script.write_text(_SLAVE.replace("CLASSNAME", cls))
        (Path(tmp) / "mbdsim_fmu.json").write_text(json.dumps(meta))
        built = FmuBuilder.build_FMU(script, dest=tmp, project_files=[Path(tmp) / "mbdsim_fmu.json"],
                                     needsExecutionTool="false", canHandleVariableCommunicationStepSize="true")
        shutil.move(str(built), str(out))
    return out


# the FMU's slave: pythonfmu imports it inside the importing tool's Python (mbdsim must be installed there)
_SLAVE = '''"""mbdsim FMU slave (generated by mbdsim.export_fmu): a Simulator advanced one communication step at a time."""
import copy
import json
import os

from pythonfmu import DefaultExperiment, Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class CLASSNAME(Fmi2Slave):
    author = "mbdsim"
    description = "mbdsim multibody model (FMI 2.0 co-simulation); needs a Python with mbdsim"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        here = self.resources if self.resources and os.path.isdir(self.resources) else os.path.dirname(__file__)
        with open(os.path.join(here, "mbdsim_fmu.json")) as fh:
            self._meta = json.load(fh)
        self.default_experiment = DefaultExperiment(start_time=0.0, step_size=self._meta["step_size"])
        self._u = {n: float(v) for n, v in self._meta["inputs"]}
        self._y = {n: 0.0 for n in self._meta["outputs"]}
        self._p = {n: float(v) for n, _, v in self._meta["parameters"]}
        self._sim, self._t0, self._rtol = None, 0.0, self._meta["rtol"]
        for n in self._u:
            self.register_variable(Real(n, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                                        start=self._u[n], getter=lambda n=n: self._u[n],
                                        setter=lambda v, n=n: self._u.__setitem__(n, float(v))))
        for n in self._y:
            self.register_variable(Real(n, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                                        getter=lambda n=n: self._y[n]))
        for n in self._p:
            self.register_variable(Real(n, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                                        start=self._p[n], getter=lambda n=n: self._p[n],
                                        setter=lambda v, n=n: self._p.__setitem__(n, float(v))))

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._t0 = float(start_time or 0.0)
        if tolerance:
            self._rtol = float(tolerance)

    def exit_initialization_mode(self):
        import mbdsim
        from mbdsim.io import model_from_dict
        from mbdsim.studies.variant import apply_path
        data = copy.deepcopy(self._meta["model"])
        for n, path, v in self._meta["parameters"]:
            if self._p[n] != v:
                apply_path(data, path, self._p[n])
        for item in data.get("inputs", []):
            item["value"] = self._u[item["name"]]
        self._sim = mbdsim.Simulator(model_from_dict(data, source="FMU model"), rtol=self._rtol,
                                     start_time=self._t0)
        self._y.update(self._sim.outputs())

    def do_step(self, current_time, step_size):
        sim = self._sim
        for n, v in self._u.items():
            sim.set_input(n, v)
        sim.advance_to(current_time + step_size)
        self._y.update(sim.outputs())
        return True
'''
