"""The index-1 stepper: a scipy OdeSolver (DOP853, RK45, Radau, BDF) on y = [q, v] with coordinate
projection, for `solvers.driver.drive`.

The equations of motion are solved for the accelerations at every stage (augmented KKT system); after
every accepted step the positions and velocities are projected back onto phi(q, t) = 0 and
phi_q v = nu (minimum-norm Newton steps), which keeps the drift at the Newton tolerance (~1e-12). At an
event the step is cut at the root on its dense output and the solver restarts there.
"""
from __future__ import annotations

import bisect

import numpy as np

from ..errors import SolverError
from ..results.result import Result
from .autoswitch import OrderTrack
from .common import _weak_joints, accelerations, consistent_state, normalize, project_positions, \
    project_velocities, qdot
from .driver import Step, drive
from .events import EventTracker
from ..results.state import state_factory


class _Trajectory:
    """Accepted steps' dense outputs, for evaluation at any time inside the integrated span."""

    def __init__(self, sys, rows, sf):
        self.sys, self.rows, self.sf = sys, rows, sf
        self.t_end, self.dense = [], []

    def add(self, t_old, t_new, dense):
        self.t_end.append(t_new)
        self.dense.append((t_old, dense))

    def state(self, t):
        k = min(bisect.bisect_left(self.t_end, t), len(self.dense) - 1)
        y = self.dense[k][1](t)
        return consistent_state(self.sys, y, t, self.rows, self.sf)

    def step_states(self):
        """(t, q, v) at the start of every accepted step and at the end (Euler parameters normalised)."""
        ts = [d[0] for d in self.dense] + [self.t_end[-1]]
        ys = [d(t0) for t0, d in self.dense] + [self.dense[-1][1](self.t_end[-1])]
        Y = np.array(ys)
        q = np.array([normalize(self.sys, y[:self.sys.nq]) for y in Y])
        return np.array(ts), q, Y[:, self.sys.nq:]

    def evaluate(self, ts):
        states = [self.state(t) for t in ts]
        return tuple(np.array([s[i] for s in states]) for i in range(4))


class Index1Stepper:
    """scipy OdeSolver `solver_cls` over [t0, t_end] from the assembled state `rep` (rtol, atol, max_step
    as scipy's), one accepted step per `step()`; outputs are (q, v, vd, lambda_) tuples."""

    out_tol = 1e-14

    def __init__(self, sys, rep, t0, t_end, solver_cls, rtol, atol, max_step, sf):
        self.sys, self.rep, self.rows, self.sf = sys, rep, rep.rows, sf
        self.cls, self.t_end = solver_cls, float(t_end)
        self.opts = dict(rtol=rtol, atol=atol, max_step=max_step if max_step else np.inf)
        self.t, self.y = float(t0), np.concatenate([rep.q, rep.v])
        self.traj = _Trajectory(sys, self.rows, sf)
        self.solver = self.track = None
        self.nsteps = self.nsmall = 0

    def rhs(self, t, y):
        """dy/dt = [qdot, vd] at (t, y)."""
        sys = self.sys
        q, v = y[:sys.nq], y[sys.nq:]
        vd, _ = accelerations(sys, normalize(sys, q), v, t, self.rows, self.sf)
        return np.concatenate([qdot(sys, q, v), vd])

    def first(self):
        return consistent_state(self.sys, self.y, self.t, self.rows, self.sf)

    def here(self):
        return consistent_state(self.sys, self.y, self.t, self.rows, self.sf)

    def step(self) -> Step:
        if self.solver is None:
            self.restart()
        solver, sys = self.solver, self.sys
        t_old, order = solver.t, self.track.order(solver)
        msg = solver.step()
        tiny = 1e-10 * max(1.0, abs(solver.t))
        if solver.status == "failed" or (solver.t - t_old < tiny and solver.status == "running"):
            self.nsmall = self.nsmall + 1 if solver.status == "running" else 99
            if self.nsmall > 20:
                y = solver.y
                raise SolverError(f"step size collapsed ({msg or 'steps below 1e-10 s'}): lock-up or "
                                  "singular configuration", time=solver.t,
                                  joints=_weak_joints(sys, y[:sys.nq], y[sys.nq:], solver.t, self.rows),
                                  state=y[:sys.nq])
        else:
            self.nsmall = 0
        self.nsteps += 1
        self.track.step(t_old, order)
        step = Step(t_old, solver.t, solver.y, solver.dense_output(), None)
        self._sampler(step)
        return step

    def to_event(self, step, t_hit, locate=None):
        """Cut the step at the event on its dense output."""
        step.t_new, step.y_new = t_hit, step.dense(t_hit)
        return step, True

    def _sampler(self, step):
        step.sample = lambda t: consistent_state(self.sys, step.dense(t), t, self.rows, self.sf)

    def take(self, step):
        self.traj.add(step.t_old, step.t_new, step.dense)
        sys = self.sys
        q, v = step.y_new[:sys.nq], step.y_new[sys.nq:]
        q, _, _ = project_positions(sys, normalize(sys, q), step.t_new, self.rows)
        v = project_velocities(sys, q, v, step.t_new, self.rows)
        self.t, self.y = step.t_new, np.concatenate([q, v])
        if self.solver.t == step.t_new:   # no event: the solver goes on from the projected state
            self.solver.y = self.y
            if hasattr(self.solver, "f"):
                self.solver.f = self.rhs(self.solver.t, self.y)

    def restart(self):
        """A new solver from (t, y) (the start, or after an event)."""
        if self.t >= self.t_end and self.solver is not None:
            return
        self.solver = self.cls(self.rhs, self.t, self.y, self.t_end, **self.opts)
        if self.track is None:
            self.track = OrderTrack(self.t, self.cls.__name__, self.solver)

    def has_steps(self) -> bool:
        return bool(self.traj.dense)

    def evaluate(self, ts):
        return self.traj.evaluate(ts)

    def step_states(self):
        return self.traj.step_states()

    def stats(self) -> dict:
        track = self.track
        return {"steps": self.nsteps, "method": self.cls.__name__, "assembly": self.rep,
                "order": track.history[-1][2] if track else None, "order_history": track.history if track else []}

    def result(self, times, out, **kw) -> Result:
        return Result(self.sys, times, *[np.array([s[i] for s in out]) for i in range(4)], **kw)


def integrate_index1(sys, rep, times, solver_cls, rtol, atol, max_step, progress=None) -> Result:
    """Dynamic analysis over the output grid `times` [s] with the scipy OdeSolver `solver_cls` (index-1
    form, coordinate projection after every step, events located on the dense output); a Result."""
    sf = state_factory(sys)
    events = EventTracker(sys, rep.rows, sf)
    t0 = float(times[0])
    events.start(t0, np.concatenate([rep.q, rep.v]))   # first: initial modes of switching elements (stick/slip)
    stepper = Index1Stepper(sys, rep, t0, times[-1], solver_cls, rtol, atol, max_step, sf)
    return drive(stepper, sys, rep, times, events, progress)
