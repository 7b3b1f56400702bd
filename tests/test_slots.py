"""mbdsim._slots.Slots: the kernels' compiled model and work arrays as one pointer (issue 32).

The buffer is written in Python in numba's in-memory form of the tuple; these tests check it against
numba's own layout (LLVM's size of the tuple type, each slot read back by compiled code) rather than
against our own numbers."""
import pickle

import numpy as np
import pytest
from numba import njit, typeof

import mbdsim as mb
from mbdsim._slots import Slots
from mbdsim.solvers import fastdyn
from mbdsim.solvers.assembly import assemble_state
from mbdsim.system.assemble import assemble_system
from mbdsim.system.compiled import Work, compile_system


def _pendulum_arrays():
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", mass=2.0, inertia=(2.0 / 12, 0.0, 2.0 / 12), position=(0.5, 0, 0))
    m.add_revolute("pin", m.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    sys_ = assemble_system(m)
    rep = assemble_state(sys_, sys_.q0, sys_.v0, 0.0)
    cm = compile_system(sys_, rep.rows)
    return sys_, rep, cm


@njit
def _leaf(s):   # a compiled read of a top-level slot, a nested slot, and a write through one
    a = s[2]
    a[0, 1] = 7.5
    return s[0].sum() + s[1][1].shape[0] + s[1][0][1] + s[3].shape[1]


def test_buffer_matches_numbas_layout_and_compiled_reads():
    from numba.core.registry import cpu_target
    ctx = cpu_target.target_context
    _, _, cm = _pendulum_arrays()
    for s in (cm.arrays(), Work.for_model(cm).arrays()):
        assert s._buf.nbytes == ctx.get_abi_sizeof(ctx.get_value_type(typeof(s._t)))
    x = np.arange(5.0)
    nested = (np.array([3, 4], np.int64), np.zeros((2, 3, 4)))
    m = np.zeros((2, 3))
    s = Slots((x, nested, m, np.zeros((0, 6), np.bool_)))
    assert _leaf(s) == x.sum() + 2 + 4 + 6
    assert m[0, 1] == 7.5                     # the arrays are shared, not copied
    assert len(s) == 4 and s[0] is x and s[1] is nested and s[1:2] == (nested,) and list(s)[2] is m


def test_kernel_through_slots_equals_kernel_on_the_arrays():
    sys_, rep, cm = _pendulum_arrays()
    a = cm.arrays()
    assert a is cm.arrays()                   # made once per model
    v = rep.v + np.linspace(0.3, 1.1, sys_.nv)
    qd1, qd2 = np.zeros(sys_.nq), np.zeros(sys_.nq)
    fastdyn.qdot_into(a, rep.q, v, qd1)
    fastdyn.qdot_kernel(cm.r_idx, cm.p_idx, cm.rd_idx, cm.w_idx, rep.q, v, qd2)
    assert np.array_equal(qd1, qd2) and np.abs(qd1).max() > 0.1


def test_copy_replace_and_bad_slots():
    _, _, cm = _pendulum_arrays()
    a = cm.arrays()
    b = pickle.loads(pickle.dumps(a))
    assert len(b) == len(a) and np.array_equal(b[9], a[9]) and b._addr != a._addr
    dims = a[31].copy()
    c = a.replace(31, dims)
    assert c[31] is dims and c[9] is a[9] and typeof(c) == typeof(a)
    w1, w2 = Work.for_model(cm).arrays(), Work.for_model(cm).arrays()   # typed once per model
    assert typeof(w1) is typeof(w2) and typeof(w2) == typeof(Slots(w2._t)) and w1._addr != w2._addr
    other = Slots((np.zeros(3), np.zeros((2, 2))), typeof(Slots((np.zeros(3), np.zeros(2)))))
    assert typeof(other) == typeof(Slots((np.zeros(3), np.zeros((2, 2)))))   # a type of another size: retyped
    with pytest.raises(TypeError, match="only arrays and tuples of arrays"):
        Slots((np.zeros(2), [1.0]))


def test_slot_type_reused_only_for_the_same_structure():
    """A tuple of the same structure (dtypes, dimensions, layout, writeability) reuses the type typed once;
    any difference that numba's type sees gives numba's own type for it, never the cached one."""
    a = (np.zeros(3), (np.zeros((2, 2)), np.zeros(4, np.int64)))
    b = (np.ones(5), (np.ones((3, 3)), np.arange(2)))   # same structure, other sizes
    assert Slots(a)._numba_type_ is Slots(b)._numba_type_
    ro = np.zeros(3)
    ro.flags.writeable = False
    others = [(ro, a[1]), (np.zeros(3, np.float32), a[1]), (np.zeros((3, 1)), a[1]),
              (np.zeros(6)[::2], a[1]), (np.zeros(3), (np.zeros((2, 2)).T[:, :1], a[1][1]))]
    for t in others:
        assert Slots(t)._numba_type_.tup == typeof(t), t
    assert Slots(others[0])._numba_type_.tup != Slots(a)._numba_type_.tup   # (read-only: numba's own type)
