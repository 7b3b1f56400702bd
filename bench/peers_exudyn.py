"""Exudyn builds of bench/peers_vocabulary.py's three models, for that script (same parameters, same
closed forms, outputs every OUT_DT on the same grid).

All three are 1-D coordinate models (no rigid bodies): each shaft or mass is a ``Node1D`` (one ODE2
coordinate, its initial value and rate) carrying an ``ObjectMass1D`` whose ``physicsMass`` is the mass
[kg] or the shaft inertia [kg m^2]; coordinates are read with ``MarkerNodeCoordinate``, ground is a
``NodePointGround`` coordinate.

* gear train: two ``ObjectConnectorCoordinate`` (markers [q_out, q_in], ``factor1`` = the gear ratio:
  factor1 q_in - q_out = 0) and an ``ObjectConnectorCoordinateSpringDamper`` (stiffness k) from ground
  to the output shaft.
* stiff chain: two ``ObjectConnectorCoordinateSpringDamper`` (ground-m1, k1; m1-m2, k2) on the
  displacements from the free lengths.
* friction slider: ``ObjectConnectorCoordinateSpringDamperExt`` (Exudyn 1.13 has no dry friction on
  the plain CoordinateSpringDamper) with stiffness 0, dynamicFrictionForce = mu m g and
  frictionProportionalZone = FRICTION_VREG (its regularised Coulomb law, linear for |v| < v_reg).

Solvers: ``mbs.SolveDynamic`` at a fixed step: GeneralizedAlpha (spectral radius 1: the trapezoidal
rule, Exudyn's most accurate implicit setting; 0.9 is its default) and the explicit RK44.  Only the
SolveDynamic call is timed, best of ``repeat`` fresh builds.  Exudyn's adaptive step reduction stays
on (its default): without it GeneralizedAlpha's Newton iteration fails where the slider stops for steps
>= 1e-3 s; with it, the slider's samples after the stop fall off the 0.01 s grid and are compared with
the closed form at their own times.  RK44 refuses the gear train (an explicit Exudyn solver accepts
only coordinate constraints to ground).
"""
from __future__ import annotations

import math
import time

import numpy as np

try:
    import exudyn as exu
    import exudyn.itemInterface as ii
    EXUDYN = exu.__version__
except Exception as exc:  # pragma: no cover
    exu, EXUDYN = None, f"not importable: {exc}"

FRICTION_VREG = 1e-4   # m/s: regularisation zone of the friction law (extra travel ~ m v_reg^2 / F ~ 3e-9 m)
SOLVERS = {"GA rho=1": ("GeneralizedAlpha", 1.0), "RK44": ("RK44", None)}


def _coord(mbs, node):
    return mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=node, coordinate=0))


def _mass(mbs, m, q0, v0):
    node = mbs.AddNode(ii.Node1D(referenceCoordinates=[0.0], initialCoordinates=[q0], initialVelocities=[v0]))
    mbs.AddObject(ii.ObjectMass1D(physicsMass=m, nodeNumber=node))
    return node, _coord(mbs, node)


def _ground(mbs):
    return _coord(mbs, mbs.AddNode(ii.NodePointGround()))


def gear_exudyn(mbs, p):
    """Shaft angles [rad]: rates (w0/(r1 r2), w0/r2, w0) as the mbdsim model; reads the output shaft."""
    J, r1, r2, w0 = p["J"], p["r1"], p["r2"], p["w0"]
    rates = (w0 / (r1 * r2), w0 / r2, w0)
    nodes, marks = zip(*[_mass(mbs, J[k], 0.0, rates[k]) for k in range(3)])
    mbs.AddObject(ii.ObjectConnectorCoordinate(markerNumbers=[marks[1], marks[0]], factor1=r1))
    mbs.AddObject(ii.ObjectConnectorCoordinate(markerNumbers=[marks[2], marks[1]], factor1=r2))
    mbs.AddObject(ii.ObjectConnectorCoordinateSpringDamper(markerNumbers=[_ground(mbs), marks[2]],
                                                           stiffness=p["k"]))
    return [nodes[2]], lambda q: q[:, 0]


def chain_exudyn(mbs, p, x0):
    """Displacements [m] from the free lengths, started at x0 (the slow mode's shape) at rest."""
    (n1, m1), (n2, m2) = _mass(mbs, p["m"][0], x0[0], 0.0), _mass(mbs, p["m"][1], x0[1], 0.0)
    mbs.AddObject(ii.ObjectConnectorCoordinateSpringDamper(markerNumbers=[_ground(mbs), m1], stiffness=p["k1"]))
    mbs.AddObject(ii.ObjectConnectorCoordinateSpringDamper(markerNumbers=[m1, m2], stiffness=p["k2"]))
    return [n1, n2], lambda q: q


def fric_exudyn(mbs, p, g):
    """Block position [m] from the start, launched at v0 against the friction force mu m g."""
    n, mk = _mass(mbs, p["m"], 0.0, p["v0"])
    mbs.AddObject(ii.ObjectConnectorCoordinateSpringDamperExt(
        markerNumbers=[_ground(mbs), mk], stiffness=0.0, dynamicFrictionForce=p["mu"] * p["m"] * g,
        frictionProportionalZone=FRICTION_VREG))
    return [n], lambda q: q[:, 0]


def run_exudyn(build, T, dt, out_dt, solver, repeat=3):
    """(best solve time [s], output times [s], outputs) for a fixed step dt [s] with SOLVERS[solver];
    (time or nan, None, message) when the solver refuses the model or fails."""
    kind, rho = SOLVERS[solver]
    n_out = int(round(T / out_dt))
    best, out = math.inf, None
    for _ in range(repeat):
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        nodes, read = build(mbs)
        sens = [mbs.AddSensor(ii.SensorNode(nodeNumber=n, storeInternal=True,
                                            outputVariableType=exu.OutputVariableType.Coordinates))
                for n in nodes]
        mbs.Assemble()
        s = exu.SimulationSettings()
        ti = s.timeIntegration
        ti.numberOfSteps, ti.endTime, ti.verboseMode = int(round(T / dt)), T, 0
        if rho is not None:
            ti.generalizedAlpha.spectralRadius = rho
        s.solution.file.write = False
        s.solution.sensors.writePeriod = out_dt
        s.displayComputationTime = s.displayStatistics = False
        exu.SetWriteToConsole(False)   # Exudyn's console banner on a refused model (for this process)
        t0 = time.perf_counter()
        try:
            ok = mbs.SolveDynamic(s, solverType=getattr(exu.DynamicSolverType, kind))
        except Exception as exc:   # noqa: BLE001  (e.g. RK44 refuses constraints between two nodes)
            return math.nan, None, f"{type(exc).__name__}: {str(exc).split(';')[0]}"
        best = min(best, time.perf_counter() - t0)
        if ok is False:
            return best, None, "SolveDynamic failed"
        out = [mbs.GetSensorStoredData(x) for x in sens]
    t = out[0][:, 0]
    q = np.stack([d[:, 1] for d in out], 1)
    grid = np.linspace(0, T, n_out + 1)
    idx = [int(np.argmin(np.abs(t - g))) for g in grid]
    if len(t) == n_out + 1 and np.max(np.abs(t[idx] - grid)) <= 1e-9:
        return best, grid, read(q[idx])
    # Exudyn's adaptive step (Newton not converging at the friction slider's stop) shifts the sensor
    # samples off the grid: they are kept, at their own times, and compared with the closed form there.
    return best, t, read(q)
