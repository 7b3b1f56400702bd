"""FMUs in the Simulator's step loop (Model.add_fmu): an FMI 2.0 co-simulation FMU run by fmpy as a
sampled subsystem (a controller, a hydraulic model).

At each communication point t_k = t0 + k h the FMU's inputs are set from their expressions of the
mechanism's state at t_k (compiled like the model's outputs: mbdsim.cosim.outputs), the FMU advances
one communication step (fmi2DoStep(t_k, h)), and its outputs are written to the model inputs they feed,
held over [t_k, t_k + h] (the FMU acts first, as a sampled controller: what it computes from the state
at t_k drives the mechanism until t_(k+1)). Times in s.
"""
from __future__ import annotations

import shutil
import weakref

from ..errors import ModelError


def _release(fmu, unzipdir):
    """Terminate and free an FMU instance and remove its extracted files (finaliser)."""
    try:
        fmu.terminate()
        fmu.freeInstance()
    except Exception:  # noqa: BLE001 - already gone, or the FMU failed: nothing more to do
        pass
    shutil.rmtree(unzipdir, ignore_errors=True)


class FmuRunner:
    """One FMU of `Model.add_fmu` (`link`, a model.signals.FmuLink) instantiated for Simulator `sim`,
    started at t0 [s]; `next_time` is its next communication point [s]."""

    def __init__(self, link, sim, t0: float):
        try:
            from fmpy import extract, read_model_description
            from fmpy.fmi2 import FMU2Slave
        except ImportError:
            raise ModelError(f"fmu '{link.name}'", "path", "running an FMU needs fmpy (pip install fmpy)") from None
        from .outputs import ExprPrograms
        self.link, self.sim = link, sim
        entity = f"fmu '{link.name}'"
        md = read_model_description(link.path)
        refs = {v.name: v.valueReference for v in md.modelVariables}
        self._in = [refs[k] for k in link.inputs]
        self._out = [refs[k] for k in link.outputs]
        self._targets = list(link.outputs.values())
        self._exprs = ExprPrograms(sim.system, sim._run, sim._rep, sim._slots,
                                   {f"{link.name}:{k}": t for k, t in link.inputs_text.items()})
        self.can_save = bool(md.coSimulation.canGetAndSetFMUstate)
        unzipdir = extract(link.path)
        try:
            self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                                 instanceName=link.name)
            self.fmu.instantiate()
            self.fmu.setupExperiment(startTime=t0)
            self.fmu.enterInitializationMode()
            self.fmu.exitInitializationMode()
        except Exception as exc:  # noqa: BLE001 - the FMU's own failure, named
            shutil.rmtree(unzipdir, ignore_errors=True)
            raise ModelError(entity, "path", f"the FMU {link.path!r} failed to start: {exc}") from None
        self._finalize = weakref.finalize(self, _release, self.fmu, unzipdir)
        self.next_time = t0

    def sample(self, t: float) -> None:
        """The communication point t [s]: inputs from the state, one FMU step of h, outputs to the model."""
        sim, h = self.sim, self.link.step
        if self._in:
            self._exprs.stale = True
            values = self._exprs.values(t, sim._y)
            self.fmu.setReal(self._in, list(values.values()))
        try:
            self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            out = self.fmu.getReal(self._out) if self._out else []
        except Exception as exc:  # noqa: BLE001 - fmpy raises on an FMU's error status
            raise ModelError(f"fmu '{self.link.name}'", "path", f"the FMU failed at t = {t:.12g} s: {exc}") from None
        for target, v in zip(self._targets, out):
            sim.set_input(target, v)
        self.next_time = t + h

    def save(self):
        """(next communication time [s], the FMU's state or None when it cannot save one)."""
        return self.next_time, (self.fmu.getFMUstate() if self.can_save else None)

    def load(self, saved) -> None:
        next_time, fmu_state = saved
        if fmu_state is None:
            raise ModelError(f"fmu '{self.link.name}'", "state", "the FMU cannot save and restore its state "
                             "(canGetAndSetFMUstate is false): a Simulator with it cannot restore()")
        self.fmu.setFMUstate(fmu_state)
        self.next_time = next_time

    def close(self) -> None:
        self._finalize()
