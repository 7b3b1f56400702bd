"""An unchanged Model is assembled and compiled once; any change to it (a field set, an array edited in
place, an entity added) is seen and the next analysis assembles anew, giving the results of a freshly
built model with the same data."""
from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.system.assemble import assemble_system
from mbdsim.system.fingerprint import model_fingerprint


def _double_pendulum(m2=1.0, axis=(0.0, 0.0, 1.0)):
    m = mb.Model("dp", gravity=(0.0, -9.81, 0.0))
    a = m.add_body("a", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0.0, 0.0))
    b = m.add_body("b", m2, inertia=(0.01, 0.01, 0.01), position=(1.5, 0.0, 0.0))
    m.add_revolute("j1", m.ground, a, (0, 0, 0), axis)
    m.add_revolute("j2", a, b, (1.0, 0, 0), (0, 0, 1))
    return m


def _run(m):
    return mb.simulate(m, 0.5, 0.05, rtol=1e-9)


def test_unchanged_model_reuses_its_system_with_fresh_run_state():
    m = _double_pendulum()
    s1, s2 = assemble_system(m), assemble_system(m)
    assert s1 is not s2 and s1.derived is s2.derived and s1.M is s2.M
    s1.run_state["x"] = 1
    assert s2.run_state == {}
    r1, r2 = _run(m), _run(m)
    assert np.array_equal(r1.q, r2.q) and np.array_equal(r1.v, r2.v)


def test_changes_are_seen():
    m = _double_pendulum()
    base = _run(m).position("b")[-1]
    m.bodies["b"].mass = 3.0                        # a field set after a run
    heavy = _run(m).position("b")[-1]
    assert np.array_equal(heavy, _run(_double_pendulum(m2=3.0)).position("b")[-1])
    assert not np.allclose(heavy, base)
    m.bodies["b"].mass = 1.0
    assert np.array_equal(_run(m).position("b")[-1], base)
    fp = model_fingerprint(m)
    m.joints["j1"].axis[:] = np.array([0.0, 0.6, 0.8])   # an array edited in place
    assert model_fingerprint(m) != fp
    m.add_body("c", 1.0, inertia=(0.01, 0.01, 0.01), position=(3.0, 0.0, 0.0))
    assert assemble_system(m).nbody == 3


def test_pickle_and_copy_leave_the_cache_behind():
    m = _double_pendulum()
    _run(m)
    assert "_assembled" in m.__dict__
    for other in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m)):
        assert "_assembled" not in other.__dict__
        assert np.array_equal(_run(other).q, _run(m).q)


def test_assembly_kept_only_without_python_callables():
    m = _double_pendulum()
    m.add_motion("drive", "j1", displacement="0.3*t")
    _run(m)
    sys = assemble_system(m)
    assert sys.derived["calls_python"] is False and "assembly" in sys.derived
    level = [0.0]
    m2 = _double_pendulum()
    m2.add_motion("drive", "j1", displacement=lambda t: level[0] + 0.3 * t)
    first = float(np.ravel(_run(m2).joint_coordinate("j1"))[0])
    level[0] = 0.2                      # the same callable now gives other values: assembled anew
    second = float(np.ravel(_run(m2).joint_coordinate("j1"))[0])
    assert assemble_system(m2).derived["calls_python"] is True
    assert abs(first) < 1e-9 and abs(second - 0.2) < 1e-9


def test_fingerprint_is_deterministic_and_sees_deep_changes():
    """The same content gives the same digest whatever else was allocated in between; a change deep in
    an entity (a marker of a body) gives another."""
    m = _double_pendulum()
    first = model_fingerprint(m)
    junk = [dict(a=k) for k in range(1000)]   # allocations between two walks
    assert model_fingerprint(m) == first and model_fingerprint(_double_pendulum()) == first
    del junk
    m.bodies["b"].add_marker("tip", point=(2.0, 0.0, 0.0))
    assert model_fingerprint(m) != first


def test_fingerprint_tells_arrays_apart_by_dtype_shape_and_bytes():
    """Arrays with the same bytes but another dtype or shape, or another byte order, give other digests
    (the dtype names are cached per dtype)."""
    from mbdsim.system.fingerprint import fingerprint
    arrays = [np.zeros(1, np.int64), np.zeros(1, np.float64), np.zeros(2, np.float32), np.zeros((1, 2), np.float32),
              np.zeros(1, ">f8"), np.array([1.0]), np.array([1.0], ">f8")]
    digests = [fingerprint({"x": a})[0] for a in arrays]
    assert len(set(digests)) == len(arrays)
    assert [fingerprint({"x": a.copy()})[0] for a in arrays] == digests   # the same again (cache hits)


def test_energies_from_the_state_equal_the_frame_forms():
    """Kinetic and gravity energies straight from (q, v) against the ground-axes forms through the body
    frames (0.5 m |v_cm|^2 + 0.5 w . (A J A^T) w, -m g . r_cm), on a model with rigid bodies and a
    particle, at random states."""
    from mbdsim.system import measures as ms
    from mbdsim.system.frames import body_frames
    m = _double_pendulum()
    m.add_particle("p", 0.7, position=(0.3, -0.4, 0.2), velocity=(0.1, 0.2, -0.3))
    sys = assemble_system(m)
    rng = np.random.default_rng(11)
    q = np.tile(sys.q0, (4, 1)) + 0.1 * rng.standard_normal((4, sys.nq))
    for p in sys.p_idx:
        q[:, p] /= np.linalg.norm(q[:, p], axis=1, keepdims=True)
    v = rng.standard_normal((4, sys.nv))
    fr = body_frames(sys, q, v)
    g = np.asarray(m.gravity, dtype=float)
    for n in range(4):
        T = V = 0.0
        for f in range(1, sys.nbody + 1):
            A = fr.A[n, f]
            T += 0.5 * sys.mass[f] * fr.rd[n, f] @ fr.rd[n, f] + 0.5 * fr.w[n, f] @ (A @ sys.inertia_B[f] @ A.T) @ fr.w[n, f]
            V -= sys.mass[f] * g @ fr.r[n, f]
        assert ms.kinetic_energy(sys, v)[n] == pytest.approx(T, rel=1e-13) and T > 0
        assert ms.gravity_potential(sys, q)[n] == pytest.approx(V, rel=1e-13, abs=1e-15)


def test_user_callable_objects_are_flagged_expression_functions_are_not():
    class Ramp:
        def __init__(self, rate):
            self.rate = rate

        def __call__(self, t):
            return self.rate * t
    m = _double_pendulum()
    m.add_motion("drive", "j1", displacement="0.3*t")
    assert assemble_system(m).derived["calls_python"] is False
    m2 = _double_pendulum()
    m2.add_motion("drive", "j1", displacement=Ramp(0.3))
    assert assemble_system(m2).derived["calls_python"] is True


def test_single_use_assembles_afresh_and_keeps_nothing():
    """Inside assembly.single_use (the study runs) a Model's System is neither looked up nor kept; the
    analysis is the same as a kept one's."""
    from mbdsim.system.assemble import single_use
    m = _double_pendulum()
    with single_use():
        s1, s2 = assemble_system(m), assemble_system(m)
        res = _run(m)
    assert "_assembled" not in m.__dict__ and s1.derived is not s2.derived
    assert s1.derived["calls_python"]        # nothing computed from the model's callables is cached
    ref = _run(m)
    assert "_assembled" in m.__dict__
    assert np.array_equal(res.q, ref.q)
