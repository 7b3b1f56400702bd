"""Slider-crank: crank 0.2 m driven at one revolution per second, rod 0.4 m, slider on x.

Slider position x = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)).  Same model as slider_crank.yaml.
Run: python examples/slider_crank.py
"""
import mbdsim as mb

R, L = 0.2, 0.4


def build() -> mb.Model:
    """Crank about z at the origin, rod to the slider at x = 0.6 m, slider on a translational joint along x."""
    model = mb.Model("slider_crank", gravity=(0, -9.81, 0), planar=True)   # 2D: no redundancy warning
    crank = model.add_body("crank", mass=1.0, inertia=(1.0e-4, 0.00343, 0.00343), position=(0.1, 0, 0))
    rod = model.add_body("rod", mass=2.0, inertia=(2.0e-4, 0.0267, 0.0267), position=(0.4, 0, 0))
    slider = model.add_body("slider", mass=1.5, inertia=(1.0e-3, 1.0e-3, 1.0e-3), position=(0.6, 0, 0))
    model.add_revolute("crank_pin", model.ground, crank, point=(0, 0, 0), axis=(0, 0, 1))
    model.add_revolute("crank_rod", crank, rod, point=(0.2, 0, 0), axis=(0, 0, 1))
    model.add_revolute("rod_slider", rod, slider, point=(0.6, 0, 0), axis=(0, 0, 1))
    model.add_translational("slide", model.ground, slider, point=(0.6, 0, 0), axis=(1, 0, 0))
    model.add_motion("drive", "crank_pin", displacement="2*pi*t")
    return model


if __name__ == "__main__":
    res = mb.kinematics(build(), end_time=1.0, output_step=0.01)
    print("slider travel [m]:", res.joint_coordinate("slide").min(), "..", res.joint_coordinate("slide").max())
