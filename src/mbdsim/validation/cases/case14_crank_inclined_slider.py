"""Case 14: crank, link and a slider on an inclined guide; speeds of the slider and the link's midpoint.

Meriam & Kraige 7th ed., p.359, Problem 5/80.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); compared quantities in m/s.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
OMEGA = 0.8                   # crank OB speed [rad/s], clockwise
L = 0.5                       # link AB [m]
R = 0.25                      # crank OB [m]
BETA = np.radians(20.0)       # inclination of the slider's guide to the horizontal

MANUAL = {"v_A": (0.2259, 0.2261), "v_C": (0.1747, 0.1746)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=14,
    slug="crank_inclined_slider",
    title="Crank, link and slider on a 20 deg guide: speeds of A and of the link midpoint C",
    reference="Meriam & Kraige, Dynamics 7th ed., p.359, Problem 5/80",
    analysis="kinematics",
    statement=(
        "The crank OB (0.25 m) turns clockwise at 0.8 rad/s and is horizontal at the instant shown. "
        "The link AB (0.5 m) connects B to the slider A, which moves on a straight guide inclined "
        "at 20 deg to the horizontal; A is directly below O. Using the instantaneous centre of "
        "zero velocity of AB find the speed of A and of the midpoint C of AB."
    ),
    reconstruction=(
        "* From v_B = -0.8 k x 0.25 i: O at the origin, B = (0.25, 0). OA = sqrt(l^2 - r^2) = 0.4330 "
        "with A = (0, -0.4330) directly below O (theta = acos(r/l) = 60 deg is the link's angle).\n"
        "* The 20 deg enters as the direction of A's guide: the IC lies on the x axis (normal to v_B) "
        "and on the normal to the guide through A, so IC = (-OA tan 20, 0) = (-0.1576, 0), "
        "IC-A = OA/cos 20 = 0.4608 (0.461), IC-B = 0.25 + 0.1576 = 0.4076 (0.408), and the manual's "
        "vector IC->A = 0.158 i - 0.433 j. The guide is the line through A with direction "
        "(cos 20, sin 20); A moves down-left at this instant (manual: v_A = -0.2122 i - 0.0774 j).\n"
        "* C is the midpoint of AB (manual: r_BC = -0.25 cos 60 i - 0.25 sin 60 j).\n"
        "* Check: omega_AB = 0.2/0.40760 = 0.490673 (0.49, clockwise); v_A = 0.490673*0.46080 = "
        "0.226103 (0.2259 with the rounded 0.49); v_C = |(-0.106234, -0.138666)| = 0.174682 (0.1747).\n"
        "* Model: crank, link (CM at C) and slider bodies (nominal masses); revolutes at O "
        "(axis -z, driven 0.8 t), B and A; translational joint of the slider along (cos 20, sin 20). "
        "The crank cannot turn fully (the link would have to stretch beyond 0.5 m), so the run "
        "covers 1 s and the speeds are read at the instant shown, t = 0."
    ),
    discrepancies=[
        "Given-data row 'OA-OB angle beta = 20 deg' is mislabelled: OA is perpendicular to OB; the "
        "20 deg is the inclination of the slider's guide (it enters as OA/cos 20 and 0.433 tan 20).",
        "Rounded theory: with omega_AB rounded to 0.49 the manual's v_A = 0.2259 m/s; the exact "
        "value is 0.226103 m/s, against which RecurDyn's 0.2261 is within 0.0014 % (printed error "
        "0.089 % is an artefact of the rounding). v_C = 0.174682 m/s: RecurDyn's 0.1746 is 0.047 % "
        "off (printed 0.057 % against the rounded 0.1747).",
        "'v_A = omega_AB x r_OA' uses the vector from the instantaneous centre to A (0.158 i - "
        "0.433 j), not r_OA.",
        "The plot description 'Measure the time when the displacement of the Slider is 1 m' belongs "
        "to another problem; the compared quantities are v_A and v_C at the instant shown.",
    ],
    notes=["Exact rigid-body kinematics (instantaneous-centre construction); no approximation."],
)


def geometry():
    """O, B, A, C [m] in ground at the instant shown, and the guide direction."""
    OA = np.sqrt(L**2 - R**2)
    O, B, A = np.zeros(3), np.array([R, 0.0, 0.0]), np.array([0.0, -OA, 0.0])
    guide = np.array([np.cos(BETA), np.sin(BETA), 0.0])
    return O, B, A, (A + B) / 2, guide


def theory() -> dict:
    """Instantaneous-centre solution in full precision [m/s]."""
    v_B = OMEGA * R
    OA = np.sqrt(L**2 - R**2)
    ic_A = OA / np.cos(BETA)
    ic_B = R + OA * np.tan(BETA)
    w_AB = v_B / ic_B                                   # clockwise
    v_A = w_AB * ic_A
    # v_C = v_B + omega_AB x r_BC with omega_AB = -w_AB k, r_BC = (A - B)/2
    r_BC = np.array([-R / 2, -OA / 2])
    v_C = np.array([0.0, -v_B]) - w_AB * np.array([-r_BC[1], r_BC[0]])
    return {"v_A": float(v_A), "v_C": float(np.hypot(*v_C))}


def build_model():
    """The mechanism at the instant shown, crank driven clockwise at OMEGA."""
    import mbdsim as mb

    O, B, A, C, guide = geometry()
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    model = mb.Model("case14_inclined_slider", gravity=(0.0, 0.0, 0.0))
    crank = model.add_body("crank", mass=0.5, inertia=(1e-5, 0.5 * R**2 / 12, 0.5 * R**2 / 12),
                           position=(O + B) / 2)
    link = model.add_body("link", mass=1.0, inertia=(1e-5, L**2 / 12, L**2 / 12), position=C,
                          orientation=rz(np.arctan2(B[1] - A[1], B[0] - A[0])))
    slider = model.add_body("slider", mass=0.5, inertia=(1e-4, 1e-4, 1e-4), position=A,
                            orientation=rz(BETA))
    model.add_revolute("rev_O", model.ground, crank, point=O, axis=(0, 0, -1))
    model.add_revolute("rev_B", crank, link, point=B, axis=(0, 0, 1))
    model.add_revolute("rev_A", link, slider, point=A, axis=(0, 0, 1))
    model.add_translational("guide_A", model.ground, slider, point=A, axis=guide)
    model.add_motion("crank_drive", "rev_O", displacement="0.8*t")
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    slider, link = model.bodies["slider"], model.bodies["link"]
    res = mb.kinematics(model, end_time=1.0, output_step=0.01)
    at = res.at(0.0)                                  # the instant shown
    v_A = float(np.linalg.norm(at.velocity(slider)[0]))
    v_C = float(np.linalg.norm(at.velocity(link)[0]))  # link CM = midpoint C
    th = theory()
    q = [
        Quantity("v_A", "m/s", th["v_A"], *MANUAL["v_A"], v_A, note="speed of slider A at t = 0"),
        Quantity("v_C", "m/s", th["v_C"], *MANUAL["v_C"], v_C, note="speed of the midpoint C at t = 0"),
    ]
    plots = [Plot("Speeds of A and C", res.time,
                  {"v_A": np.linalg.norm(res.velocity(slider), axis=1),
                   "v_C": np.linalg.norm(res.velocity(link), axis=1)},
                  "time [s]", "speed [m/s]", mark=(0.0, v_A), mark_label="v_A at the instant shown")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
