"""Catalogue of bad inputs (issue 10): each case is (id, action, error class, entity, field).

API cases: `action(m)` does one bad call on a fresh base model `m` (see `base_model`). File cases:
`action` is (dotted path into the base model-file dict, bad value); the mutated dict is written as YAML
and loaded. The runner (test_bad_inputs.py) asserts the class, the entity and the field, and that
nothing ran: the model is unchanged (no element added) and no analysis step was taken.
"""
import mbdsim as mb
from mbdsim.errors import ModelError, ModelFileError

NaN, Inf = float("nan"), float("inf")


def base_model():
    """A pendulum `rod` on revolute `pin`, a slider `block` on translational `slide`, a particle `pt`."""
    m = mb.Model("base", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", 1.0, inertia=(0.08, 1e-4, 0.08), position=(0.0, -0.5, 0.0))
    rod.add_marker("tip", (0.0, -1.0, 0.0)) if hasattr(rod, "add_marker") else None
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    blk = m.add_body("block", 2.0, inertia=(0.1, 0.1, 0.1), position=(2.0, 0.0, 0.0))
    m.add_translational("slide", m.ground, blk, (2.0, 0.0, 0.0), (1, 0, 0))
    m.add_particle("pt", 0.5, position=(0.0, 3.0, 0.0))
    return m


def _b(name="x", **kw):
    base = dict(mass=1.0, inertia=(1.0, 1.0, 1.0))
    base.update(kw)
    return lambda m: m.add_body(name, **base)


def _spring_named(name):
    return lambda m: m.add_spring_damper(name, (m.bodies["rod"], (0, -1, 0)), (m.ground, (0, -2, 0)), 10.0)


def _rev(**kw):
    base = dict(body_i="ground", body_j="block", point=(0, 0, 0), axis=(0, 0, 1))
    base.update(kw)
    return lambda m: m.add_revolute("j", **base)


def _motion(joint="pin", **kw):
    return lambda m: m.add_motion("d", joint, **kw)


def _spring(**kw):
    base = dict(at_i=("rod", (0, -1, 0)), at_j=("ground", (0, -2, 0)), stiffness=10.0)
    base.update(kw)

    def act(m):
        at_i = (m.bodies[base["at_i"][0]] if base["at_i"][0] != "ground" else m.ground, base["at_i"][1]) \
            if isinstance(base["at_i"], tuple) else base["at_i"]
        at_j = (m.ground, base["at_j"][1]) if isinstance(base["at_j"], tuple) else base["at_j"]
        kw2 = {k: v for k, v in base.items() if k not in ("at_i", "at_j")}
        m.add_spring_damper("s", at_i, at_j, **kw2)
    return act


def _contact(**kw):
    base = dict(stiffness=1e5, exponent=1.5, damping=10.0, penetration=1e-3)
    base.update(kw)
    return lambda m: m.add_contact("c", mb.Plane(m.ground, (0, -5, 0), (0, 1, 0)), mb.Sphere(m.bodies["rod"], 0.1),
                                   **base)


def _sim(*args, **kw):
    return lambda m: mb.simulate(m, *args, **kw)


def _kin(*args, **kw):
    return lambda m: mb.kinematics(m, *args, **kw)


class _Junk:
    """Not a force element, though it has a name."""
    name = "junk"


B, J, MO = "body 'x'", "joint 'j'", "motion 'd'"
API_CASES = [
    # bodies: mass properties, states
    ("body-mass-negative", _b(mass=-1.0), ModelError, B, "mass"),
    ("body-mass-true", _b(mass=True), ModelError, B, "mass"),
    ("body-mass-string", _b(mass="heavy"), ModelError, B, "mass"),
    ("body-mass-nan", _b(mass=NaN), ModelError, B, "mass"),
    ("body-mass-inf", _b(mass=Inf), ModelError, B, "mass"),
    ("body-mass-missing", _b(mass=None), ModelError, B, "mass"),
    ("body-mass-1e300", _b(mass=1e300), ModelError, B, "mass"),   # ran, then its reactions overflowed
    ("body-mass-1e-300", _b(mass=1e-300), ModelError, B, "mass"),
    ("body-inertia-1e300", _b(inertia=(1e300, 1e300, 1e300)), ModelError, B, "inertia"),
    ("body-inertia-negative", _b(inertia=(-1.0, 1.0, 1.0)), ModelError, B, "inertia"),
    ("body-inertia-triangle", _b(inertia=(1.0, 1.0, 5.0)), ModelError, B, "inertia"),
    ("body-inertia-asymmetric", _b(inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]), ModelError, B, "inertia"),
    ("body-inertia-short", _b(inertia=(1.0, 1.0)), ModelError, B, "inertia"),
    ("body-inertia-bool", _b(inertia=(True, 1.0, 1.0)), ModelError, B, "inertia"),
    ("body-inertia-nan", _b(inertia=(NaN, 1.0, 1.0)), ModelError, B, "inertia"),
    ("body-inertia-indefinite", _b(inertia=[[1, 2, 0], [2, 1, 0], [0, 0, 1]]), ModelError, B, "inertia"),
    ("body-position-short", _b(position=(0.0, 0.0)), ModelError, B, "position"),
    ("body-position-nan", _b(position=(0.0, NaN, 0.0)), ModelError, B, "position"),
    ("body-position-string", _b(position="origin"), ModelError, B, "position"),
    ("body-velocity-string", _b(velocity="fast"), ModelError, B, "velocity"),
    ("body-velocity-inf", _b(velocity=(Inf, 0, 0)), ModelError, B, "velocity"),
    ("body-omega-short", _b(angular_velocity=(1.0, 2.0)), ModelError, B, "angular_velocity"),
    ("body-orientation-bad", _b(orientation="sideways"), ModelError, B, "orientation"),
    ("body-duplicate-name", lambda m: m.add_body("rod", 1.0, inertia=(1, 1, 1)), ModelError, "body 'rod'", "name"),
    ("particle-mass-zero", lambda m: m.add_particle("x", 0.0), ModelError, "particle 'x'", "mass"),
    ("particle-mass-bool", lambda m: m.add_particle("x", False), ModelError, "particle 'x'", "mass"),
    # joints
    ("joint-unknown-body", _rev(body_j="nobody"), ModelError, J, "body_j"),
    ("joint-axis-zero", _rev(axis=(0, 0, 0)), ModelError, J, "axis"),
    ("joint-axis-nan", _rev(axis=(0, NaN, 1)), ModelError, J, "axis"),
    ("joint-point-long", _rev(point=(0, 0, 0, 0)), ModelError, J, "point"),
    ("joint-point-bool", _rev(point=(True, 0, 0)), ModelError, J, "point"),
    ("joint-duplicate-name", lambda m: m.add_revolute("pin", m.ground, m.bodies["block"], (0, 0, 0), (0, 0, 1)),
     ModelError, "joint 'pin'", "name"),
    # motions
    ("motion-unknown-joint", _motion("nojoint", displacement="t"), ModelError, MO, "joint"),
    ("motion-none-given", _motion(), ModelError, MO, "displacement"),
    ("motion-two-given", _motion(displacement="t", velocity="1"), ModelError, MO, "displacement"),
    ("motion-syntax", _motion(displacement="sin("), ModelError, MO, "displacement"),
    ("motion-hostile", _motion(displacement="__import__('os').system('touch x')"), ModelError, MO, "displacement"),
    ("motion-attribute", _motion(displacement="t.__class__"), ModelError, MO, "displacement"),
    ("motion-unknown-variable", _motion(displacement="x*t"), ModelError, MO, "displacement"),
    ("motion-nested-too-deep", _motion(displacement="sin(" * 150 + "t" + ")" * 150), ModelError, MO, "displacement"),
    ("motion-power-tower", _motion(displacement="t" + "**t" * 50), ModelError, MO, "displacement"),
    ("motion-too-long", _motion(displacement="+".join(["t"] * 6000)), ModelError, MO, "displacement"),
    ("motion-callable-signature", _motion(displacement=lambda: 0.0), ModelError, MO, "displacement"),
    ("motion-velocity-signature", _motion(velocity=lambda t, u: 0.0), ModelError, MO, "velocity"),
    ("motion-initial-string", _motion(velocity="1", initial_displacement="zero"), ModelError, MO,
     "initial_displacement"),
    ("motion-type", _motion(displacement=[1, 2]), ModelError, MO, "displacement"),
    ("motion-dof-on-revolute", _motion(displacement="t", dof="translation"), ModelError, MO, "dof"),
    ("motion-twice", lambda m: (m.add_motion("d0", "pin", displacement="t"), m.add_motion("d", "pin", velocity="1")),
     ModelError, MO, "joint"),
    # loads
    ("force-signature", lambda m: m.add_force("f", (m.bodies["rod"], (0, 0, 0)), lambda t: (0, 0, 0)), ModelError,
     "force 'f'", "force"),
    ("force-short", lambda m: m.add_force("f", (m.bodies["rod"], (0, 0, 0)), (1.0, 2.0)), ModelError, "force 'f'",
     "force"),
    ("force-nan", lambda m: m.add_force("f", (m.bodies["rod"], (0, 0, 0)), (NaN, 0, 0)), ModelError, "force 'f'",
     "force"),
    ("force-string", lambda m: m.add_force("f", (m.bodies["rod"], (0, 0, 0)), "down"), ModelError, "force 'f'",
     "force"),
    ("force-frame-unknown", lambda m: m.add_force("f", (m.bodies["rod"], (0, 0, 0)), (1, 0, 0), frame="nobody"),
     ModelError, "force 'f'", "frame"),
    ("torque-signature", lambda m: m.add_torque("tq", "rod", lambda: (0, 0, 1)), ModelError, "torque 'tq'", "torque"),
    ("torque-on-particle", lambda m: m.add_torque("tq", "pt", (0, 0, 1)), ModelError, "torque 'tq'", "body"),
    ("torque-bool", lambda m: m.add_torque("tq", "rod", (0, 0, True)), ModelError, "torque 'tq'", "torque"),
    ("torque-unknown-body", lambda m: m.add_torque("tq", "nobody", (0, 0, 1)), ModelError, "torque 'tq'", "body"),
    ("spring-stiffness-negative", _spring(stiffness=-1.0), ModelError, "spring 's'", "stiffness"),
    ("spring-stiffness-bool", _spring(stiffness=True), ModelError, "spring 's'", "stiffness"),
    ("spring-damping-nan", _spring(damping=NaN), ModelError, "spring 's'", "damping"),
    ("spring-free-length-negative", _spring(free_length=-1.0), ModelError, "spring 's'", "free_length"),
    ("spring-preload-string", _spring(preload="some"), ModelError, "spring 's'", "preload"),
    ("contact-exponent-zero", _contact(exponent=0.0), ModelError, "contact 'c'", "exponent"),
    ("contact-penetration-zero", _contact(penetration=0.0), ModelError, "contact 'c'", "penetration"),
    ("contact-stiffness-negative", _contact(stiffness=-1.0), ModelError, "contact 'c'", "stiffness"),
    ("contact-mu-negative", _contact(mu=-0.1), ModelError, "contact 'c'", "mu"),
    # analysis arguments: refused before any work
    ("sim-end-string", _sim("a"), ModelError, "analysis", "end_time"),
    ("sim-end-before-start", _sim(-1.0), ModelError, "analysis", "end_time"),
    ("sim-end-nan", _sim(NaN), ModelError, "analysis", "end_time"),
    ("sim-step-zero", _sim(1.0, 0.0), ModelError, "analysis", "output_step"),
    ("sim-step-negative", _sim(1.0, -0.1), ModelError, "analysis", "output_step"),
    ("sim-step-nan", _sim(1.0, NaN), ModelError, "analysis", "output_step"),
    ("sim-step-budget", _sim(1e6, 1e-6), ModelError, "simulate", "output_step"),
    ("sim-rtol-zero", _sim(1.0, rtol=0.0), ModelError, "simulate", "rtol"),
    ("sim-rtol-negative", _sim(1.0, rtol=-1e-6), ModelError, "simulate", "rtol"),
    ("sim-rtol-1e-30", _sim(0.2, rtol=1e-30), ModelError, "simulate", "rtol"),
    ("sim-rtol-string", _sim(1.0, rtol="tight"), ModelError, "simulate", "rtol"),
    ("sim-hht-rtol-1e-13", _sim(0.2, rtol=1e-13, method="hht"), ModelError, "simulate", "rtol"),
    ("sim-atol-negative", _sim(1.0, atol=-1.0), ModelError, "simulate", "atol"),
    ("sim-atol-nan", _sim(1.0, atol=NaN), ModelError, "simulate", "atol"),
    ("sim-method-unknown", _sim(1.0, method="euler"), ModelError, "simulate", "method"),
    ("sim-method-number", _sim(1.0, method=3), ModelError, "simulate", "method"),
    ("sim-max-step-zero", _sim(1.0, max_step=0.0), ModelError, "simulate", "max_step"),
    ("sim-start-nan", _sim(1.0, start_time=NaN), ModelError, "simulate", "start_time"),
    ("sim-start-string", _sim(1.0, start_time="a"), ModelError, "simulate", "start_time"),
    ("sim-start-inf", _sim(1.0, start_time=-Inf), ModelError, "simulate", "start_time"),
    ("sim-not-a-model", lambda m: mb.simulate("model.yaml", 1.0), ModelError, "analysis", "model"),
    ("sim-contact-deep", lambda m: (m.add_contact("c", mb.Plane(m.ground, (0, -0.4, 0), (0, 1, 0)),
                                                  mb.Sphere(m.bodies["rod"], 0.05), 1e5, 1.5, 10.0, 1e-3),
                                    mb.simulate(m, 1.0)), ModelError, "contact 'c'", "initial_gap"),
    ("kin-free-dof", _kin(1.0, 0.1), ModelError, "model 'base'", "motions"),
    ("kin-start-string", _kin(1.0, 0.1, start_time="a"), ModelError, "simulate", "start_time"),
    ("kin-step-budget", _kin(1e6, 1e-6), ModelError, "simulate", "output_step"),
    # issue 35: unbounded work and bad callbacks refused before any work
    ("sim-progress-not-callable", _sim(1.0, progress=5), ModelError, "simulate", "progress"),
    ("kin-progress-not-callable", _kin(1.0, 0.1, progress="bar"), ModelError, "kinematics", "progress"),
    ("sim-max-step-budget", _sim(1.0, max_step=1e-10), ModelError, "simulate", "max_step"),
    ("sim-end-1e12-max-step", _sim(1e12, max_step=1e-2), ModelError, "simulate", "max_step"),
    ("sim-outputs-budget-streamed", _sim(1e12, 1e-2, out="run.parquet"), ModelError, "simulate", "output_step"),
    ("sim-outputs-budget-csv", _sim(1e9, 1.0, out="run.csv"), ModelError, "simulate", "output_step"),
    # issue 35: refused at once, not a bare exception later (ZeroDivisionError, TypeError at simulate)
    ("sim-empty-model", lambda m: mb.simulate(mb.Model("e"), 1.0), ModelError, "model 'e'", "bodies"),
    ("kin-empty-model", lambda m: mb.kinematics(mb.Model("e"), 1.0, 0.1), ModelError, "model 'e'", "bodies"),
    ("element-not-an-element", lambda m: m.add_element(_Junk()), ModelError, "element 'junk'", "type"),
    ("element-a-string", lambda m: m.add_element("junk"), ModelError, "element 'junk'", "name"),
    # issue 35: names that expressions would shadow (time, constants, functions) or that hide a marker
    ("body-name-t", _b(name="t"), ModelError, "body 't'", "name"),
    ("body-name-dotted", _b(name="rod.tip"), ModelError, "body 'rod.tip'", "name"),
    ("particle-name-pi", lambda m: m.add_particle("pi", 1.0), ModelError, "particle 'pi'", "name"),
    ("joint-name-TIME", lambda m: m.add_revolute("TIME", "ground", "block", (0, 0, 0), (0, 0, 1)), ModelError,
     "joint 'TIME'", "name"),
    ("joint-name-sin", lambda m: m.add_revolute("sin", "ground", "block", (0, 0, 0), (0, 0, 1)), ModelError,
     "joint 'sin'", "name"),
    ("joint-name-step", lambda m: m.add_revolute("STEP", "ground", "block", (0, 0, 0), (0, 0, 1)), ModelError,
     "joint 'STEP'", "name"),
    ("joint-name-rate-clash", lambda m: m.add_revolute("pin_dot", "ground", "block", (0, 0, 0), (0, 0, 1)),
     ModelError, "joint 'pin_dot'", "name"),
    ("marker-name-DX", lambda m: m.bodies["rod"].add_marker("DX", (0, 0, 0)), ModelError, "marker 'rod.DX'", "name"),
    ("marker-name-dotted", lambda m: m.bodies["rod"].add_marker("a.b", (0, 0, 0)), ModelError, "marker 'rod.a.b'",
     "name"),
    ("spring-name-dotted", _spring_named("k.1"), ModelError, "spring 'k.1'", "name"),
    # issue 35: silently accepted before
    ("body-mass-text", _b(mass="2"), ModelError, B, "mass"),
    ("body-position-text", _b(position=("0", "1", "0")), ModelError, B, "position"),
    ("body-inertia-text", _b(inertia=["1", "1", "1"]), ModelError, B, "inertia"),
    ("sim-end-true", _sim(True), ModelError, "analysis", "end_time"),
    ("sim-end-text", _sim("1.0"), ModelError, "analysis", "end_time"),
    ("sim-step-true", _sim(1.0, True), ModelError, "analysis", "output_step"),
    ("sim-max-step-text", _sim(1.0, max_step="0.1"), ModelError, "simulate", "max_step"),
    ("sim-start-false", _sim(1.0, start_time=False), ModelError, "simulate", "start_time"),
    ("spring-coincident-free-length", _spring(at_j=("ground", (0, -1, 0)), free_length=0.5), ModelError,
     "spring 's'", "at_j"),
    ("spring-coincident-preload", _spring(at_j=("ground", (0, -1, 0)), free_length=0.0, preload=3.0), ModelError,
     "spring 's'", "at_j"),
]

BASE_FILE = {
    "name": "file",
    "gravity": [0, -9.81, 0],
    "bodies": [{"name": "rod", "mass": "1 kg", "inertia": [0.08, 1.0e-4, 0.08], "position": [0, -0.5, 0],
                "markers": [{"name": "tip", "point": [0, -1, 0]}]},
               {"name": "block", "mass": 2, "inertia": [0.1, 0.1, 0.1], "position": [2, 0, 0]}],
    "joints": [{"name": "pin", "type": "revolute", "body_i": "ground", "body_j": "rod", "point": [0, 0, 0],
                "axis": [0, 0, 1]},
               {"name": "slide", "type": "translational", "body_i": "ground", "body_j": "block",
                "point": [2, 0, 0], "axis": [1, 0, 0]}],
    "motions": [{"name": "drive", "joint": "slide", "displacement": "0.1*sin(t)"}],
    "forces": [{"name": "k", "type": "spring_damper", "at_i": {"body": "rod", "point": [0, -1, 0]},
                "at_j": {"body": "ground", "point": [0, -2, 0]}, "stiffness": "10 N/m"}],
}
DELETE = object()
R, BL, P, S, D, K = "body 'rod'", "body 'block'", "joint 'pin'", "joint 'slide'", "motion 'drive'", "spring 'k'"
FILE_CASES = [
    ("file-mass-negative", ("bodies.0.mass", -1), ModelFileError, R, "mass"),
    ("file-mass-units", ("bodies.0.mass", "1 m"), ModelFileError, R, "mass"),
    ("file-mass-bool", ("bodies.0.mass", True), ModelFileError, R, "mass"),
    ("file-mass-missing", ("bodies.1.mass", DELETE), ModelFileError, BL, "mass"),
    ("file-inertia-triangle", ("bodies.0.inertia", [1, 1, 5]), ModelFileError, R, "inertia"),
    ("file-inertia-short", ("bodies.0.inertia", [1, 1]), ModelFileError, R, "inertia"),
    ("file-inertia-negative", ("bodies.1.inertia", [-1, 1, 1]), ModelFileError, BL, "inertia"),
    ("file-position-short", ("bodies.0.position", [0, 0]), ModelFileError, R, "position"),
    ("file-position-text", ("bodies.0.position", "here"), ModelFileError, R, "position"),
    ("file-body-typo", ("bodies.0.mas", 1), ModelFileError, R, "mas"),
    ("file-body-duplicate", ("bodies.1.name", "rod"), ModelFileError, R, "name"),
    ("file-joint-type", ("joints.0.type", "hinge"), ModelFileError, P, "type"),
    ("file-joint-body", ("joints.0.body_j", "nobody"), ModelFileError, P, "body_j"),
    ("file-joint-axis-zero", ("joints.0.axis", [0, 0, 0]), ModelFileError, P, "axis"),
    ("file-joint-axis-missing", ("joints.0.axis", DELETE), ModelFileError, P, "axis"),
    ("file-joint-point-short", ("joints.1.point", [2, 0]), ModelFileError, S, "point"),
    ("file-motion-joint", ("motions.0.joint", "nojoint"), ModelFileError, D, "joint"),
    ("file-motion-syntax", ("motions.0.displacement", "sin("), ModelFileError, D, "displacement"),
    ("file-motion-hostile", ("motions.0.displacement", "__import__('os').getcwd()"), ModelFileError, D,
     "displacement"),
    ("file-motion-deep", ("motions.0.displacement", "sin(" * 150 + "t" + ")" * 150), ModelFileError, D,
     "displacement"),
    ("file-motion-tower", ("motions.0.displacement", "t" + "**t" * 50), ModelFileError, D, "displacement"),
    ("file-spring-stiffness", ("forces.0.stiffness", -5), ModelFileError, K, "stiffness"),
    ("file-spring-units", ("forces.0.stiffness", "10 kg"), ModelFileError, K, "stiffness"),
    ("file-spring-marker", ("forces.0.at_i", "rod.tipp"), ModelFileError, K, "at_i"),
    ("file-gravity-short", ("gravity", [0, -9.81]), ModelFileError, "model", "gravity"),
    ("file-gravity-text", ("gravity", "down"), ModelFileError, "model", "gravity"),
    ("file-top-typo", ("bodys", []), ModelFileError, "model", "bodys"),
    # issue 35: unit strings are evaluated in bounded (float) arithmetic: no hang, no bare OverflowError
    ("file-mass-power-tower", ("bodies.0.mass", "9**9**9 kg"), ModelFileError, R, "mass"),
    ("file-mass-power-overflow", ("bodies.0.mass", "2**10000 kg"), ModelFileError, R, "mass"),
    ("file-stiffness-unit-power", ("forces.0.stiffness", "1 N/m**9**9**9"), ModelFileError, K, "stiffness"),
    # issue 35: reserved and dotted names
    ("file-body-name-pi", ("bodies.1.name", "pi"), ModelFileError, "body 'pi'", "name"),
    ("file-body-name-dotted", ("bodies.1.name", "rod.tip"), ModelFileError, "body 'rod.tip'", "name"),
    ("file-joint-name-t", ("joints.0.name", "t"), ModelFileError, "joint 't'", "name"),
    ("file-marker-name-TIME", ("bodies.0.markers.0.name", "TIME"), ModelFileError, "marker 'rod.TIME'", "name"),
]
