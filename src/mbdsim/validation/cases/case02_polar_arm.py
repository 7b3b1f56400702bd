"""Case 2: point B on a rotating, retracting arm in polar coordinates (Meriam & Kraige 7th ed., P2.136).

Planar, in the ground x-y plane: the arm turns about the ground z axis through O (origin), B slides
along it.  Kinematic analysis; SI units (m, s, rad), results converted to the table units m/s, m/s^2.
"""
from __future__ import annotations

import numpy as np

import mbdsim as mb
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

R0 = 0.500                  # [m] r at the instant considered
R_DOT = -0.150              # [m/s] constant (r_ddot = 0)
THETA_DOT = np.pi / 3.0     # [rad/s] = 60 deg/s, constant (theta_ddot = 0)

MANUAL = {                  # name -> (unit, manual theory, manual RecurDyn)
    "v": ("m/s", 0.5447, 0.5447),
    "a": ("m/s^2", 0.63193, 0.63193),
}

CASE = CaseInfo(
    number=2,
    slug="polar_arm",
    title="Velocity and acceleration of a point on a rotating telescoping arm (polar coordinates)",
    reference="Meriam & Kraige, Dynamics 7th ed., p.72, P2.136",
    analysis="kinematics (particle, polar coordinates)",
    statement=(
        "Point B moves along an arm that rotates about the fixed point O with the constant rate "
        "theta_dot = 60 deg/s, while its distance r = OB decreases at the constant rate 150 mm/s. "
        "At the instant r = 500 mm, find the magnitudes of the velocity and acceleration of B."
    ),
    reconstruction=(
        "O at the origin, the arm along +x at t = 0, rotating counter-clockwise about +z with "
        "theta = (pi/3) t; B a particle on the arm with r = 0.5 - 0.15 t [m] (translational joint "
        "arm-B, driven). r_ddot = 0 and theta_ddot = 0 (both rates constant).\n\n"
        "Consistency: v_theta = 500*pi/3 = 523.6 mm/s, v = sqrt(150^2 + 523.6^2) = 544.7 mm/s; "
        "a_r = 0 - 500*(pi/3)^2 = -548.31 mm/s^2 (so r_ddot = 0), a_theta = 0 + 2*(-150)*(pi/3) = "
        "-314.16 mm/s^2 (so theta_ddot = 0), a = 631.93 mm/s^2: every printed number follows."
    ),
    discrepancies=[
        "The note's second unit-vector derivative is printed 'e_theta = -theta_dot e_r'; it is "
        "d(e_theta)/dt = -theta_dot e_r.",
        "Given-data table: a 'decreasing rate' of -150 mm/s (double negative); r decreases at 150 mm/s, "
        "r_dot = -150 mm/s as used.",
        "Error column recomputed against the full-precision theory v = 0.5446611 m/s, "
        "a = 0.6319346 m/s^2: RecurDyn's 0.5447 is 0.0071 % off and 0.63193 is 0.0007 % off "
        "(printed 0 % for both, i.e. equal after rounding).",
    ],
    notes=["The derivation is exact for the prescribed motion (both rates constant)."],
)


def theory() -> dict[str, float]:
    """|v| [m/s] and |a| [m/s^2] of B from v = r_dot e_r + r theta_dot e_theta and
    a = (r_ddot - r theta_dot^2) e_r + (r theta_ddot + 2 r_dot theta_dot) e_theta."""
    r_ddot, theta_ddot = 0.0, 0.0
    v_r, v_t = R_DOT, R0 * THETA_DOT
    a_r = r_ddot - R0 * THETA_DOT**2
    a_t = R0 * theta_ddot + 2.0 * R_DOT * THETA_DOT
    return {"v": float(np.hypot(v_r, v_t)), "a": float(np.hypot(a_r, a_t))}


def build_model():
    """Arm (revolute about z at O, driven) and particle B (translational along the arm, driven)."""
    model = mb.Model("polar_arm", gravity=(0.0, 0.0, 0.0))
    arm = model.add_body("arm", mass=1.0, inertia=(1e-3, 0.1, 0.1), position=(0.4, 0.0, 0.0))
    b = model.add_particle("B", mass=0.1, position=(R0, 0.0, 0.0))
    pivot = model.add_revolute("pivot", model.ground, arm, point=(0, 0, 0), axis=(0, 0, 1))
    slide = model.add_translational("slide", arm, b, point=(R0, 0, 0), axis=(1, 0, 0))
    model.add_motion("theta", pivot, displacement="pi/3*t")     # = THETA_DOT*t
    model.add_motion("r", slide, displacement="-0.15*t")        # r - r0 = R_DOT*t along +x
    return model, b


def run() -> CaseOutcome:
    model, b = build_model()
    res = mb.kinematics(model, 2.0, 0.01)
    now = res.at(0.0)                        # the instant r = 500 mm
    measured = {"v": float(np.linalg.norm(now.velocity(b)[0])),
                "a": float(np.linalg.norm(now.acceleration(b)[0]))}
    th = theory()
    quantities = [Quantity(n, u, theory=th[n], manual_theory=mt, manual_commercial=mc, mbdsim=measured[n])
                  for n, (u, mt, mc) in MANUAL.items()]
    speed = np.linalg.norm(res.velocity(b), axis=1)
    accel = np.linalg.norm(res.acceleration(b), axis=1)
    plots = [
        Plot("Velocity of point B", res.time, speed, "t [s]", "|v_B| [m/s]",
             mark=(0.0, measured["v"]), mark_label=f"r = 500 mm: {measured['v']:.6f} m/s"),
        Plot("Acceleration of point B", res.time, accel, "t [s]", "|a_B| [m/s^2]",
             mark=(0.0, measured["a"]), mark_label=f"r = 500 mm: {measured['a']:.6f} m/s^2"),
    ]
    return CaseOutcome(info=CASE, quantities=quantities, model=model, result=res, plots=plots)
