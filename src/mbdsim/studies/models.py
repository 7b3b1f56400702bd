"""Model factories for studies and benchmarks (importable by Dask workers, unlike a test module)."""
from __future__ import annotations

import math

__all__ = ["slider_crank"]


def slider_crank(crank: float = 0.2, rod: float = 0.4, crank_mass: float = 1.0, rod_mass: float = 2.0,
                 slider_mass: float = 1.5, speed: float = 2 * math.pi, gravity: float = 9.81):
    """The slider-crank of examples/slider_crank.yaml with its dimensions as arguments.

    crank, rod: lengths [m] (drawn along +x, crank at theta = 0); masses [kg] (slender rods: inertia
    m L^2 / 12 about their y and z axes); speed: the crank's drive rate [rad/s] (theta = speed * t);
    gravity [m/s^2] along -y.  A rod shorter than the crank cannot turn through a revolution (lock-up)."""
    import mbdsim as mb
    model = mb.Model("slider_crank", gravity=(0, -gravity, 0))
    c = model.add_body("crank", mass=crank_mass, inertia=(1e-4, crank_mass * crank**2 / 12, crank_mass * crank**2 / 12),
                       position=(crank / 2, 0, 0))
    r = model.add_body("rod", mass=rod_mass, inertia=(2e-4, rod_mass * rod**2 / 12, rod_mass * rod**2 / 12),
                       position=(crank + rod / 2, 0, 0))
    s = model.add_body("slider", mass=slider_mass, inertia=(1e-3, 1e-3, 1e-3), position=(crank + rod, 0, 0))
    model.add_revolute("crank_pin", model.ground, c, point=(0, 0, 0), axis=(0, 0, 1))
    model.add_revolute("crank_rod", c, r, point=(crank, 0, 0), axis=(0, 0, 1))
    model.add_revolute("rod_slider", r, s, point=(crank + rod, 0, 0), axis=(0, 0, 1))
    model.add_translational("slide", model.ground, s, point=(crank + rod, 0, 0), axis=(1, 0, 0))
    model.add_motion("drive", "crank_pin", displacement=f"{speed!r}*t")
    return model
