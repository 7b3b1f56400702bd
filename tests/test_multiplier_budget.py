"""Minimum-norm multipliers of redundant rows (reactions of a closed loop of revolutes) within a memory
budget: samples in chunks give the same reactions, and a model whose single sample exceeds the budget gets
a clear error naming the redundant rows' joints instead of a MemoryError (issue 35)."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers import compiled_run


def _four_bar():
    """The warm-up's planar crank-rocker of four revolutes (3 redundant rows in 3D), undriven."""
    from mbdsim._warmup import _four_bar as four_bar
    return four_bar(False)


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
