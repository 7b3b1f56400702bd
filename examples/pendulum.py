"""Compound pendulum: a 1 m, 1 kg rod on a pin, small swing; same model as pendulum.yaml.

Small-amplitude period T = 2 pi sqrt(2 L / (3 g)).  Run: python examples/pendulum.py
"""
import mbdsim as mb

L, MASS, G, OMEGA0 = 1.0, 1.0, 9.81, 0.1


def build() -> mb.Model:
    """The pendulum hanging along -y, swinging about z with 0.1 rad/s at t = 0."""
    model = mb.Model("pendulum", gravity=(0, -G, 0))
    rod = model.add_body("rod", mass=MASS, inertia=(0.0833333333333333, 1.0e-6, 0.0833333333333333),
                         position=(0, -L / 2, 0), velocity=(OMEGA0 * L / 2, 0, 0), angular_velocity=(0, 0, OMEGA0))
    rod.add_marker("tip", point=(0, -L, 0))
    model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    return model


if __name__ == "__main__":
    res = mb.simulate(build(), end_time=5.0, output_step=0.01)
    ups = res.crossings(lambda r: r.joint_coordinate("pin"), 0.0, direction=1)
    print("period from the run:", ups[1] - ups[0], "s; closed form:", 2 * 3.141592653589793 * (2 * L / (3 * G)) ** 0.5)
