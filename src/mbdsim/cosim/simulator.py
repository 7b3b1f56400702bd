"""`Simulator`: a model assembled and compiled once, advanced step by step (control loops, co-simulation).

    sim = mb.Simulator(model)                 # model.add_input("u"), model.add_output("theta", "pin")
    for k in range(1000):                     # a PD controller sampled at 1 kHz
        sim.set_input("u", -kp * sim.output("theta") - kd * sim.output("omega"))
        sim.step(1e-3)
    res = sim.result()

Each `step(dt)` runs the compiled, error-controlled DOP853 of `simulate` (mbdsim.solvers.fastdop.run: as
many internal steps as the tolerance needs, projection onto the constraints, sensors watched) from the
current state to t + dt with the inputs held constant, in one compiled call on arrays packed once
(mbdsim.cosim._stepper: the derivative at the step's start after an input changed, the run, the outputs
at its end); between steps Python only writes the inputs into the constants of the compiled expression
and driver programs (mbdsim.system.exprloads_pack, mbdsim.cosim.drivers: motion drivers reading inputs
keep a velocity driver's displacement continuous, and a displacement driver's jump re-projects the state
at the step's start) and reads the outputs. Nothing is re-assembled or re-compiled. Times in s, SI
units throughout.
The model must be one the compiled core carries (as simulate's method "auto"); FMUs added with
`Model.add_fmu` run in the loop at their communication steps (mbdsim.cosim.fmu_import).
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ModelError, SolverError
from ..solvers import fastdop, pyloads
from ..solvers.fastdyn import INTERRUPTED
from . import _stepper
from .._slots import Slots
from ._fastcall import Bound

if TYPE_CHECKING:
    from ..model.model import Model
    from ..results.result import Result

MAX_STEPS_PER_CALL = 10_000_000   # internal steps of one step()/advance_to(), at most (simulate's budget)
_ROUND = 1e-12                    # relative: a target time this close to the current one is reached


@dataclasses.dataclass(frozen=True)
class SimulatorState:
    """A snapshot of a Simulator (`Simulator.state()`): time [s], integrator state, step size, inputs, FMU
    states and the kernels' work arrays, so that `restore` continues bit-identically. `n` is how many
    samples the history had (restore drops the later ones)."""

    time: float
    data: tuple
    inputs: dict
    n: int
    fmus: tuple = ()


def _copy(x):
    """A deep copy of nested tuples of arrays."""
    return tuple(_copy(a) for a in x) if isinstance(x, (tuple, Slots)) else np.array(x, copy=True)


def _put(dst, src):
    """Copy nested tuples of arrays `src` into `dst` in place."""
    if isinstance(dst, (tuple, Slots)):
        for d, s in zip(dst, src):
            _put(d, s)
    else:
        dst[...] = src


class Simulator:
    """A model assembled and compiled once and advanced step by step (see the module docstring).

    rtol: target relative error of the outputs as simulate's "auto" (default 1e-7; the step control uses
    rtol / 20, atol in the same ratio); start_time [s]. ModelError when the model is not one the compiled
    core carries (a Python-callable load is fine; joint friction, path constraints are not)."""

    def __init__(self, model: Model, rtol: float | None = None, start_time: float = 0.0):
        from ..solvers.assembly import assemble_state
        from ..solvers.checks import check_initial_contacts
        from ..solvers.compiled_run import CompiledRun
        from ..solvers.dynamic import AUTO_LOCAL, _number, _positive, _tolerances
        from ..solvers.kinematic import check_model
        from ..system.assemble import assemble_system
        from ..system.compiled import NotCompiled
        check_model(model, "Simulator")
        rt, at = _tolerances("auto", None if rtol is None else _positive("rtol", rtol), None)
        t0 = _number("start_time", start_time)
        self.model = model
        sys = self.system = assemble_system(model)
        rep = self._rep = assemble_state(sys, sys.q0, sys.v0, t0)
        check_initial_contacts(sys, rep.q, rep.v)
        try:
            run = CompiledRun(sys, rep.rows, AUTO_LOCAL * rt, AUTO_LOCAL * at, None, state=(rep.q, rep.v))
        except NotCompiled as exc:
            raise ModelError("Simulator", "model", f"the step-by-step Simulator needs a model the compiled core "
                             f"carries ({exc})") from None
        ex = list(run.cm.exprloads)
        if len(ex) > 14:   # the inputs are constants of these programs: this Simulator's own copy
            ex[14] = ex[14].copy()
        consts = run.cm.consts.copy() if run.cm.driver_slots else run.cm.consts   # drivers reading inputs
        run.cm = dataclasses.replace(run.cm, exprloads=tuple(ex), consts=consts)
        self._run = run
        self._a, self._w = run.cm.arrays(), run.work.arrays()
        self._inputs = {n: float(i.value) for n, i in getattr(model, "inputs", {}).items()}
        self._slots = {n: [] for n in self._inputs}   # input -> [(array, index)] written by set_input
        for name, k in run.cm.input_slots:
            self._slots[name].append((ex[14], k))
        from .drivers import driver_constants
        self._drivers = driver_constants(run, self._slots)   # input -> [DriverConstants]
        from .outputs import ExprPrograms
        self._out = ExprPrograms(sys, run, rep, self._slots,
                                 {n: o.text for n, o in getattr(model, "outputs", {}).items()})
        y0 = np.concatenate([rep.q, rep.v])
        self._y = run.state_of(y0)
        n = len(self._y)
        self._f = np.zeros(n)
        self._st = np.array([t0, 0.0])   # h = 0: the first step starts the integrator (fastdop.run)
        self._K, self._F, self._sc = np.zeros((16, n)), np.zeros((7, n)), np.zeros((4, n))
        self._SY, self._ST, self._ns = np.zeros((0, n)), np.zeros((0, 2)), np.zeros(1, np.int64)
        self._Y = np.zeros((2, len(y0)))
        self._Y[0] = y0
        self._tout = np.array([t0, t0])
        self._watch = bool(run.sensors)
        self._fresh = False   # f is the derivative at the current state with the current inputs
        self._times, self._rows, self._held = [t0], [y0.copy()], [self._input_vector()]
        self.stopped = None   # the SensorEvent of a sensor with action "stop", once met
        self._reproject = False   # an input read by a motion driver changed: project at the step's start
        out = self._out
        self._box = _stepper.pack(
            cm=self._a, wk=self._w, cmo=out.arrays[0] if out.names else self._a,
            wko=out.arrays[1] if out.names else self._w, co=fastdop.COEFFS, st=self._st, y=self._y,
            f=self._f, tout=self._tout, Y=self._Y, K=self._K, F=self._F, sc=self._sc, SY=self._SY, ST=self._ST,
            ns=self._ns, stats=run.stats, yo=out.yo, values=out.buffer,
            par=np.array([run.rtol, run.atol, run.max_step]), watch=self._watch, n_out=len(out.names))
        self._kernel = Bound(_stepper.advance)
        self._outputs = Bound(_stepper.outputs)
        from .fmu_import import FmuRunner
        self._fmus = [FmuRunner(link, self, t0) for link in getattr(model, "fmus", {}).values()]
        for fmu in self._fmus:
            fmu.sample(t0)

    # ------------------------------------------------------------------ inputs and outputs
    @property
    def time(self) -> float:
        """The current time [s]."""
        return float(self._st[0])

    def set_input(self, name: str, value: float) -> None:
        """Set the model input `name` (Model.add_input) to `value` (SI units of what reads it), held
        constant over the following steps until set again."""
        if name not in self._inputs:
            raise ModelError(f"input '{name}'", "name", f"the model has no input {name!r} (inputs: "
                             f"{', '.join(self._inputs) or 'none; declare them with Model.add_input'})")
        if value.__class__ is float and value - value == 0.0:   # a finite float (the loop's usual case)
            v = value
        else:
            from ..model._check import scalar
            v = scalar(f"input '{name}'", "value", value)
        if v != self._inputs[name]:
            self._inputs[name] = v
            for drv in self._drivers.get(name, ()):   # motion drivers reading it: anchors moved at t
                drv.set(float(self._st[0]), name, v)
                self._reproject = self._reproject or drv.reprojects
            for arr, k in self._slots[name]:
                arr[k] = v
            self._fresh = False
            self._out.stale = True

    def input(self, name: str) -> float:
        """The current value of input `name`."""
        if name not in self._inputs:
            raise ModelError(f"input '{name}'", "name", f"the model has no input {name!r}")
        return self._inputs[name]

    def output(self, name: str) -> float:
        """The model output `name` (Model.add_output) at the current time and state."""
        out = self._out
        if out.stale:
            self._outputs(self._box)
            out.stale = False
        return out.read(name)

    def outputs(self) -> dict:
        """{output name: value} of every model output at the current time and state."""
        out = self._out
        if out.stale:
            self._outputs(self._box)
            out.stale = False
        return dict(zip(out.names, out.buffer.tolist()))

    # ------------------------------------------------------------------ stepping
    def step(self, dt: float) -> float:
        """Advance by dt [s] > 0 (inputs held constant; internal steps as the error control needs);
        returns the new time [s]."""
        if not (dt.__class__ is float and 0.0 < dt < np.inf):
            from ..model._check import scalar
            dt = scalar("Simulator.step", "dt", dt, 0.0, strict=True)
        t = float(self._st[0]) + dt
        if self._fmus or self.stopped is not None:
            return self.advance_to(t)
        if dt > _ROUND * max(1.0, abs(t)):   # (the loop's usual case: no FMU, not stopped)
            self._advance(t)
        return float(self._st[0])

    def advance_to(self, t: float) -> float:
        """Advance to time t [s] (>= the current time), FMUs sampled at their communication steps on the
        way; returns the time reached (earlier than t only when a sensor with action "stop" was met)."""
        if not (t.__class__ is float and t - t == 0.0):
            from ..model._check import scalar
            t = scalar("Simulator.advance_to", "t", t)
        if self.stopped is not None:
            raise ModelError("Simulator", "time", f"the run was stopped by sensor '{self.stopped.name}' at "
                             f"t = {self.stopped.time:.12g} s (restore an earlier state to go on)")
        if t < self._st[0] - _ROUND * max(1.0, abs(self._st[0])):
            raise ModelError("Simulator.advance_to", "t", f"{t!r} s is before the current time {self.time!r} s "
                             "(restore an earlier state() to go back)")
        if not self._fmus:
            if t - self._st[0] > _ROUND * max(1.0, abs(t)):
                self._advance(t)
            return float(self._st[0])
        while self.stopped is None and t - self.time > _ROUND * max(1.0, abs(t)):
            nxt = min([t] + [f.next_time for f in self._fmus])
            self._advance(nxt)
            for fmu in self._fmus:
                if self.stopped is None and fmu.next_time <= self.time + _ROUND * max(1.0, abs(self.time)):
                    fmu.sample(self.time)
        return self.time

    def _advance(self, t1: float) -> None:
        """One macro step of the compiled DOP853 from the current state to t1 [s] (one output there, and
        the model's outputs evaluated there: mbdsim.cosim._stepper.advance)."""
        run = self._run
        fresh, reproject = self._fresh, self._reproject
        iout, status = 1, 0
        max_steps = int(run.stats[0]) + MAX_STEPS_PER_CALL
        events = run.sensors
        try:
            while iout < 2 and status in (0, fastdop.EVENTS_FULL):
                if events:
                    run._take_events()
                status, iout = self._kernel(self._box, t1, fresh, reproject, max_steps)
                fresh, reproject = True, False
        except KeyboardInterrupt:
            status = INTERRUPTED
        if status != 0:
            status, run.run_error = pyloads.settle(run.pyloads, status, run.run_error)
        if events:
            run._take_events()
        self._fresh, self._reproject = True, False
        self._out.stale = not (status == 0 and iout == 2)
        if status == fastdop.SENSOR_STOP:
            self._stop(t1)
            return
        if status != 0 or iout < 2:
            self._fail(status, t1)
        self._record(t1, self._Y[1])

    def _record(self, t, row):
        Y = self._Y
        Y[0] = row
        self._times.append(float(t))
        self._rows.append(np.array(row, copy=True))
        self._held.append(self._input_vector())

    def _stop(self, t1):
        """A sensor with action "stop" ended the step at st[0]: its state is the last sample."""
        from ..solvers.fastdyn import write_state
        row = np.zeros(self._Y.shape[1])
        write_state(self._a, self._w, self._y, row, self._Y[0])
        self._record(self._st[0], row)
        self.stopped = min((e for e in self._run.sensor_events if e.action == "stop"), key=lambda e: e.time)
        self._fresh = False

    def _fail(self, status, t1):
        from ..solvers.compiled_run import failure
        from ..solvers.fastdyn import write_state
        row = np.zeros(self._Y.shape[1])
        write_state(self._a, self._w, self._y, row, row[:0])
        error, _ = failure(self.system, self._rep, status, float(self._st[0]), row, np.array(self._times),
                           "integration failed", self._run.run_error)
        if status == 0:
            error = SolverError(f"the step to t = {t1:.12g} s did not reach its end", time=float(self._st[0]))
        raise error

    def _driver_list(self) -> list:
        """Each DriverConstants once (a driver may read several inputs)."""
        return list({id(d): d for ds in self._drivers.values() for d in ds}.values())

    def _input_vector(self) -> tuple:
        return tuple(self._inputs.values())

    # ------------------------------------------------------------------ snapshots and results
    def state(self) -> SimulatorState:
        """A copy of everything the next steps depend on; `restore(state)` reinstates it (trial moves,
        model-predictive control). FMUs are saved through FMI 2.0 getFMUstate when they can."""
        data = (self._st.copy(), self._y.copy(), self._f.copy(), self._run.stats.copy(), self._Y[0].copy(),
                _copy(self._w), self._fresh, len(self._run.sensor_events), self._reproject,
                tuple(d.save() for d in self._driver_list()))
        return SimulatorState(self.time, data, dict(self._inputs), len(self._times),
                              tuple(f.save() for f in self._fmus))

    def restore(self, state: SimulatorState) -> None:
        """Go back to `state` (from `state()` of this Simulator): time, integrator, inputs and FMUs; the
        history (result()) loses the samples after it."""
        if not isinstance(state, SimulatorState) or len(state.data[1]) != len(self._y) or \
                len(state.fmus) != len(self._fmus):
            raise ModelError("Simulator.restore", "state", "expected a state() of this Simulator")
        st, y, f, stats, row, w, fresh, nev, reproject, drivers = state.data
        self._st[:], self._y[:], self._f[:], self._run.stats[:], self._Y[0] = st, y, f, stats, row
        _put(self._w, w)
        self._fresh = fresh
        del self._run.sensor_events[nev:]
        for name, v in state.inputs.items():
            self._inputs[name] = np.nan   # written whatever the current value
            self.set_input(name, v)
        self._fresh, self._reproject = fresh, reproject
        for d, values in zip(self._driver_list(), drivers):
            d.load(values)
        self._out.stale = True   # the outputs at the restored state (a model without inputs too)
        del self._times[state.n:], self._rows[state.n:], self._held[state.n:]
        self.stopped = None
        for fmu, s in zip(self._fmus, state.fmus):
            fmu.load(s)

    def result(self) -> Result:
        """The Result of every sample so far (the start and the end of each step); accelerations and
        multipliers at a sample use the inputs held over the step that ended there (the first: those at
        the start). res.stats["inputs"]: {input: values (n,)} held at each sample."""
        from ..results.result import Result
        from ..solvers.compiled_run import _full_multipliers
        sys, run = self.system, self._run
        t, Y = np.array(self._times), np.array(self._rows)
        held = np.array(self._held, dtype=float).reshape(len(t), len(self._inputs))

        def accelerations():
            VD, LAM = np.zeros((len(t), sys.nv)), np.zeros((len(t), sys.nc))
            now = dict(self._inputs)
            try:
                for key in {tuple(h) for h in held.tolist()}:
                    sel = np.flatnonzero(np.all(held == np.array(key), axis=1))
                    for name, v in zip(self._inputs, key):
                        for arr, k in self._slots[name]:
                            arr[k] = v
                    VD[sel], LAM[sel] = run.outputs(t[sel], Y[sel])
            finally:
                for name, v in now.items():
                    for arr, k in self._slots[name]:
                        arr[k] = v
                self._fresh = False
            return VD, _full_multipliers(sys, self._rep.rows, t, Y, VD, LAM)

        stats = {"method": "DOP853 (compiled, stepped)", "steps": int(run.stats[0]), "rejected": int(run.stats[1]),
                 "nfev": int(run.stats[2]), "assembly": self._rep,
                 "inputs": {n: held[:, k].copy() for k, n in enumerate(self._inputs)}}
        msg = "ok" if self.stopped is None else f"stopped by sensor '{self.stopped.name}' at t = {self.time:.12g} s"
        res = Result(sys, t, Y[:, :sys.nq], Y[:, sys.nq:], None, None, stats=stats, message=msg,
                     accelerations=accelerations)
        res.sensor_events = list(run.sensor_events)
        return res

    def __repr__(self) -> str:
        return f"Simulator({self.model.name!r}, t = {self.time:.6g} s, inputs {self._inputs})"
