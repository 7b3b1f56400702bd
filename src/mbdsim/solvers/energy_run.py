"""Python side of the compiled energy bookkeeping (issue 29): which runs keep it, and what they hand over.

A compiled DOP853 run of `simulate(monitor=True)` (System.track_energy, set by simulate) accumulates the
dissipated energy D and the applied loads' work W [J] inside its step loop (solvers.fastenergy,
solvers.fastdopstep) when the compiled kernels evaluate every element that dissipates or does work (`coverage`:
not a Python callable or an element called back through its Python evaluator). The Result then carries
them at its output times (`attach`: Result.energy, stats["energy"] = "compiled"), and
`Result.dissipated_energy` and the run monitors read them instead of the post-run quadrature
(results/energy.py, which stays the independent reference: `dissipated_energy_reference`).
"""
from __future__ import annotations

import numpy as np

from ..model.contacts import ShapeContact
from ..model.element_specs import Bushing, Contact, Stop, TorsionSpring
from ..model.forces import Force, SpringDamper, Torque
from ..model.friction_path import JointFriction

# the element types whose dissipation power the compiled loads evaluate (solvers.fastenergy)
DISSIPATIVE = (SpringDamper, Bushing, Contact, ShapeContact, TorsionSpring, Stop, JointFriction)


def coverage(sys, cm) -> tuple[bool, bool]:
    """(D, W): whether the compiled loads of CompiledModel `cm` evaluate the dissipation power of every
    element of `sys` that has one, and the power of every applied force and torque."""
    from ..system.force_elements import evaluator
    from .pyloads import all_applied
    called = set(cm.python_loads)
    applied = all_applied([sys.model.forces[n] for n in called])   # the kernel sums the callback's power then
    d_ok = w_ok = True
    for e in sys.model.forces.values():
        if isinstance(e, (Force, Torque)):
            w_ok = w_ok and (e.name not in called or applied)
        elif hasattr(evaluator(e), "dissipation"):
            d_ok = d_ok and type(e) in DISSIPATIVE and e.name not in called
    return d_ok, w_ok


def wanted(sys, cm) -> bool:
    """Whether a compiled run of `sys` keeps the energy bookkeeping: its monitor checks the energy balance
    (sys.track_energy) and the kernels evaluate all of D or all of W for a model that has them."""
    if not getattr(sys, "track_energy", False) or sys.model.motions:
        return False
    from ..results.diagnostics import _can_dissipate
    d_ok, w_ok = coverage(sys, cm)
    forces = sys.model.forces.values()
    return (d_ok and any(_can_dissipate(e) for e in forces)) or \
        (w_ok and any(isinstance(e, (Force, Torque)) for e in forces))


def take(run, n) -> None:
    """After run.integrate: the bookkeeping's values at the first n outputs (D, W) and at the state the run
    ended in (run.energy, or None when the run did not keep it); switches it off in the work arrays (the
    re-integrations of Result.at share them)."""
    en = run.work.arrays()[53]
    run.energy = None
    if en[0][0] == 0.0:
        return
    en[0][0] = 0.0
    d_ok, w_ok = coverage(run.sys, run.cm)
    d_ok = d_ok and not en[1][0]   # (shape-contact points beyond the record buffer: D incomplete)
    run.energy = {"D": en[8][:n, 0].copy() if d_ok else None, "W": en[8][:n, 1].copy() if w_ok else None,
                  "end": en[4].copy()}


def attach(res, run, extra=False) -> None:
    """Result.energy of a compiled run (dict D, W: arrays at res.time [J], None where not evaluated); with
    `extra` the last sample is the run's end state (a sensor's stop) and gets the value there."""
    if getattr(run, "energy", None) is None:
        return
    out = {}
    for c, k in enumerate(("D", "W")):
        v = run.energy[k]
        if v is not None and extra:
            v = np.append(v[:len(res.time) - 1], run.energy["end"][c])
        out[k] = v if v is not None and len(v) == len(res.time) else None
    if out["D"] is None and out["W"] is None:
        return
    res.energy = out
    res.stats["energy"] = "compiled"
