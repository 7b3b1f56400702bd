"""Loads (t, state) and drivers (t) written as Python callables, evaluated from inside the compiled step
loop (issue 29).

`attach(sys, cm, work)` wraps the force elements the kernels call back (`CompiledModel.python_loads`: Python
callables, and elements that cannot be packed in the model's formulation, `system.compiled._called_back`)
in one ctypes
callback `int64 f(double t)` whose address goes into the work arrays (slot 48); the kernels' `loads_into`
calls it at every evaluation of the loads (solvers.pycall). The callback reads the frames the kernel has
just computed (r, A, rd, w: work slots 0-3, ground axes), rebuilds the absolute state [q, v] from them
(one compiled call, `fasttree.to_maximal`), hands the user's callable a light `State` of that one instant
(its frames injected, so nothing is recomputed; `results.state.State`), and writes the generalized loads
of those elements (the same evaluators as the reference path: `system.force_elements`) into work slot
48[0] (six slots per frame: force [N] in ground axes, torque [N m] in body axes).

Drivers whose function has no compiled program (a Python callable of t, or an integral without a closed
form) get a second callback (address in slot 48[1][2]): `drivers_at` calls it after the programs, and it
writes value, d1, d2 of each such driver into the kernels' driver arrays (work slots 34-36).

Sensors whose signal is a Python callable (t, state) are programs of the expression sensors (system.
exprloads_pack) that call a ctypes callback `double f(double t)` (`sensor_callback`, one per sensor, its
address a constant of the program: exprvm's USER op) wherever the step loop evaluates the sensors, at the
accepted steps and at the probes of the event location on the dense output (solvers.fastdop, as for
expression sensors): the callback hands the sensor's callable the light State of the frames the kernel has
just computed for that time and returns the signal (nan once it has failed: the step loops then end the run
at the start of that step, fastdop.SENSOR_FAILED, and `settle` reports the error naming the sensor and the
time). User functions compiled with numba (mbdsim.userfunctions)
need no callback; a run whose user function returned a non-finite value ends with the EvaluationError
naming it (`settle`).

A callable that raises, or returns a non-finite or malformed value, is caught here (a ctypes callback
cannot raise into the kernel): the callback returns 1 and the step is rejected; shorter steps then reach
up to the failure (the outputs before it are written), and after CALLBACK_RETRIES failed steps in a row the
kernel ends the run with CALLBACK_FAILED; `error` keeps the EvaluationError naming the load, field and
time (a KeyboardInterrupt inside the callable makes every later call fail: an interrupted run).
"""
from __future__ import annotations

import ctypes
import math

import numpy as np

from ..errors import EvaluationError, MbdsimError
from ..results.state import State
from ..system.force_elements import evaluator
from ..system.frames import Frames
from . import fasttree
from .pydrive import triple

_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_double)
_SIGNAL = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double)


class SensorCallback:
    """The ctypes callback `double f(double t)` of one Python-callable sensor: the signal at the kernel's
    current frames (through `target`, the PythonLoads of the run; nan while no run is attached)."""

    def __init__(self, sensor):
        self.sensor, self.name, self.target = sensor, f"sensor '{sensor.name}'", None
        self._cb = _SIGNAL(self._call)
        self.address = ctypes.cast(self._cb, ctypes.c_void_p).value

    def _call(self, t):
        pyl = self.target
        return math.nan if pyl is None else pyl.signal(self.sensor, t)


_SENSOR_CALLBACKS: dict = {}   # id(sensor) -> SensorCallback (kept out of the sensor: the model's fingerprint)


def sensor_callback(sensor) -> SensorCallback:
    """The SensorCallback of a Python-callable sensor (made once per sensor object and signal, kept here: the
    compiled model's programs hold its address)."""
    from ..userfunctions import _BY_ADDRESS
    cb = _SENSOR_CALLBACKS.get(id(sensor))
    if cb is None or cb.sensor is not sensor or cb.signal is not sensor.signal:
        cb = SensorCallback(sensor)
        cb.signal = sensor.signal
        _SENSOR_CALLBACKS[id(sensor)] = cb
        _BY_ADDRESS[cb.address] = cb
    return cb


def all_applied(elems) -> bool:
    """Whether the called-back elements are all applied forces and torques (their power: the work W of the
    energy balance, summed by the kernel from the loads the callback writes; solvers.energy_run)."""
    from ..model.forces import Force, Torque
    return all(isinstance(e, (Force, Torque)) for e in elems)


class PythonLoads:
    """The callback of one run's work arrays (keep this object alive as long as the kernels may call it)."""

    def __init__(self, sys, cm, work):
        wk = work.arrays()
        self.sys, self.cm, self.wk = sys, cm, wk
        self.elems = [sys.model.forces[n] for n in cm.python_loads]
        self.F, self.ctl = wk[48][0], wk[48][1]
        self.calls, self.error, self.interrupted = 0, None, False
        self.last_failed = False   # whether the latest call of either callback failed
        self.sensor_error = None   # the error of a Python-callable sensor (the run ends with it)
        self.ctl[:] = 0
        self._callbacks = []   # kept alive: the kernels hold their addresses
        from ..userfunctions import reset, sites
        self.user_sites = sites(cm)   # compiled user functions and sensor callbacks (exprvm's USER op)
        reset(self.user_sites)
        for sn in getattr(sys.model, "sensors", {}).values():
            cb = _SENSOR_CALLBACKS.get(id(sn))
            if sn.text is None and cb is not None and cb.sensor is sn:
                cb.target = self
        if self.elems:
            self.ctl[0] = self._address(self._call)
        if cm.python_drivers:
            fns = sys.derived["packed"][6]
            drv, owner = sys.derived["packed"][5], sys.row_owner
            rows = {int(d): r for r, d in enumerate(drv) if d >= 0}
            self.drivers = [(d, triple(fns[d]), f"motion '{owner[rows[d]]}'") for d in cm.python_drivers]
            self._driver_names = ", ".join(e for _, _, e in self.drivers)
            self.ctl[2] = self._address(self._drive)
        # the velocity slots of each frame (frame f's six load slots are v[vadr[f]: vadr[f] + 6]; particles 3):
        # F[f, k] = Q[vadr[f] + k], one scatter of the flat F
        slots = [(f, int(a), 6 if sys.frame_rigid[f] else 3) for f, a in enumerate(sys.frame_v_adr) if a >= 0]
        self.F_dst = np.array([6 * f + k for f, a, n in slots for k in range(n)], dtype=np.int64)
        self.F_src = np.array([a + k for f, a, n in slots for k in range(n)], dtype=np.int64)
        self.F_flat = self.F.reshape(-1)   # a view (F is C-contiguous)
        # every frame rigid: Q is F's rows 1.. as they stand (a view the loads are added into, no scatter)
        contiguous = np.array_equal(self.F_dst, 6 + np.arange(sys.nv)) and np.array_equal(self.F_src, np.arange(sys.nv))
        self._Q_in_F = self.F_flat[6:6 + sys.nv] if contiguous else None
        self.evals = [(evaluator(e), e) for e in self.elems]
        self._load_entity = "load '" + ", ".join(e.name for e in self.elems) + "'"
        self.applied = bool(self.elems) and all_applied(self.elems)
        self.ctl[3] = int(self.applied)   # their power is the applied loads' work (fastenergy)
        # fasttree.to_maximal's model arguments (the absolute state from the kernel's frames)
        self._tree = (cm.tree, cm.p_idx, cm.r_idx, cm.rd_idx, cm.w_idx, cm.rigid_fid)
        self._nq, self._ny = sys.nq, sys.nq + sys.nv
        self._frames = tuple(wk[k] for k in range(4))   # the kernel's r, A, rd, w (work slots 0-3)
        self._monitor = wk[53][0]   # [0] != 0 while the run keeps the energy account

    def _address(self, fn) -> int:
        cb = _CALLBACK(fn)
        self._callbacks.append(cb)
        return ctypes.cast(cb, ctypes.c_void_p).value

    def _drive(self, t):
        """The driver callback: value, d1, d2 of each Python-callable driver at t [s] into wk[34:37]."""
        return self._guarded(lambda: self._drivers_at(t), self._driver_names, "function", t, self._poison_drivers)

    def _drivers_at(self, t):
        """value, d1, d2 of each driver at t (solvers.pydrive.triple: the user's functions called on the
        float t directly, numerical derivatives from one stencil of f) into wk[34:37]."""
        w0, w1, w2 = self.wk[34], self.wk[35], self.wk[36]
        for d, tri, entity in self.drivers:
            try:
                x = tri(t)
            except (TypeError, ValueError) as exc:
                raise EvaluationError(entity, "function", f"did not return a number ({exc})", time=float(t)) from None
            if not (math.isfinite(x[0]) and math.isfinite(x[1]) and math.isfinite(x[2])):
                raise EvaluationError(entity, "function", f"is not finite ({x!r})", time=float(t))
            w0[d], w1[d], w2[d] = x

    def _poison_drivers(self):
        for d, _, _ in self.drivers:
            for k in range(3):
                self.wk[34 + k][d] = np.nan

    def _guarded(self, work, entity, field, t, poison):
        """0 after work() (the callback's evaluation at t [s]); on any failure 1, with the error kept (a
        user exception named after `entity`.`field`) and the outputs poisoned (poison()). After a Ctrl-C
        inside it every later call fails at once (an interrupted run)."""
        self.calls += 1
        if not self.interrupted:
            try:
                work()
                self.last_failed = False
                return 0
            except KeyboardInterrupt:
                self.interrupted = True
            except MbdsimError as exc:
                self.error = exc
            except Exception as exc:  # noqa: BLE001 - user code: reported with the element's name
                self.error = EvaluationError(entity, field, f"{type(exc).__name__}: {exc}", time=float(t))
        poison()
        self.ctl[1], self.last_failed = 1, True
        return 1

    def state(self, t) -> tuple[State, Frames]:
        """The light State of the kernel's current frames at t [s] and the single-instant Frames the
        evaluators take (the State's own). The absolute [q, v] are rebuilt from the frames (one compiled
        call) on first use when every called-back load is a force or torque (their evaluators read the
        frames only), else at once (the Frames carry them)."""
        f = self._frames
        r, A, rd, w = f[0].copy(), f[1].copy(), f[2].copy(), f[3].copy()

        def maximal():
            y = np.empty(self._ny)
            fasttree.to_maximal(*self._tree, r, A, rd, w, y, y[:0])
            return y[:self._nq], y[self._nq:]
        if self.applied:   # (their evaluators read the frames only)
            fr = Frames(r, A, rd, w, t=t)
            return State(self.sys, t, None, None, fr, maximal), fr
        q, v = maximal()
        fr = Frames(r, A, rd, w, t=t, q=q, v=v)
        state = State(self.sys, t, q, v, fr)
        # joint angles read by the evaluators (torsion springs, stops, expression loads in closed loops):
        # continued beyond +-pi over the run by the State's anchors (results.state._continued)
        fr.angle = lambda jt: np.atleast_1d(state.joint_coordinate(jt))[:1]
        return state, fr

    def signal(self, sensor, t) -> float:
        """The signal of a Python-callable sensor at t [s] and the kernel's current frames; nan when it
        fails (the error kept: the run ends with it)."""
        self.calls += 1
        if self.interrupted or self.sensor_error is not None:
            return math.nan
        try:
            state, _ = self.state(t)
            v = sensor.signal(t, state)
            try:
                x = float(v)
            except TypeError:
                x = float(np.asarray(v, dtype=float).reshape(()))
            if not math.isfinite(x):
                raise EvaluationError(f"sensor '{sensor.name}'", "signal", f"is not finite ({x!r})", time=float(t))
            return x
        except KeyboardInterrupt:
            self.interrupted = True
        except MbdsimError as exc:
            self.sensor_error = exc
        except Exception as exc:  # noqa: BLE001 - user code: reported with the sensor's name
            self.sensor_error = EvaluationError(f"sensor '{sensor.name}'", "signal", f"{type(exc).__name__}: {exc}",
                                                time=float(t))
        return math.nan

    def _call(self, t):
        """The load callback: generalized loads of the called-back elements at t [s] into slot 48[0]."""
        return self._guarded(lambda: self._loads_at(t), self._load_entity, "value", t, self._poison_loads)

    def _poison_loads(self):
        self.F.fill(np.nan)

    def _loads_at(self, t):
        state, fr = self.state(t)
        if self.applied:   # forces and torques only: added into one Q (their values checked finite on return)
            Q = self._Q_in_F
            if Q is None:
                Q = np.zeros(self.sys.nv)
            else:
                Q.fill(0.0)
            on = self._monitor[0] != 0.0   # the run keeps the energy account: their power [W] too
            P = 0.0
            for ev, e in self.evals:
                P += ev.accumulate(self.sys, fr, e, t, state, Q, on)
            if self._Q_in_F is None:
                self.F_flat[self.F_dst] = Q[self.F_src]
            if on:   # for the kernel's account, in the ground row (never applied)
                self.F[0, 0] = P
            return
        first, *rest = self.evals
        Q = first[0].generalized(self.sys, fr, first[1], t, state)
        for ev, e in rest:
            Q = Q + ev.generalized(self.sys, fr, e, t, state)
        if not np.isfinite(Q).all():
            bad = next(e for ev, e in self.evals if not np.all(np.isfinite(ev.generalized(self.sys, fr, e, t, state))))
            raise EvaluationError(f"load '{bad.name}'", "value", "is not finite", time=float(t))
        self.F_flat[self.F_dst] = Q[self.F_src]


def settle(pyl, status, error):
    """(status, error) of a kernel run that ended with `status`: CALLBACK_FAILED with the callable's error
    (or INTERRUPTED for a Ctrl-C inside it) when the run ended on a failed callback (the step loop's
    CALLBACK_FAILED, or another failure status, e.g. the step size collapsing onto the failure, right
    after a failed call)."""
    from .fastdyn import CALLBACK_FAILED, INTERRUPTED
    if pyl is not None and error is None:   # a sensor callback, or a compiled user function, failed
        if pyl.sensor_error is not None:
            return CALLBACK_FAILED, pyl.sensor_error
        from ..userfunctions import failures
        failed = failures(pyl.user_sites, pyl.sys.model)
        if failed is not None:
            return CALLBACK_FAILED, failed
    if pyl is None or status == 0 or error is not None:
        return status, error
    if pyl.interrupted:
        return INTERRUPTED, None
    if (status == CALLBACK_FAILED or pyl.last_failed) and pyl.error is not None:
        return CALLBACK_FAILED, pyl.error
    return status, error


def attach(sys, cm, work) -> PythonLoads | None:
    """The callbacks of the model's Python-callable loads, drivers and sensors set into `work`, with the
    compiled user functions' failure counters reset (None without any)."""
    if cm.python_loads or cm.python_drivers:
        return PythonLoads(sys, cm, work)
    from ..userfunctions import sites
    return PythonLoads(sys, cm, work) if sites(cm) else None
