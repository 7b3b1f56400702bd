"""The references of the joint angles that loads and sensors read from the frames in absolute
coordinates (closed loops, issue 29), for evaluations after a compiled run.

The kernels continue such an angle to within pi of its reference (work slot 44[7]; the step loops move it to
every accepted state: system.exprloads_kernel.accept_angles). Outputs, dense output and re-integrations
evaluate the loads again at other states; `angle_refs` gives each of those its reference from the run's
own steps (the angles at the step starts, continued over the steps from the start's references), or
without kept steps from the rows themselves; `kept` restores the run's references afterwards.
"""
from __future__ import annotations

import contextlib

import numpy as np

from . import fastdyn


def angle_columns(run):
    """The measures of cm.exprloads that are joint angles read from the frames (absolute coordinates),
    as a boolean mask (None when there are none)."""
    ex = run.cm.exprloads
    if run.joint_space or not len(ex) or not len(ex[0]):
        return None
    sel = (ex[0] == 20) & (ex[5] < 0)
    return sel if sel.any() else None


def angle_refs(run, times, Y, steps=False):
    """Absolute coordinates: the references [rad] of the joint angles that loads and sensors read from
    the frames (one column per measure of cm.exprloads; the kernels continue each angle to within pi of
    its reference) at the output rows Y (at `times` [s]), or with `steps` at the run's accepted steps:
    the angles at the run's step starts (checkpoints) continued from the start's references
    (`angle_ref0`), each row taking that of the last step before it; without checkpoints the rows'
    own angles continued from row to row, anchored at the run's current references (the last accepted
    state, just after the last row). None when the model has no such angle."""
    sel = angle_columns(run)
    if sel is None:
        return None
    a, w = run.cm.arrays(), run.work.arrays()
    cp = getattr(run, "checkpoints", None)
    ref0 = getattr(run, "angle_ref0", np.zeros(len(sel)))

    def wrapped(rows):
        out = np.zeros((len(rows), len(sel)))
        fastdyn.angle_rows(a, w, np.ascontiguousarray(rows, dtype=float), out)
        return out
    if cp is not None and len(cp[1]):
        SY, ST = cp
        C = np.unwrap(np.vstack([ref0, wrapped(SY)]), axis=0)[1:]
        if steps:
            return np.where(sel, C, 0.0)
        k = np.clip(np.searchsorted(ST[:, 0], np.asarray(times, float), side="right") - 1, 0, len(ST) - 1)
        return np.where(sel, C[k], 0.0)
    if not len(Y):
        return np.zeros((0, len(sel)))
    back = np.unwrap(np.vstack([w[44][7], wrapped(Y)[::-1]]), axis=0)[1:]
    return np.where(sel, back[::-1], 0.0)


@contextlib.contextmanager
def kept(ref):
    """Restore the joint-angle references `ref` (work slot 44[7]) after evaluations at other states
    (outputs, dense output, re-integration), so that a run continued later goes on from its own."""
    saved = ref.copy()
    try:
        yield
    finally:
        ref[:] = saved
