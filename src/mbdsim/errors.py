"""Errors raised by mbdsim: each names the offending entity and field."""
from __future__ import annotations


class MbdsimError(Exception):
    """Base class of every mbdsim error."""


class ModelError(MbdsimError, ValueError):
    """Invalid model input: names the entity and the field at fault."""

    def __init__(self, entity: str, field: str, message: str):
        self.entity, self.field = entity, field
        super().__init__(f"{entity}.{field}: {message}")


class ModelFileError(ModelError):
    """An error in a model file (YAML/JSON): names the file, the line where known, the entity and the field."""

    def __init__(self, entity: str, field: str, message: str, file: str | None = None, line: int | None = None):
        self.file, self.line, self.message = file, line, message
        super().__init__(entity, field, message)
        where = ", ".join(p for p in (file, None if line is None else f"line {line}") if p)
        self.args = (f"{where}: {self.args[0]}" if where else self.args[0],)


class _TimedError(MbdsimError):
    """An analysis failure at a time, naming the joints involved and keeping the last state."""

    def __init__(self, message: str, time: float | None = None, joints=(), state=None):
        self.time, self.joints, self.state = time, tuple(joints), state
        where = f" at t = {time:.9g} s" if time is not None else ""
        names = f" (joints involved: {', '.join(self.joints)})" if self.joints else ""
        super().__init__(f"{message}{where}{names}")


class AssemblyError(_TimedError):
    """The constraints cannot be satisfied (assembly or kinematic position analysis)."""


class SolverError(_TimedError):
    """A solver failed (lock-up, singular equations, step size underflow)."""


class EvaluationError(SolverError):
    """A user function or expression failed during an analysis (raised, returned a non-number or a
    non-finite value): names the element (`entity`), its `field` and the time [s]."""

    def __init__(self, entity: str, field: str, message: str, time: float | None = None):
        self.entity, self.field = entity, field
        super().__init__(f"{entity}.{field}: {message}", time=time)


class AnalysisInterrupted(SolverError):
    """The analysis was interrupted (KeyboardInterrupt): the Result keeps every output before it."""
