"""The Simulator's compiled step: every array of a stepped run held once in a numba structref (kernel module).

Calling a kernel from Python costs the unboxing of its arguments; the compiled model's and work arrays'
tuples (about a hundred arrays) plus the integrator's scratch are several microseconds at every call, more
than a small model's step.  `pack` puts them once into a `Stepper` (a numba structref: a Python handle on
compiled storage, unboxed by one pointer), whose arrays are the Simulator's own (the same memory: what
Python writes into the input constants or the state is what the kernels read).  `advance` is the whole
macro step in one call: the re-projection of the state onto the constraints when an input read by a
motion driver changed, the right-hand side at the step's start when an input changed (the integrator
keeps f = ydot(t, y) between calls), the compiled DOP853 (`solvers.fastdop.run`) to the target time,
and the model's outputs at the end; `outputs` evaluates the outputs alone (after `set_input`).
Times in s, SI units; status codes those of `solvers.fastdyn` and `solvers.fastdop`.
"""
from __future__ import annotations

from numba import njit, typeof, types
from numba.experimental import structref

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from ..solvers.fastdop import _sensor_g, run
from ..solvers.fastdyn import OK, project, rhs

PROJECTION_TOL = 1e-12   # the run's projection tolerance (simulate's)

_FIELDS = ("cm", "wk", "cmo", "wko", "co", "st", "y", "f", "tout", "Y", "K", "F", "sc", "SY", "ST", "ns",
           "stats", "yo", "values", "par", "watch", "n_out")


@structref.register
class StepperType(types.StructRef):
    """numba type of a `Stepper`: one field per array group of `_FIELDS`."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(t)) for name, t in fields)


class Stepper(structref.StructRefProxy):
    """Python handle on the compiled storage of one Simulator's arrays (made by `pack`)."""


structref.define_boxing(StepperType, Stepper)


@njit(cache=True)
def _new(typ, cm, wk, cmo, wko, co, st, y, f, tout, Y, K, F, sc, SY, ST, ns, stats, yo, values, par, watch,
         n_out):
    s = structref.new(typ)
    s.cm, s.wk, s.cmo, s.wko, s.co = cm, wk, cmo, wko, co
    s.st, s.y, s.f, s.tout, s.Y = st, y, f, tout, Y
    s.K, s.F, s.sc, s.SY, s.ST, s.ns, s.stats = K, F, sc, SY, ST, ns, stats
    s.yo, s.values, s.par, s.watch, s.n_out = yo, values, par, watch, n_out
    return s


def pack(**arrays) -> Stepper:
    """A Stepper holding `arrays` (the keyword names of `_FIELDS`: the kernels' tuples cm, wk; those of the
    output programs cmo, wko; the DOP853 coefficients co; the state st = [t, h], y, f; tout (2,), Y (2, row);
    the scratch K, F, sc, SY, ST, ns, stats; yo, values (outputs); par = [rtol, atol, max_step]; watch
    (bool: sensors watched) and n_out (int: the number of outputs)). The arrays are shared, not copied."""
    args = [arrays[k] for k in _FIELDS]
    typ = StepperType([(k, typeof(a)) for k, a in zip(_FIELDS, args)])
    return _new(typ, *args)


@njit(cache=True)
def advance(s, t1, fresh, reproject, max_steps):
    """One macro step from st[0] to t1 [s]: (status, next output index; 2 when t1 was reached). fresh:
    f is ydot at the current state and inputs; reproject: the state is projected onto the constraints
    at st[0] first (a motion driver's value or rate jumped with an input), then f is evaluated."""
    cm, wk, st, y, f = s.cm, s.wk, s.st, s.y, s.f
    if reproject:
        nq = cm[31][0]
        code = project(cm, wk, st[0], y[:nq], y[nq:], PROJECTION_TOL, True)
        if code != OK:
            return code, 1
        fresh = False
    if st[1] > 0.0 and not fresh:
        code = rhs(cm, wk, st[0], y, f, True)
        if code != OK:
            return code, 1
    tout = s.tout
    tout[0] = st[0]
    tout[1] = t1
    par = s.par
    status, iout = run(cm, wk, s.co, st, y, f, t1, tout, 1, s.Y, par[0], par[1], par[2], max_steps, 1 << 30,
                       PROJECTION_TOL, s.stats, s.K, s.F, s.sc, False, s.SY, s.ST, s.ns, s.watch)
    if status == OK and iout == 2 and s.n_out > 0:
        _sensor_g(s.cmo, s.wko, st[0], y, s.yo, s.values)
    return status, iout


@njit(cache=True)
def outputs(s):
    """The model's outputs at the current time and state into s.values."""
    if s.n_out > 0:
        _sensor_g(s.cmo, s.wko, s.st[0], s.y, s.yo, s.values)
