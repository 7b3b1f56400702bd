"""Model inputs and outputs (issue 33): named scalars that a control loop writes and reads.

`Model.add_input(name, value)` declares a scalar that load, sensor and output expressions read by name
(e.g. `add_joint_force("motor", "pin", "u")`); `mbdsim.Simulator.set_input` changes it between steps
(held constant over each step), and `simulate` uses `value`. `Model.add_output(name, expression)`
declares a measured signal: an expression of the state in the language of load expressions
(mbdsim.model.loadexpr: t, joint coordinates and rates, measures DX ... AZ, and the inputs), read by
`Simulator.output(name)` and exported as an FMU output. Units are the user's: SI in the core (an input
read as a torque is in N m, one read as an angle in rad).
"""
from __future__ import annotations

from typing import Any

from dataclasses import dataclass

from ..errors import ModelError
from ._check import scalar


@dataclass(eq=False)
class Input:
    """A scalar input: its `name` (read by expressions) and `value` (what `simulate` and a new Simulator
    start with; SI units of whatever reads it)."""

    name: str
    value: float = 0.0

    def __repr__(self) -> str:
        return f"Input({self.name!r} = {self.value:g})"


@dataclass(eq=False)
class Output:
    """A measured signal: `name` and its expression (a LoadExpr of the state and inputs; `text` the string
    given). Units: those of the quantity the expression gives."""

    name: str
    expression: object
    text: str

    def __repr__(self) -> str:
        return f"Output({self.name!r}: {self.text})"


class SignalsMixin:
    """add_input, add_output (Model methods)."""

    def add_input(self, name: str, value: float = 0.0) -> Input:
        """Declare the scalar input `name` (initial `value`, SI units of whatever reads it) that load,
        sensor and output expressions read by name (e.g. a joint force "u" [N m]); declare it before the
        elements that read it. `mbdsim.Simulator.set_input(name, v)` changes it between steps."""
        entity = f"input '{name}'"
        from .loadexpr import check_name
        check_name(entity, name, True)
        if not isinstance(name, str) or not name.isidentifier():
            raise ModelError(entity, "name", f"{name!r} must be an identifier (letters, digits, _), so that "
                             "expressions can read it")
        if name.endswith("_dot") and name[:-4] in self.joints:
            raise ModelError(entity, "name", f"{name!r} is how expressions read the rate of joint {name[:-4]!r}")
        self._claim(name, "input")
        try:
            v = scalar(entity, "value", value)
        except ModelError:
            self._names.discard(name)
            raise
        inp = Input(name, v)
        self.__dict__.setdefault("inputs", {})[name] = inp
        return inp

    def add_function(self, name: str, function: Any) -> Any:
        """Make the compiled function `function` callable as `name(x, ...)` in the model's load, sensor
        and output expressions: a `numba.njit` function or a `numba.cfunc` of 1 to 6 float64 arguments
        returning a float64, in the SI units of what it computes (mbdsim.userfunctions). The compiled
        kernels call it through its C address (no Python in the loop); declare it before the elements that
        read it. A plain Python callable is refused (ModelError): give a load callable (t, state) instead,
        or decorate it with numba.njit. Returns the mbdsim.userfunctions.UserFunction."""
        from ..userfunctions import user_function
        from .loadexpr import check_name
        entity = f"function '{name}'"
        check_name(entity, name, True)
        if not name.isidentifier():
            raise ModelError(entity, "name", f"{name!r} must be an identifier (letters, digits, _), so that "
                             "expressions can call it")
        if name in getattr(self, "tables", {}):
            raise ModelError(entity, "name", f"the model has a table {name!r}: choose another name")
        if name in getattr(self, "functions", {}):
            raise ModelError(entity, "name", "a function of this name already exists in the model")
        uf = user_function(function, name, entity=entity)   # (called by name: entities may share the name)
        self.__dict__.setdefault("functions", {})[name] = uf
        return uf

    def add_output(self, name: str, expression: str) -> Output:
        """Declare the measured signal `name`: an expression string of the state, as load expressions use
        (t [s], joint coordinates by name and <joint>_dot, DX ... AZ of bodies and markers, the model's
        inputs), in the SI units of what it computes. Read by `mbdsim.Simulator.output(name)`."""
        from .loadexpr import parse_load
        entity = f"output '{name}'"
        self._claim(name, "output")
        try:
            if not isinstance(expression, str):
                raise ModelError(entity, "expression", f"expected an expression string, got {expression!r}")
            le = parse_load(self, expression, entity, "expression")
        except ModelError:
            self._names.discard(name)
            raise
        out = Output(name, le, expression)
        self.__dict__.setdefault("outputs", {})[name] = out
        return out


@dataclass(eq=False)
class FmuLink:
    """An FMI 2.0 co-simulation FMU in the Simulator's step loop: `path` of the .fmu, `inputs` {FMU input:
    LoadExpr of the state} (`inputs_text` the strings), `outputs` {FMU output: model input name}, the
    communication `step` [s], and `description` (fmpy's ModelDescription)."""

    name: str
    path: str
    inputs: dict
    inputs_text: dict
    outputs: dict
    step: float
    description: object = None

    def __repr__(self) -> str:
        return f"FmuLink({self.name!r}: {self.path}, every {self.step:g} s)"


def _fmu_description(entity, path):
    """fmpy's ModelDescription of an FMI 2.0 co-simulation FMU at `path`, else ModelError naming `path`."""
    import os
    if not isinstance(path, (str, os.PathLike)) or not os.path.isfile(path):
        raise ModelError(entity, "path", f"no FMU file at {path!r}")
    try:
        from fmpy import read_model_description
    except ImportError:
        raise ModelError(entity, "path", "running an FMU needs fmpy (pip install fmpy, or mbdsim[fmi])") from None
    try:
        md = read_model_description(str(path))
    except Exception as exc:  # noqa: BLE001 - a broken archive or XML, named
        raise ModelError(entity, "path", f"{str(path)!r} is not a readable FMU: {exc}") from None
    if not str(md.fmiVersion).startswith("2.") or md.coSimulation is None:
        raise ModelError(entity, "path", f"{str(path)!r} is not an FMI 2.0 co-simulation FMU "
                         f"(FMI {md.fmiVersion}, co-simulation: {md.coSimulation is not None})")
    return md


class FmuMixin:
    """add_fmu (a Model method)."""

    def add_fmu(self, name: str, path: str, inputs: dict | None = None, outputs: dict | None = None,
                step: float | None = None) -> FmuLink:
        """Run the FMI 2.0 co-simulation FMU at `path` (with fmpy) as a sampled subsystem in the step loop
        of `mbdsim.Simulator`: every `step` seconds (default: the FMU's default experiment step size) its
        inputs are set from `inputs` {FMU input name: expression of the state, as load expressions use},
        it advances one communication step, and its outputs are written to the model inputs named by
        `outputs` {FMU output name: model input name} and held until its next sample (the FMU sees the
        state at the start of its step and its outputs act over that step: a sampled controller)."""
        from .loadexpr import parse_load
        entity = f"fmu '{name}'"
        self._claim(name, "fmu")
        try:
            md = _fmu_description(entity, path)
            variables = {v.name: v for v in md.modelVariables}

            def check(field, key, causality):
                v = variables.get(key)
                if v is None or v.causality != causality:
                    names = [n for n, x in variables.items() if x.causality == causality]
                    raise ModelError(entity, field, f"{key!r} is not an {causality} of the FMU ({causality}s: "
                                     f"{', '.join(names) or 'none'})")
            exprs, texts = {}, {}
            for key, text in dict(inputs or {}).items():
                check("inputs", key, "input")
                if not isinstance(text, str):
                    text = repr(float(scalar(entity, f"inputs[{key}]", text)))
                exprs[key], texts[key] = parse_load(self, text, entity, f"inputs[{key}]"), text
            outs = {}
            for key, target in dict(outputs or {}).items():
                check("outputs", key, "output")
                if target not in getattr(self, "inputs", {}):
                    raise ModelError(entity, "outputs", f"{target!r} is not an input of the model (declare it with "
                                     f"Model.add_input; inputs: {', '.join(getattr(self, 'inputs', {})) or 'none'})")
                outs[key] = target
            default = md.defaultExperiment.stepSize if md.defaultExperiment is not None else None
            if step is None and default is None:
                raise ModelError(entity, "step", "the FMU has no default step size: give step [s]")
            h = scalar(entity, "step", default if step is None else step, 0.0, strict=True)
        except ModelError:
            self._names.discard(name)
            raise
        link = FmuLink(name, str(path), exprs, texts, outs, h)
        self.__dict__.setdefault("fmus", {})[name] = link
        return link
