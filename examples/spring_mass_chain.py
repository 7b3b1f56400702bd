"""Three point masses hanging in a chain of springs from the ceiling (springs at their free length at t = 0).

Static sag of mass k: sum over the springs above it of (weight hanging below the spring) / stiffness.
Same model as spring_mass_chain.yaml.  Run: python examples/spring_mass_chain.py
"""
import mbdsim as mb

MASSES, K, SPACING, G = (1.0, 2.0, 0.5), 500.0, 0.25, 9.81


def build() -> mb.Model:
    """Particles m1..m3 at y = -0.25, -0.5, -0.75 m, springs s1 (ceiling-m1), s2, s3 of 500 N/m, light damping."""
    model = mb.Model("spring_mass_chain", gravity=(0, -G, 0))
    above = (model.ground, (0.0, 0.0, 0.0))
    for k, m in enumerate(MASSES, start=1):
        y = -SPACING * k
        p = model.add_particle(f"m{k}", mass=m, position=(0.0, y, 0.0))
        model.add_spring_damper(f"s{k}", above, (p, (0.0, y, 0.0)), stiffness=K, damping=2.0)
        above = (p, (0.0, y, 0.0))
    return model


def static_sag():
    """Closed-form downward displacement [m] of each mass at equilibrium."""
    below = [sum(MASSES[k:]) for k in range(len(MASSES))]
    out, total = [], 0.0
    for w in below:
        total += w * G / K
        out.append(total)
    return out


if __name__ == "__main__":
    eq = mb.equilibrium(build())
    print("sag [m]:", [float(-eq.position(f"m{k}")[0, 1] - 0.25 * k) for k in (1, 2, 3)], "closed form:", static_sag())
