"""Python side of the compiled HHT-alpha (mbdsim.solvers.fasthht): method "hht" on a model the compiled
kernels carry.

`HHTRun` is a `RadauRun` (the same compiled model, work arrays, outputs, failure reports, checkpoints and
dense output between outputs: each accepted step's start state, (t, h) and the coefficients of its cubic
Hermite polynomial, in the form `fastradau.dense` evaluates) whose step loop is `fasthht.run`. Sensors are
watched on the steps' Hermite polynomials (solvers.fastswitch), as on Radau; contacts and stops are
integrated through. Joint friction with stick/slip runs here: the step loop stops at
each switching event located on the step's polynomial (solvers.fastswitch) and the run restarts there with
the modes decided by `friction_run.FrictionModes` (as on DOP853 and Radau).
"""
from __future__ import annotations

import numpy as np

from . import fasthht
from .compiled_run import CHUNK
from .radau_run import RadauRun, _integrate, _switching_check

METHOD = "HHT (compiled)"


def coefficients(alpha: float) -> np.ndarray:
    """(alpha, beta, gamma) of HHT-alpha: beta = (1 - alpha)^2 / 4, gamma = 1/2 - alpha."""
    return np.array([alpha, (1.0 - alpha) ** 2 / 4.0, 0.5 - alpha])


class HHTRun(RadauRun):
    """A compiled model stepped by the compiled HHT-alpha (fasthht.run); stats: steps, rejected, rhs
    evaluations, projections, tangents (K, C by differences), LU factorisations."""

    METHOD, HISTORY, ORDER, N_ST = METHOD, ("HHT", 2), 2, fasthht.N_ST
    LU_PER_FACTORISATION = 1
    alpha = -0.05

    def _scratch(self, n):
        nv = n - (n // 2 if self.joint_space else self.sys.nq)
        nf = int(self.cm.dims[3])
        return (np.zeros((nv, 2 * nv)), np.zeros((nv, nv)), np.zeros(nv, dtype=np.int64),
                np.zeros((fasthht.N_SCRATCH, n)), np.zeros((nf, 6)))

    def _step_loop(self, a, w, st, y, f, tout, iout, Y, scratch, SY, ST, SQ, ns, start_row):
        return fasthht.run(a, w, coefficients(self.alpha), st, y, f, float(tout[-1]), tout, iout, Y, self.rtol,
                           self.atol, self.max_step, self.max_steps, CHUNK, 1e-12, self.stats, *scratch, SY, ST,
                           SQ, ns, start_row)


def integrate_hht_compiled(sys, rep, times, rtol, atol, max_step, alpha, progress=None):
    """Dynamic analysis with the compiled HHT-alpha (method "hht"); NotCompiled when the model needs the
    reference path. Sensors and joint friction's stick/slip events are located on the steps' Hermite
    polynomials (solvers.fastswitch)."""
    _switching_check(sys)
    run = HHTRun(sys, rep.rows, rtol, atol, max_step, state=(rep.q, rep.v), friction=len(sys.lock_rows) > 0)
    run.alpha = float(alpha)
    return _integrate(sys, rep, run, times, progress)
