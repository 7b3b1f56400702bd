"""The compiled Radau's Jacobian by groups of columns that share no nonzero row (fastradau._column_groups,
_jacobian): valid groups on known sparsity patterns, and on a cable of particles joined by stiff springs (a
banded Jacobian) far fewer evaluations than one per column, with the same motion as DOP853."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers.fastradau import _column_groups


def _check(J, G):
    grp = np.zeros(J.shape[0])
    g = _column_groups(J, grp, np.zeros(J.shape[0]))
    if g:
        assert set(grp.astype(int)) == set(range(g))
        for k in range(g):   # no row has two nonzeros among one group's columns
            assert np.all((J[:, grp == k] != 0).sum(axis=1) <= 1)
    assert g == G, (g, G)


def test_groups_of_a_tridiagonal_a_block_diagonal_and_a_dense_pattern():
    n = 30
    _check(np.eye(n) * 2 + np.eye(n, k=1) + np.eye(n, k=-1), 3)
    _check(np.kron(np.eye(5), np.ones((6, 6))), 6)
    _check(np.ones((n, n)), 0)          # dense: no grouping (every column its own evaluation)
    rng = np.random.default_rng(1)
    S = (rng.random((n, n)) < 0.08) * rng.normal(size=(n, n)) + np.eye(n)
    grp = np.zeros(n)
    g = _column_groups(S, grp, np.zeros(n))
    assert 0 < g < n // 2
    for k in range(g):
        assert np.all((S[:, grp == k] != 0).sum(axis=1) <= 1)


def cable(n=20, k=1e6, c=5.0):
    """n particles of 0.1 kg, 0.1 m apart along x, joined by springs k [N/m] (damping c [N s/m]), the first
    to a ground point at the origin; gravity -z."""
    m = mb.Model("cable", gravity=(0, 0, -9.81))
    prev = (m.ground, (0.0, 0.0, 0.0))
    for i in range(n):
        p = m.add_particle(f"p{i}", 0.1, position=(0.1 * (i + 1), 0, 0))
        m.add_spring_damper(f"s{i}", prev, p, k, c, 0.1)
        prev = p
    return m


@pytest.mark.parametrize("n", [20])
def test_stiff_cable_on_radau_groups_its_jacobian_and_matches_dop853(n):
    m = cable(n)
    res = mb.simulate(m, 0.2, 0.01, method="radau", rtol=1e-8, monitor=False)
    ref = mb.simulate(m, 0.2, 0.01, method="dop853", rtol=1e-10, monitor=False)
    assert res.success and ref.success
    ny = 6 * n
    st = res.stats
    assert st["njev"] >= 2 and st["nfev"] < st["njev"] * ny / 2, st   # a full Jacobian alone costs ny each
    err = np.max(np.abs(res.position(f"p{n - 1}") - ref.position(f"p{n - 1}")))
    assert err < 1e-6, err
