"""Case 15: four-bar linkage, angular velocities of the coupler AB and the rocker AC.

Meriam & Kraige 7th ed., p.361, Problem 5/89.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); compared quantities in rad/s, clockwise positive
as in the manual.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
OMEGA_OB = 0.5                # crank OB [rad/s], clockwise
TAN_THETA = 4.0 / 3.0         # slope of the rocker CA
OB = 0.12                     # crank length [m] (derivation)
CA = 0.20                     # rocker length [m]: C->A = (-0.12, 0.16) in the derivation
BA = np.array([-0.24, 0.04])  # B->A at the instant shown [m] (derivation)

MANUAL = {"omega_AB": (0.214, 0.214), "omega_AC": (0.429, 0.429)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=15,
    slug="four_bar_ic",
    title="Four-bar linkage: angular velocities of AB and AC",
    reference="Meriam & Kraige, Dynamics 7th ed., p.361, Problem 5/89",
    analysis="kinematics",
    statement=(
        "In the four-bar linkage O-B-A-C the crank OB (vertical, 0.12 m) turns clockwise at "
        "0.5 rad/s. The rocker CA (tan theta = 4/3) and the coupler BA connect it to the fixed "
        "pivot C. Find the angular velocities of AB and AC at the instant shown."
    ),
    reconstruction=(
        "* From the derivation's vectors: O = (0, 0), B = (0, 0.12) (r_OB = 0.12 j), A = B + "
        "(-0.24, 0.04) = (-0.24, 0.16), C = A - (-0.12, 0.16) = (-0.12, 0): ground link OC = 0.12 m, "
        "coupler BA = 0.24331 m, rocker CA = 0.2 m at tan theta = 0.16/0.12 = 4/3 to the horizontal.\n"
        "* Check: v_B = 0.5*0.12 = 0.06 i; i: 0.16 w_AC = 0.06 + 0.04 w_AB, j: 0.12 w_AC = 0.24 w_AB "
        "give w_AB = 0.06/0.28 = 3/14 = 0.2142857 (0.214), w_AC = 3/7 = 0.4285714 (0.429), both "
        "clockwise (the manual writes every rotation as -w k).\n"
        "* Model: crank, coupler and rocker bodies (nominal masses), four revolutes about z (a "
        "planar four-bar in 3D: the engine reports and handles the redundant constraints), the "
        "crank revolute's axis -z, driven 0.5 t. The linkage is non-Grashof (0.12 + 0.2433 > "
        "0.12 + 0.2), so the crank cannot turn fully; the run covers 0.5 s and the rates are read "
        "at the instant shown, t = 0, as minus the z components (clockwise positive)."
    ),
    discrepancies=[
        "The section 'Calculate the Accelerations of the Link AB and the Link AC' and its "
        "'a_A = a_B + a_A/B' are mislabelled: the equations solved are the relative-velocity "
        "equation v_A = v_B + v_A/B.",
        "The table gives magnitudes; both links turn clockwise, so their Z components are "
        "-0.2143 and -0.4286 rad/s.",
    ],
    notes=["Exact rigid-body kinematics; no approximation."],
)


def geometry():
    """O, B, A, C [m] in ground at the instant shown."""
    O = np.zeros(3)
    B = np.array([0.0, OB, 0.0])
    A = B + np.array([BA[0], BA[1], 0.0])
    C = A - CA * np.array([-1.0, TAN_THETA, 0.0]) / np.hypot(1.0, TAN_THETA)
    return O, B, A, C


def theory() -> dict:
    """Relative-velocity equation v_A = v_B + v_A/B solved as a 2x2 system, clockwise positive [rad/s]."""
    O, B, A, C = geometry()
    cw = lambda w, r: w * np.array([r[1], -r[0]])      # (-w k) x r
    v_B = cw(OMEGA_OB, B - O)
    # cw(w_AC, A - C) = v_B + cw(w_AB, A - B)  ->  linear in (w_AB, w_AC)
    M = np.column_stack([-cw(1.0, A - B)[:2], cw(1.0, A - C)[:2]])
    w_AB, w_AC = np.linalg.solve(M, v_B[:2])
    return {"omega_AB": float(w_AB), "omega_AC": float(w_AC)}


def build_model():
    """The four-bar at the instant shown, crank driven clockwise at OMEGA_OB."""
    import mbdsim as mb

    O, B, A, C = geometry()
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    ang = lambda p, q: np.arctan2(q[1] - p[1], q[0] - p[0])
    model = mb.Model("case15_four_bar", gravity=(0.0, 0.0, 0.0))
    bodies = {}
    for name, p, q in (("crank_OB", O, B), ("coupler_AB", B, A), ("rocker_AC", C, A)):
        ln = float(np.linalg.norm(q - p))
        bodies[name] = model.add_body(name, mass=1.0, inertia=(1e-5, ln**2 / 12, ln**2 / 12),
                                      position=(p + q) / 2, orientation=rz(ang(p, q)))
    g = model.ground
    model.add_revolute("rev_O", g, bodies["crank_OB"], point=O, axis=(0, 0, -1))
    model.add_revolute("rev_B", bodies["crank_OB"], bodies["coupler_AB"], point=B, axis=(0, 0, 1))
    model.add_revolute("rev_A", bodies["coupler_AB"], bodies["rocker_AC"], point=A, axis=(0, 0, 1))
    model.add_revolute("rev_C", g, bodies["rocker_AC"], point=C, axis=(0, 0, 1))
    model.add_motion("crank_drive", "rev_O", displacement="0.5*t")
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    ab, ac = model.bodies["coupler_AB"], model.bodies["rocker_AC"]
    res = mb.kinematics(model, end_time=0.5, output_step=0.005)
    at = res.at(0.0)
    w_AB = float(-at.angular_velocity(ab)[0, 2])
    w_AC = float(-at.angular_velocity(ac)[0, 2])
    th = theory()
    q = [
        Quantity("omega_AB", "rad/s", th["omega_AB"], *MANUAL["omega_AB"], w_AB,
                 note="clockwise positive (= -omega_z), at the instant shown"),
        Quantity("omega_AC", "rad/s", th["omega_AC"], *MANUAL["omega_AC"], w_AC,
                 note="clockwise positive (= -omega_z), at the instant shown"),
    ]
    plots = [Plot("Angular velocities (Z) of AB and AC", res.time,
                  {"AB": res.angular_velocity(ab)[:, 2], "AC": res.angular_velocity(ac)[:, 2]},
                  "time [s]", "omega_z [rad/s]", mark=(0.0, -w_AC), mark_label="AC at the instant shown")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
