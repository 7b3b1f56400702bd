"""Heavy symmetric top (gyroscope) on a ball joint, started in steady precession.

Tilt theta from the vertical, spin s about the symmetry axis e3 plus precession Omega about z:
omega = s e3 + Omega z.  Steady precession needs m g l = Omega (I3 omega3 - I1 Omega cos(theta)),
omega3 = s + Omega cos(theta), I1 about the pivot; build() solves it for Omega.  The axis then keeps its
tilt and turns about z at Omega.  Same model as heavy_top.yaml.  Run: python examples/heavy_top.py
"""
import math

import numpy as np
from scipy.spatial.transform import Rotation

import mbdsim as mb

MASS, ARM, G = 1.0, 0.1, 9.81                 # kg, pivot to centre of mass [m], m/s^2
I_CM, I3 = 0.002, 0.004                       # transverse (about the CM) and axial moments [kg m^2]
TILT, SPIN = math.radians(30.0), 100.0        # rad, rad/s


def precession_rate() -> float:
    """Slow root Omega of I1' c Omega^2 ... : (I3 - I1) c W^2 + I3 s W - m g l = 0 with I1 = I_CM + m l^2."""
    i1, c = I_CM + MASS * ARM ** 2, math.cos(TILT)
    a, b, k = (I3 - i1) * c, I3 * SPIN, -MASS * G * ARM
    return (-b + math.sqrt(b * b - 4 * a * k)) / (2 * a)


def initial_state():
    """(CM position [m], CM velocity [m/s], angular velocity [rad/s]) in ground."""
    e3 = np.array([math.sin(TILT), 0.0, math.cos(TILT)])
    w = SPIN * e3 + precession_rate() * np.array([0.0, 0.0, 1.0])
    r = ARM * e3
    return r, np.cross(w, r), w


def build() -> mb.Model:
    """The top's body z axis is its symmetry axis, tilted by 30 deg about y; pivot at the origin."""
    r, v, w = (np.round(x, 15) for x in initial_state())
    model = mb.Model("heavy_top", gravity=(0, 0, -G))
    top = model.add_body("top", mass=MASS, inertia=(I_CM, I_CM, I3), position=r,
                         orientation=Rotation.from_rotvec([0.0, TILT, 0.0]).as_matrix(), velocity=v, angular_velocity=w)
    top.add_marker("tip", point=2 * r)
    model.add_spherical("pivot", model.ground, top, point=(0, 0, 0))
    return model


if __name__ == "__main__":
    res = mb.simulate(build(), end_time=1.0, output_step=0.01)
    tip = res.position("top.tip")
    print("precession rate:", precession_rate(), "rad/s; azimuth after 1 s:", math.atan2(tip[-1, 1], tip[-1, 0]))
