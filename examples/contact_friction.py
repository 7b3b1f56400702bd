"""A ball thrown sliding (no spin) onto a plane with Coulomb friction: it slides, spins up and rolls.

Closed form for a solid sphere: rolling starts at t = 2 v0 / (7 mu g) with speed 5/7 v0, whatever mu.
Compliant contact (Adams IMPACT law) with regularised friction.  Same model as contact_friction.yaml.
Run: python examples/contact_friction.py
"""
import mbdsim as mb

RADIUS, DENSITY, V0, MU = 0.05, 1000.0, 1.0, 0.3


def build() -> mb.Model:
    """Ball of 5 cm radius resting on the plane z = 0, moving at 1 m/s along x."""
    model = mb.Model("contact_friction", gravity=(0, 0, -9.81))
    ball = model.add_body("ball", shape=mb.Sphere(None, RADIUS), density=DENSITY, position=(0, 0, RADIUS),
                          velocity=(V0, 0, 0))
    model.add_contact("floor", mb.Sphere(ball, RADIUS), mb.Plane(model.ground, (0, 0, 0), (0, 0, 1)),
                      stiffness=1e6, exponent=1.5, damping=50.0, penetration=1e-4, mu=MU, friction_velocity=1e-3)
    return model


if __name__ == "__main__":
    res = mb.simulate(build(), end_time=0.3, output_step=0.005)
    print("final speed [m/s]:", res.velocity("ball")[-1, 0], "closed form 5/7 v0 =", 5 / 7 * V0)
