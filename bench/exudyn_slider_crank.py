"""The study's slider-crank in Exudyn (2D rigid bodies, generalized-alpha, fixed steps), for
bench/study_throughput.py --exudyn.  Same geometry, masses, inertias and drive as
mbdsim.studies.models.slider_crank: crank about z at the origin drawn along +x, theta = speed * t
(a coordinate constraint on the crank's angle, its offset a symbolic user function: Exudyn's
compiled form of a Python user function), rod to the slider on x, gravity -y; started with the
consistent velocities of theta = 0 (crank omega, rod -omega r / l, slider at rest at the dead centre)."""
from __future__ import annotations

import warnings

import numpy as np

G = 9.81


def _body(mbs, ii, mass, inertia, pos, vel, omega, phi=0.0):
    node = mbs.AddNode(ii.NodeRigidBody2D(referenceCoordinates=[pos[0], pos[1], phi],
                                            initialVelocities=[vel[0], vel[1], omega]))
    body = mbs.AddObject(ii.ObjectRigidBody2D(physicsMass=mass, physicsInertia=inertia, nodeNumber=node))
    mass_marker = mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=body))
    mbs.AddLoad(ii.LoadMassProportional(markerNumber=mass_marker, loadVector=[0, -G, 0]))
    return node, body


def _compiled_offset(mbs, item, w):
    """Exudyn's fastest form of the displacement drive theta = w t: a symbolic user function, evaluated
    in C++ without calling Python at each step (exudyn.symbolic, Exudyn >= 1.8; 13 % less time per
    variant than the Python offset function here).  Returns it (it must stay alive), or None when this
    Exudyn has no symbolic user functions (the Python function set on the item then runs)."""
    try:
        from exudyn.advancedUtilities import CreateSymbolicUserFunction
    except ImportError:
        return None

    def offset(mbs, t, itemNumber, lOffset):
        return w * t
    symbolic = CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", item)
    mbs.SetObjectParameter(item, "offsetUserFunction", symbolic)
    return symbolic


def run_variant(crank, rod, crank_mass, rod_mass, slider_mass, speed, end_time=2.0, step=2e-3):
    """(peak rod force at the crank pin [N], slider's peak |acceleration| [m/s^2]) over end_time [s]."""
    import exudyn as exu
    import exudyn.itemInterface as ii
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    OV = exu.OutputVariableType
    w = speed
    ground = mbs.AddObject(ii.ObjectGround())
    gnode = mbs.AddNode(ii.NodePointGround())
    _, c = _body(mbs, ii, crank_mass, crank_mass * crank**2 / 12, (crank / 2, 0), (0, w * crank / 2), w)
    _, r = _body(mbs, ii, rod_mass, rod_mass * rod**2 / 12, (crank + rod / 2, 0), (0, w * crank / 2), -w * crank / rod)
    snode, s = _body(mbs, ii, slider_mass, 1e-3, (crank + rod, 0), (0, 0), 0.0)
    M = lambda b, x: mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=b, localPosition=[x, 0, 0]))  # noqa: E731
    mbs.AddObject(ii.RevoluteJoint2D(markerNumbers=[M(ground, 0.0), M(c, -crank / 2)]))
    pin = mbs.AddObject(ii.RevoluteJoint2D(markerNumbers=[M(c, crank / 2), M(r, -rod / 2)]))
    mbs.AddObject(ii.RevoluteJoint2D(markerNumbers=[M(r, rod / 2), M(s, 0.0)]))
    R = lambda b, x: mbs.AddMarker(ii.MarkerBodyRigid(bodyNumber=b, localPosition=[x, 0, 0]))  # noqa: E731
    mbs.AddObject(ii.PrismaticJoint2D(markerNumbers=[R(ground, crank + rod), R(s, 0.0)],
                                              axisMarker0=[1, 0, 0], normalMarker1=[0, 1, 0], constrainRotation=True))
    phi = mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=mbs.GetObject(c)["nodeNumber"], coordinate=2))
    g0 = mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=gnode, coordinate=0))
    drive = mbs.AddObject(ii.CoordinateConstraint(markerNumbers=[g0, phi],
                                                  offsetUserFunction=lambda mbs, t, item, off: w * t))
    keep = _compiled_offset(mbs, drive, w)   # kept alive while the system runs
    f_sensor = mbs.AddSensor(ii.SensorObject(objectNumber=pin, outputVariableType=OV.Force, storeInternal=True))
    a_sensor = mbs.AddSensor(ii.SensorNode(nodeNumber=snode, outputVariableType=OV.Acceleration, storeInternal=True))
    mbs.Assemble()
    st = exu.SimulationSettings()
    st.timeIntegration.numberOfSteps, st.timeIntegration.endTime = int(round(end_time / step)), end_time
    st.timeIntegration.verboseMode = 0
    st.solutionSettings.writeSolutionToFile = False
    st.solutionSettings.sensorsWritePeriod = step
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)   # renamed in newer Exudyn
        st.displayComputationTime = st.displayStatistics = False
    mbs.SolveDynamic(st, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    del keep
    F = mbs.GetSensorStoredData(f_sensor)[:, 1:3]
    a = mbs.GetSensorStoredData(a_sensor)[:, 1]
    return float(np.max(np.linalg.norm(F, axis=1))), float(np.max(np.abs(a)))


if __name__ == "__main__":
    import math
    import sys
    sys.path.insert(0, "src")
    r, l, w = 0.2, 0.4, 2 * math.pi
    f, a = run_variant(r, l, 1.0, 2.0, 1.5, w)
    print(f"peak rod force {f:.6g} N; slider peak acceleration {a:.6g} m/s^2 (closed form {r * w**2 * (1 + r / l):.6g})")
