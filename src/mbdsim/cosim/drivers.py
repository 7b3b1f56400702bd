"""The Simulator's side of motion drivers that read model inputs (mbdsim.model.input_drivers).

Each such driver's compiled programs hold the inputs it reads and its anchors (ANCHOR_X, ANCHOR_V) as
constants of the packed driver programs (CompiledModel.driver_slots). When `Simulator.set_input` changes
one of its inputs at time t [s], `DriverConstants.set` moves the anchors so that a velocity driver's
displacement (an acceleration driver's displacement and velocity) is continuous at t, and writes them;
the Simulator writes the inputs themselves and, for displacement and velocity drivers, re-projects the
state onto the constraints at the start of the next step.
"""
from __future__ import annotations

from ..model.input_drivers import ANCHOR_V, ANCHOR_X


class DriverConstants:
    """The constants of one driver reading inputs: `sym` (model.input_drivers.InputDriver), `values`
    {input or anchor name: value now}, `places` {anchor name: [index into consts]}, `consts` (the
    Simulator's own copy of the packed driver constants)."""

    __slots__ = ("sym", "values", "places", "consts")

    def __init__(self, sym, consts, places):
        self.sym, self.consts, self.places = sym, consts, places
        self.values = dict(sym.constants)

    @property
    def reprojects(self) -> bool:
        """True when an input change moves the driven coordinate's value or rate (the state is projected)."""
        return self.sym.kind != "acceleration"

    def set(self, t: float, name: str, value: float) -> None:
        """Input `name` becomes `value` at time t [s]: the anchors moved and written (not the input)."""
        self.values = self.sym.rebase(t, self.values, {name: value})
        self._write_anchors()

    def save(self) -> dict:
        return dict(self.values)

    def load(self, values: dict) -> None:
        """Back to the constants of `save()` (the inputs are written by the Simulator)."""
        self.values = dict(values)
        self._write_anchors()

    def _write_anchors(self):
        for anchor in (ANCHOR_X, ANCHOR_V):
            for k in self.places.get(anchor, ()):
                self.consts[k] = self.values[anchor]


def driver_constants(run, slots) -> dict:
    """{input name: [DriverConstants of the drivers reading it]} of the compiled run `run` (its cm.consts
    the Simulator's own copy); the places of the inputs are appended to `slots` {input: [(array, index)]}."""
    cm = run.cm
    if not cm.driver_slots:
        return {}
    fns = run.sys.derived["packed"][6]
    by_driver = {}
    for d, name, k in cm.driver_slots:
        by_driver.setdefault(d, {}).setdefault(name, []).append(k)
    out = {}
    for d, places in by_driver.items():
        dc = DriverConstants(fns[d].symbolic, cm.consts, places)
        for name in dc.sym.inputs:
            out.setdefault(name, []).append(dc)
            slots[name].extend((cm.consts, k) for k in places.get(name, ()))
    return out
