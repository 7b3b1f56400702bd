"""Globally convergent statics: the stable equilibrium from any start, unstable and indeterminate cases
named, quasi-static analysis of a driven mechanism (closed forms)."""
import warnings

import numpy as np
import pytest
from scipy.optimize import fsolve
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.solvers.assembly import assemble_state
from mbdsim.solvers.static import solve_static
from mbdsim.system.assemble import assemble_system

G = 9.81


def rod_on_pin(th0, m=2.0, L=1.0, gravity=(0.0, -G, 0.0)):
    model = mb.Model("pendulum", gravity=gravity)
    c, s = np.cos(th0), np.sin(th0)
    rod = model.add_body("rod", m, inertia=(0.01, m * L**2 / 12, m * L**2 / 12), position=(L / 2 * c, L / 2 * s, 0),
                         orientation=Rotation.from_rotvec([0, 0, th0]))
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1))
    return model, rod, pin


@pytest.mark.parametrize("th0", [0.0, np.pi, -np.pi / 2 + 0.3, 1.2, np.pi / 2 - 1e-3, np.pi / 2 + 1e-6, 2.9, -3.0])
def test_rod_on_a_revolute_from_any_start_hangs(th0):
    """Any start but the top itself reaches the hanging equilibrium (the old Newton failed from horizontal)."""
    model, rod, pin = rod_on_pin(th0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = mb.equilibrium(model)
    assert res.success and res.stats["stable"] and not res.stats["unstable_directions"]
    assert np.allclose(res.position(rod)[0], [0.0, -0.5, 0.0], atol=1e-9)
    assert np.allclose(res.reaction_force(pin)[0], [0.0, 2.0 * G, 0.0], atol=1e-8)   # the pin carries the weight
    assert res.stats["iterations"] < 60 and res.stats["stiffness_eigenvalues"][0] > 0
    assert np.allclose(res.velocity(rod), 0) and np.allclose(res.acceleration(rod), 0)


def test_pendulum_started_exactly_upright_is_returned_flagged_unstable():
    model, rod, pin = rod_on_pin(np.pi / 2)
    with pytest.warns(mb.UnstableEquilibriumWarning, match=r"negative stiffness along body 'rod' rotating about"):
        res = mb.equilibrium(model)
    assert res.success and res.stats["stable"] is False
    assert np.allclose(res.position(rod)[0], [0.0, 0.5, 0.0], atol=1e-12)
    assert "pin" in res.stats["unstable_directions"][0] and "UNSTABLE" in res.message
    assert res.stats["stiffness_eigenvalues"][0] < 0


def test_no_equilibrium_names_the_unbalanced_direction():
    model = mb.Model("slider", gravity=(0.0, -G, 0.0))
    block = model.add_body("block", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.0, 1.0, 0.0))
    model.add_translational("rail", model.ground, block, (0, 1, 0), (0, 1, 1))   # a 45 deg slope, no stop
    with pytest.raises(mb.SolverError, match=r"block' CM moving along \(0, -0.707, -0.707\).*joint coordinates: "
                                             r"rail.*static equilibrium not found in 20 iterations"):
        mb.equilibrium(model, maxit=20)


def test_neutral_directions_are_reported_not_failed():
    """Without gravity every angle of the pendulum is an equilibrium: indeterminate along the pin."""
    model, rod, pin = rod_on_pin(0.4, gravity=(0.0, 0.0, 0.0))
    res = mb.equilibrium(model)
    assert res.stats["stable"] and len(res.stats["neutral_directions"]) == 1
    assert "pin" in res.stats["neutral_directions"][0] and "neutral" in res.message
    assert res.stats["iterations"] == 0


def test_spherical_pendulum_turned_upside_down_hangs():
    """Three rotational DOF started 170 deg from hanging: hangs, the spin about the vertical is neutral."""
    m_, l = 1.5, 0.8
    rot = Rotation.from_rotvec([np.radians(170), 0.3, 0.0])
    model = mb.Model("sph", gravity=(0.0, 0.0, -G))
    bob = model.add_body("bob", m_, inertia=(0.02, 0.03, 0.04), position=rot.apply([0, 0, -l]), orientation=rot)
    ball = model.add_spherical("ball", model.ground, bob, (0, 0, 0))
    res = mb.equilibrium(model)
    assert np.allclose(res.position(bob)[0], [0.0, 0.0, -l], atol=1e-9)
    assert res.stats["stable"] and len(res.stats["neutral_directions"]) == 1
    assert np.allclose(res.reaction_force(ball)[0], [0, 0, m_ * G], atol=1e-8)


def test_particle_on_two_springs_from_a_far_start():
    """The start is above both anchors (springs compressed and crossed): the hanging equilibrium of fsolve."""
    m_, g = 1.2, np.array([0.0, 0.0, -G])
    A1, A2 = np.array([-0.5, 0.1, 1.0]), np.array([0.6, -0.2, 1.2])
    k1, k2, L1, L2 = 150.0, 90.0, 0.7, 0.9
    model = mb.Model("hang", gravity=g)
    p = model.add_particle("p", m_, position=(0.3, 0.2, 2.5))
    model.add_spring_damper("s1", (model.ground, A1), p, k1, free_length=L1)
    model.add_spring_damper("s2", (model.ground, A2), p, k2, free_length=L2)

    def net(x):
        F = m_ * g
        for A, k, L0 in ((A1, k1, L1), (A2, k2, L2)):
            d = A - x
            F = F + k * (np.linalg.norm(d) - L0) * d / np.linalg.norm(d)
        return F
    x_eq = fsolve(net, [0.0, 0.0, 0.0], xtol=1e-14)
    assert np.linalg.norm(net(x_eq)) < 1e-10 and x_eq[2] < 1.0
    res = mb.equilibrium(model)
    assert np.allclose(res.position(p)[0], x_eq, atol=1e-9) and res.stats["stable"]


def test_pseudo_transient_fallback_reaches_the_same_equilibrium():
    for th0 in (0.0, 2.5, -1.0):
        model, rod, pin = rod_on_pin(th0)
        sys = assemble_system(model)
        rep = assemble_state(sys, sys.q0, np.zeros(sys.nv))
        sol = solve_static(sys, rep.q, 0.0, rep.rows, relax=True)
        assert sol.method == "pseudo-transient continuation (compiled)" and sol.stable
        assert np.allclose(sol.q[:3], [0.0, -0.5, 0.0], atol=1e-9)


def test_quasi_static_two_link_arm_with_a_free_hanging_link():
    """Link 1 driven theta(t) = t from horizontal, link 2 free on the elbow (started horizontal too): at
    every time link 2 hangs below the elbow and the driver holds g cos(theta) (m1 l1/2 + m2 l1)."""
    m1, l1, m2, l2 = 2.0, 1.0, 0.5, 0.6
    model = mb.Model("arm", gravity=(0.0, -G, 0.0))
    a1 = model.add_body("upper", m1, inertia=(0.01, m1 * l1**2 / 12, m1 * l1**2 / 12), position=(l1 / 2, 0, 0))
    a2 = model.add_body("lower", m2, inertia=(0.01, m2 * l2**2 / 12, m2 * l2**2 / 12), position=(l1 + l2 / 2, 0, 0))
    shoulder = model.add_revolute("shoulder", model.ground, a1, (0, 0, 0), (0, 0, 1))
    elbow = model.add_revolute("elbow", a1, a2, (l1, 0, 0), (0, 0, 1))
    drive = model.add_motion("drive", shoulder, displacement="t")
    res = mb.quasi_static(model, 2.0, 0.25)
    th = res.time
    assert res.success and len(res.time) == 9 and np.all(res.stats["stable"])
    elbow_pt = l1 * np.c_[np.cos(th), np.sin(th), 0 * th]
    assert np.allclose(res.position(a2), elbow_pt + [0.0, -l2 / 2, 0.0], atol=1e-9)
    assert np.allclose(res.driver_effort(drive), G * np.cos(th) * (m1 * l1 / 2 + m2 * l1), atol=1e-8)
    assert np.allclose(res.reaction_force(elbow), np.tile([0.0, m2 * G, 0.0], (len(th), 1)), atol=1e-8)
    assert np.allclose(res.velocity(a2), 0.0)
    mid = res.at(0.6)                              # solved again at t = 0.6 s from the nearest sample
    assert np.allclose(mid.position(a2)[0], [l1 * np.cos(0.6), l1 * np.sin(0.6) - l2 / 2, 0], atol=1e-9)


def test_quasi_static_zero_dof_lift_against_a_spring():
    model = mb.Model("lift", gravity=(0.0, -G, 0.0))
    b = model.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1), position=(0, 0, 0))
    slide = model.add_translational("slide", model.ground, b, (0, 0, 0), (0, 1, 0))
    model.add_motion("lift", slide, displacement="t")
    spring = model.add_spring_damper("tether", (model.ground, (0, -1, 0)), b, 100.0)
    res = mb.quasi_static(model, 1.0, 0.5)
    # driven along the only DOF: zero-DOF statics, the driver carries weight and spring
    assert res.success and np.allclose(res.spring_force(spring), 100.0 * res.time, atol=1e-9)
    assert np.allclose(res.driver_effort("lift"), G + 100.0 * res.time, atol=1e-8)
    with pytest.raises(mb.ModelError) as err:
        mb.quasi_static(model, -1.0)
    assert err.value.field == "end_time"


def test_quasi_static_stops_with_a_partial_result_when_the_motion_is_impossible():
    """Slider-crank with crank 1 m and coupler 0.5 m driven theta = t: no position once sin(t) > 0.5."""
    model = mb.Model("short coupler", gravity=(0.0, -G, 0.0))
    crank = model.add_body("crank", 1.0, inertia=(0.01, 0.1, 0.1), position=(0.5, 0, 0))
    rod = model.add_body("rod", 0.5, inertia=(0.01, 0.02, 0.02), position=(1.25, 0, 0))
    slider = model.add_body("slider", 1.0, inertia=(0.1, 0.1, 0.1), position=(1.5, 0, 0))
    pivot = model.add_revolute("pivot", model.ground, crank, (0, 0, 0), (0, 0, 1))
    model.add_revolute("wrist", crank, rod, (1, 0, 0), (0, 0, 1))
    model.add_revolute("pin", rod, slider, (1.5, 0, 0), (0, 0, 1))
    model.add_translational("guide", model.ground, slider, (1.5, 0, 0), (1, 0, 0))
    model.add_motion("drive", pivot, displacement="t")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.quasi_static(model, 1.0, 0.25)
    assert not res.success and len(res.time) == 3 and res.time[-1] == 0.5
    assert isinstance(res.error, mb.SolverError) and res.error.time == 0.75
    assert "last equilibrium at t = 0.5 s" in res.message
    x = np.cos(res.time) + np.sqrt(0.25 - np.sin(res.time) ** 2)
    assert np.allclose(res.position(slider)[:, 0], x, atol=1e-9)


def test_ball_dropped_from_high_above_a_contact_floor():
    """Adams IMPACT floor (k = 1e6 N/m^1.5): the resting penetration (m g / k)^(1/e) from 3 m above it."""
    m_, R, k, e = 2.0, 0.1, 1e6, 1.5
    for z0 in (3.0, 0.1):
        model = mb.Model("ball", gravity=(0.0, 0.0, -G))
        ball = model.add_particle("ball", m_, position=(0, 0, z0))
        model.add_contact("floor", mb.Plane(model.ground, (0, 0, 0), (0, 0, 1)), mb.Sphere(ball, R), k, e, 10.0, 1e-3)
        res = mb.equilibrium(model)
        assert R - res.position(ball)[0, 2] == pytest.approx((m_ * G / k) ** (1 / e), rel=1e-9)
        assert res.stats["stable"]


def test_circulatory_follower_load_without_a_potential():
    """A particle on a plane held by a spring (k) under a curl force c (-y, x) and a constant load f0: no
    potential exists; equilibrium (k I - c J) x = f0 with J the quarter turn."""
    k, c, f0 = 50.0, 30.0, np.array([4.0, -3.0])
    model = mb.Model("curl")
    p = model.add_particle("p", 1.0, position=(0.8, 0.6, 0.0))
    model.add_planar("table", model.ground, p, (0, 0, 0), (0, 0, 1))
    model.add_spring_damper("spring", (model.ground, (0, 0, 0)), p, k, free_length=0.0)
    model.add_force("curl", p, lambda t, s: (-c * s.position(p)[1] + f0[0], c * s.position(p)[0] + f0[1], 0.0))
    res = mb.equilibrium(model)
    x = np.linalg.solve(k * np.eye(2) - c * np.array([[0, -1], [1, 0]]), f0)
    assert np.allclose(res.position(p)[0, :2], x, atol=1e-10)


def test_quasi_static_winds_a_torsion_spring_past_half_a_turn():
    """A motor turns a drum 4 rad/s against a torsion spring (2 N m/rad) while a pendulum hangs from the
    drum's rim: the spring angle and the motor torque grow past pi at every sample, the pendulum hangs."""
    k = 2.0
    model = mb.Model("wind", gravity=(0.0, -G, 0.0))
    drum = model.add_body("drum", 1.0, inertia=(0.1, 0.1, 0.1))
    axle = model.add_revolute("axle", model.ground, drum, (0, 0, 0), (0, 0, 1))
    ts = model.add_torsion_spring("clock", axle, k)
    motor = model.add_motion("motor", axle, displacement="4*t")
    bob = model.add_body("bob", 0.2, inertia=(1e-3, 1e-3, 1e-3), position=(0.3, -0.2, 0))
    model.add_revolute("hook", drum, bob, (0.3, 0, 0), (0, 0, 1))
    res = mb.quasi_static(model, 1.5, 0.1)
    th = 4 * res.time
    assert res.success and np.allclose(res.spring_length(ts), th, atol=1e-9)
    rim = 0.3 * np.c_[np.cos(th), np.sin(th), 0 * th]
    assert np.allclose(res.position(bob), rim + [0, -0.2, 0], atol=1e-9)
    assert np.allclose(res.driver_effort(motor), k * th + 0.2 * G * rim[:, 0], atol=1e-8)


def double_pendulum(a1, a2, l=1.0, m=1.0):
    model = mb.Model("double", gravity=(0.0, -G, 0.0))
    p1 = l * np.array([np.cos(a1), np.sin(a1), 0.0])
    p2 = p1 + l * np.array([np.cos(a2), np.sin(a2), 0.0])
    b1 = model.add_body("upper", m, inertia=(0.01, m * l * l / 12, m * l * l / 12), position=p1 / 2,
                        orientation=Rotation.from_rotvec([0, 0, a1]))
    b2 = model.add_body("lower", m, inertia=(0.01, m * l * l / 12, m * l * l / 12), position=(p1 + p2) / 2,
                        orientation=Rotation.from_rotvec([0, 0, a2]))
    model.add_revolute("shoulder", model.ground, b1, (0, 0, 0), (0, 0, 1))
    model.add_revolute("elbow", b1, b2, tuple(p1), (0, 0, 1))
    return model


def test_double_pendulum_four_equilibria_only_one_stable():
    """Starts anywhere but on the three unstable equilibria reach the straight hanging one; started exactly
    on one, it is returned with as many unstable directions as it has (up-up 2, down-up 1)."""
    for a1, a2 in ((0.0, 0.0), (np.pi / 2 + 0.01, np.pi / 2), (2.0, -2.5), (0.3, 3.0), (np.pi, 0.0)):
        res = mb.equilibrium(double_pendulum(a1, a2))
        assert res.stats["stable"] and np.allclose(res.position("lower")[0], [0, -1.5, 0], atol=1e-9)
    for (a1, a2), n_bad, y in (((np.pi / 2, np.pi / 2), 2, 1.5), ((-np.pi / 2, np.pi / 2), 1, -0.5)):
        with pytest.warns(mb.UnstableEquilibriumWarning):
            res = mb.equilibrium(double_pendulum(a1, a2))
        assert len(res.stats["unstable_directions"]) == n_bad and res.position("lower")[0, 1] == pytest.approx(y)
        assert np.sum(res.stats["stiffness_eigenvalues"] < 0) == n_bad


@pytest.mark.parametrize("axis", [(0.3, -0.2, 1.0), (1.0, 0.0, 0.0)])
def test_rod_on_an_oblique_revolute_from_every_start_hangs(axis):
    """A rod on a pin whose axis is tilted from the horizontal: from 24 starts round the circle (all but the
    top) the CM ends at the lowest point of its circle, L/2 along the in-plane component of gravity."""
    ax = np.asarray(axis, float) / np.linalg.norm(axis)
    u = np.cross(ax, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(ax, u)
    down = np.array([0.0, -1.0, 0.0]) - np.dot([0.0, -1.0, 0.0], ax) * ax
    down /= np.linalg.norm(down)
    top = np.arctan2(np.dot(-down, w), np.dot(-down, u))
    for th in np.linspace(-np.pi, np.pi, 24, endpoint=False) + 0.01:
        if abs(np.angle(np.exp(1j * (th - top)))) < 1e-3:
            continue
        model = mb.Model("tilted", gravity=(0.0, -G, 0.0))
        d = np.cos(th) * u + np.sin(th) * w
        R0 = Rotation.from_matrix(np.column_stack([u, w, ax]))        # body x along u at th = 0
        rod = model.add_body("rod", 1.5, inertia=(0.001, 0.02, 0.02), position=0.4 * d,
                             orientation=Rotation.from_rotvec(ax * th) * R0)
        model.add_revolute("pin", model.ground, rod, (0, 0, 0), ax)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            res = mb.equilibrium(model)
        assert res.stats["stable"], th
        assert np.allclose(res.position(rod)[0], 0.4 * down, atol=1e-8), th
