"""Crank-rocker four-bar (Grashof: s + l <= p + q with the crank the shortest link), crank driven one turn.

Ground pivots O2 = (0, 0), O4 = (0.4, 0); crank O2-A, coupler A-B, rocker B-O4, all in the x-y plane at
t = 0 with A = (0, 0.1), B = (0.3, 0.4).  The rocker angle follows from closing the loop (two circles'
intersection), see tests/test_examples.py.  Same model as four_bar.yaml.  Run: python examples/four_bar.py
"""
import math

from scipy.spatial.transform import Rotation

import mbdsim as mb

O2, A, B, O4 = (0.0, 0.0, 0.0), (0.0, 0.1, 0.0), (0.3, 0.4, 0.0), (0.4, 0.0, 0.0)


def _about_z(angle: float) -> Rotation:
    return Rotation.from_rotvec((0.0, 0.0, angle))


def build() -> mb.Model:
    """Three moving links on revolute joints about z; the crank turns at 1 rev/s."""
    model = mb.Model("four_bar", gravity=(0, -9.81, 0), planar=True)   # 2D: no redundancy warning
    # each link's body x axis runs along the link (its long axis): O2 -> A, A -> B, B -> O4
    crank = model.add_body("crank", mass=0.5, inertia=(1.0e-4, 5.0e-4, 5.0e-4), position=(0.0, 0.05, 0.0),
                           orientation=_about_z(math.radians(90)))
    coupler = model.add_body("coupler", mass=1.0, inertia=(1.0e-4, 0.015, 0.015), position=(0.15, 0.25, 0.0),
                             orientation=_about_z(math.radians(45)))
    rocker = model.add_body("rocker", mass=0.8, inertia=(1.0e-4, 0.0113, 0.0113), position=(0.35, 0.2, 0.0),
                            orientation=_about_z(math.atan2(-0.4, 0.1)))
    coupler.add_marker("B", point=B)
    model.add_revolute("O2", model.ground, crank, point=O2, axis=(0, 0, 1))
    model.add_revolute("A", crank, coupler, point=A, axis=(0, 0, 1))
    model.add_revolute("B", coupler, rocker, point=B, axis=(0, 0, 1))
    model.add_revolute("O4", rocker, model.ground, point=O4, axis=(0, 0, 1))
    model.add_motion("drive", "O2", displacement="2*pi*t")
    return model


if __name__ == "__main__":
    res = mb.kinematics(build(), end_time=1.0, output_step=0.01)
    print("rocker swing [deg]:", res.joint_coordinate("O4").min() * 57.3, "..", res.joint_coordinate("O4").max() * 57.3)
