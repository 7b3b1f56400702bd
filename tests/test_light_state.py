"""The light State handed to load callables (results.state.State): its direct measures of bodies and markers
(read from the instant's frames) against the one-sample Result path of the same State and against closed
forms at t = 0; a callable force at an offset point against the same force as an expression."""
import numpy as np
from scipy.spatial.transform import Rotation

import mbdsim as mb

G = 9.81


def _top(load):
    """A body on a spherical joint at the origin, CM at (0.1, 0.2, 0.6), spinning and precessing, with a
    marker off the CM in rotated axes; `load(model, body, marker)` adds the load under test."""
    m = mb.Model("top", gravity=(0.0, 0.0, -G))
    R0 = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    b = m.add_body("b", 1.5, inertia=(0.04, 0.05, 0.02), position=(0.1, 0.2, 0.6), orientation=R0,
                   angular_velocity=(0.4, -1.1, 7.0))
    m.add_spherical("ball", m.ground, b, (0, 0, 0))
    mk = b.add_marker("tip", point=(0.25, -0.1, 0.7), orientation=Rotation.from_rotvec([0.0, 0.4, -0.9]).as_matrix())
    load(m, b, mk)
    return m, b, mk


def test_direct_measures_match_the_result_path_of_the_same_state_and_the_initial_state():
    seen = []

    def add(m, b, mk):
        def torque(t, s):
            ground = m.ground
            seen.append((t,
                         s.position(mk) - s.position(mk, frame=ground),
                         s.velocity(mk) - s.velocity(mk, relative_to=ground),
                         s.velocity(b) - s.velocity(b, relative_to=ground),
                         s.angular_velocity(b) - s.angular_velocity(b, relative_to=ground),
                         s.orientation(mk) - s.rotation(mk).as_matrix(),
                         s.position("b.tip"), s.velocity("b.tip"), s.angular_velocity(mk)))
            return (0.0, 0.0, -0.01 * s.angular_velocity(b)[2])
        m.add_torque("drag", b, torque)

    m, b, mk = _top(add)
    res = mb.simulate(m, 0.3, 0.01)
    assert res.success and "compiled" in res.stats["method"], res.stats["method"]
    assert len(seen) > 50
    worst = max(float(np.max(np.abs(d))) for row in seen for d in row[1:6])
    assert worst < 1e-12, worst
    # the first call is the initial state: the marker at its given point, moving with w x r about the pivot
    t0, *_, p_tip, v_tip, w_b = seen[0]
    w0 = np.array((0.4, -1.1, 7.0))
    assert t0 == 0.0
    assert np.allclose(p_tip, (0.25, -0.1, 0.7), rtol=0, atol=1e-9)
    # the body's initial angular velocity is the given one (a spherical joint keeps all three components)
    assert np.allclose(w_b, w0, rtol=0, atol=1e-9)
    assert np.allclose(v_tip, np.cross(w_b, p_tip), rtol=0, atol=1e-9)


def test_callable_force_at_an_offset_point_matches_its_expression_and_its_work_is_counted():
    """F = (-2 VX(tip), 1.5 cos 4t, -3 DZ(tip)) at the marker: once a Python callable of the light State,
    once an expression; the two runs agree to 1e-8 and the callable's work (summed by the kernel from the
    power the callback writes, F . v of the point) balances the energy."""
    def as_callable(m, b, mk):
        m.add_force("f", mk, lambda t, s: (-2.0 * s.velocity(mk)[0], 1.5 * np.cos(4 * t), -3.0 * s.position(mk)[2]))

    def as_expression(m, b, mk):
        m.add_force("f", mk, ("-2*VX(b.tip)", "1.5*cos(4*TIME)", "-3*DZ(b.tip)"))

    runs = []
    for build in (as_callable, as_expression):
        m, b, mk = _top(build)
        res = mb.simulate(m, 1.0, 0.01, method="dop853", rtol=1e-11, atol=1e-12)
        assert res.success, res.message
        runs.append((res, b, mk))
    (rc, b, mk), (re_, _, _) = runs
    assert list(rc.stats["called_back"]) == ["f"] and not re_.stats.get("called_back")
    assert np.max(np.abs(rc.position("b.tip") - re_.position("b.tip"))) < 1e-8
    assert rc.stats.get("energy") == "compiled", rc.stats.get("energy")
    E = rc.kinetic_energy() + 1.5 * G * rc.position(b)[:, 2]
    W = rc.energy["W"] - rc.energy["W"][0]
    assert np.max(np.abs(W)) > 0.05
    assert np.max(np.abs(W - (E - E[0]))) < 1e-8 * max(1.0, np.max(np.abs(W)))
