"""Case 11: slider-crank of a reciprocating engine, velocity of the connecting-rod centre of mass.

Meriam & Kraige 7th ed., p.353, Sample Problem 5/9.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); the compared quantities are in m/s and rad/s.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.cases._slider_crank import build_slider_crank
from mbdsim.validation.cases._common import one_revolution
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
OMEGA = 50.0 * np.pi          # crank speed [rad/s] = 1500 rev/min, clockwise
R = 0.125                     # crank OB [m]
L1, L2 = 0.25, 0.10           # AG and GB on the connecting rod [m]
L = L1 + L2                   # connecting rod AB [m]
THETA = np.radians(60.0)      # angle AOB at the instant considered

# printed in the manual's comparison table: (theory, RecurDyn)
MANUAL = {"v_G": (19.23, 19.24), "omega_AB": (29.5, 29.53)}

CASE = CaseInfo(
    number=11,
    slug="engine_connecting_rod",
    title="Reciprocating engine: velocity of the connecting-rod centre of mass",
    reference="Meriam & Kraige, Dynamics 7th ed., p.353, Sample Problem 5/9",
    analysis="kinematics",
    statement=(
        "The crank OB of a slider-crank (reciprocating engine) turns clockwise at a constant "
        "1500 rev/min (50*pi rad/s). OB = 125 mm, connecting rod AB = 350 mm with its centre of "
        "mass G 250 mm from the piston pin A (100 mm from the crank pin B). The piston A moves on "
        "the line through O. For the position where the angle AOB is theta = 60 deg find the "
        "speed of G and the angular velocity of the connecting rod AB."
    ),
    reconstruction=(
        "* Ground frame: crank pivot O at the origin, piston line = x axis, the piston A on the "
        "negative x side (left of O), B above the line; the crank turns clockwise, so B = "
        "r(-cos th, sin th), A = (-(r cos th + l cos b), 0) with sin b = (r/l) sin th.\n"
        "* r = OB = 0.125 m, AG = l1 = 0.25 m, GB = l2 = 0.10 m, l = AB = 0.35 m (table rows l1, l2, r); "
        "the manual's r_G/A = 0.25(cos 18.02 i + sin 18.02 j) confirms that G is 0.25 m from A.\n"
        "* Check against every number of the derivation: b = asin(0.125/0.35 sin 60) = 18.017 deg "
        "(printed 18.02), gamma = 90 - b = 71.98; v_B = 0.125*50 pi = 19.635 (19.63); "
        "v_A = 19.635 sin 78.02/sin 71.98 = 20.197 (20.19); v_A/B = 19.635 sin 30/sin 71.98 = 10.324 "
        "(10.32); omega_AB = 10.324/0.35 = 29.496 (29.49); v_G = (20.197 - 2.281) i + 7.013 j "
        "(17.91 i + 7.01 j), |v_G| = 19.240 (19.23). The clockwise crank makes omega_AB "
        "counter-clockwise (+z), as the manual's 29.49 k shows.\n"
        "* Model: crank, connecting rod and piston are rigid bodies (nominal masses; they do not "
        "affect the kinematics); revolutes at O, B, A (axis z) and a translational joint of the "
        "piston along x. The crank revolute's axis is -z so that its joint coordinate is the "
        "clockwise crank rotation, driven as 50*pi*t. The model starts at theta = 60 deg and the "
        "quantities are read where the crank angle has advanced by exactly one revolution "
        "(crossing of the driven coordinate with 2 pi), i.e. again at theta = 60 deg."
    ),
    discrepancies=[
        "Error column wrong: for v_G the printed 0.27 % should be |19.24-19.23|/19.23 = 0.052 %; "
        "for omega_AB the printed 0.346 % should be |29.53-29.5|/29.5 = 0.10 %.",
        "Rounded theory: |v_G| = 19.2401 m/s (the derivation's rounded components give 19.23); "
        "against it RecurDyn's 19.24 is within 0.001 %. omega_AB = 29.4962 rad/s (derivation "
        "29.49, table 29.5); RecurDyn's 29.53 is 0.114 % off.",
        "v_A is printed 20.19 m/s; the formula gives 20.1974 m/s (20.20).",
    ],
    notes=[
        "The derivation is exact rigid-body kinematics with the constant crank speed the problem "
        "prescribes; no approximation, so no full-physics variant.",
    ],
)


def theory() -> dict:
    """Relative-velocity solution of the manual (law of sines), in full precision."""
    beta = np.arcsin(R / L * np.sin(THETA))                 # rod angle to the piston line
    gamma = np.pi / 2 - beta
    v_B = R * OMEGA
    v_A = v_B / np.sin(gamma) * np.sin(np.pi - np.pi / 6 - gamma)   # sin 78.02 / sin 71.98
    v_AB = v_B / np.sin(gamma) * np.sin(np.pi / 6)
    omega_AB = v_AB / L
    v_G = np.array([v_A, 0.0]) + omega_AB * L1 * np.array([-np.sin(beta), np.cos(beta)])
    return {"v_G": float(np.hypot(*v_G)), "omega_AB": float(omega_AB)}


def build_model(theta0: float = THETA):
    """Engine at crank angle theta0 [rad]; rod CM G at L1 from A; crank driven clockwise at 1500 rev/min."""
    return build_slider_crank("case11_engine", R, L, theta0, "50*pi*t", masses=(1.0, 2.0, 1.5),
                              rod_cm_from_A=L1)


def run() -> CaseOutcome:
    model = build_model()
    rod, crank_joint = model.bodies["rod"], model.joints["rev_O"]
    # the instant theta = 60 deg again, one revolution after the start
    res, t60 = one_revolution(model, crank_joint, OMEGA)
    at = res.at(t60)
    v_G = float(np.linalg.norm(at.velocity(rod)[0]))
    w_AB = float(at.angular_velocity(rod)[0, 2])
    th = theory()
    q = [
        Quantity("v_G", "m/s", th["v_G"], *MANUAL["v_G"], v_G,
                 note="speed of the rod's centre of mass at theta = 60 deg"),
        Quantity("omega_AB", "rad/s", th["omega_AB"], *MANUAL["omega_AB"], w_AB,
                 note="z component (counter-clockwise positive)"),
    ]
    speed = np.linalg.norm(res.velocity(rod), axis=1)
    plots = [
        Plot("Speed of the connecting-rod CM", res.time, speed, "time [s]", "v_G [m/s]",
             mark=(t60, v_G), mark_label="theta = 60 deg"),
        Plot("Angular velocity of the connecting rod", res.time, res.angular_velocity(rod)[:, 2],
             "time [s]", "omega_AB [rad/s]", mark=(t60, w_AB), mark_label="theta = 60 deg"),
    ]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
