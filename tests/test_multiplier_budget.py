"""Minimum-norm multipliers of redundant rows (reactions of a closed loop of revolutes) within a memory
budget: samples in chunks give the same reactions, and a model whose single sample exceeds the budget gets
a clear error naming the redundant rows' joints instead of a MemoryError (issue 35)."""
import math

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers import compiled_run


def _four_bar():
    from scipy.spatial.transform import Rotation
    z = lambda a: Rotation.from_rotvec((0.0, 0.0, a))  # noqa: E731
    m = mb.Model("four_bar", gravity=(0, -9.81, 0))
    crank = m.add_body("crank", 0.5, inertia=(1e-4, 5e-4, 5e-4), position=(0.0, 0.05, 0.0), orientation=z(math.pi / 2))
    coupler = m.add_body("coupler", 1.0, inertia=(1e-4, 0.015, 0.015), position=(0.15, 0.25, 0.0),
                         orientation=z(math.pi / 4))
    rocker = m.add_body("rocker", 0.8, inertia=(1e-4, 0.0113, 0.0113), position=(0.35, 0.2, 0.0),
                        orientation=z(math.atan2(-0.4, 0.1)))
    m.add_revolute("O2", m.ground, crank, point=(0, 0, 0), axis=(0, 0, 1))
    m.add_revolute("A", crank, coupler, point=(0, 0.1, 0), axis=(0, 0, 1))
    m.add_revolute("B", coupler, rocker, point=(0.3, 0.4, 0), axis=(0, 0, 1))
    m.add_revolute("O4", rocker, m.ground, point=(0.4, 0, 0), axis=(0, 0, 1))
    return m


def test_chunked_multipliers_equal_whole(monkeypatch):
    with pytest.warns(mb.IndeterminateReactionWarning):
        whole = np.asarray(mb.simulate(_four_bar(), 0.2, 0.01).reaction_force("A", frame=None))
    m = _four_bar()
    res = mb.simulate(m, 0.2, 0.01)
    nc, nv = res.system.nc, res.system.nv
    monkeypatch.setattr(compiled_run, "MULTIPLIER_BYTES", 3 * 8 * nc * nv)   # three samples a chunk
    with pytest.warns(mb.IndeterminateReactionWarning):
        chunked = np.asarray(mb.simulate(_four_bar(), 0.2, 0.01).reaction_force("A", frame=None))
    assert chunked.shape == whole.shape == (21, 3)
    assert np.max(np.abs(chunked - whole)) <= 1e-12 * np.max(np.abs(whole))


def test_single_sample_over_budget_is_a_clear_error(monkeypatch):
    monkeypatch.setattr(compiled_run, "MULTIPLIER_BYTES", 64)
    res = mb.simulate(_four_bar(), 0.1, 0.01)
    with pytest.raises(mb.MbdsimError, match=r"redundant constraint rows .*(O2|A|B|O4).*GB"):
        res.reaction_force("A")
    assert np.all(np.isfinite(np.asarray(res.position("coupler"))))   # the motion is not affected
