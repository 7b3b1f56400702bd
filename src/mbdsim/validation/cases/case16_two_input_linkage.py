"""Case 16: two-input linkage (slider A and crank OC), angular velocity of link BC.

Meriam & Kraige 7th ed., p.405, Problem 5/195.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); the compared quantity is in rad/s.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
V_A = 1.2                     # slider A speed [m/s], to the right
OMEGA_OC = 2.0                # crank OC [rad/s], clockwise
OC, BC, AB = 0.3, 0.4, 0.5    # link lengths used by the derivation [m] (3-4-5 triangle A-C-B)

MANUAL = {"omega_BC": (2.0, 2.0)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=16,
    slug="two_input_linkage",
    title="Linkage driven by a slider and a crank: angular velocity of BC",
    reference="Meriam & Kraige, Dynamics 7th ed., p.405, Problem 5/195",
    analysis="kinematics",
    statement=(
        "Slider A moves to the right at 1.2 m/s while the crank OC (0.3 m, vertical) turns "
        "clockwise at 2 rad/s. Link AB (0.5 m) joins A to B and link BC (0.4 m, horizontal) joins "
        "B to C. Find the angular velocity of BC at the instant shown."
    ),
    reconstruction=(
        "* From the derivation: v_C = -2 k x 0.3 j = 0.6 i, so C = (0, 0.3) above the crank pivot "
        "O = (0, 0); v_B = 0.6 i + 0.8 j and v_B/C = 0.8 j, so BC is horizontal; v_B/A = v_B - v_A "
        "= -0.6 i + 0.8 j (magnitude 1.0) is normal to AB, so AB has direction (0.8, 0.6): tan theta "
        "= 3/4 and sin theta = 3/5 are the slope of AB, the triangle A-C-B is the 3-4-5 triangle "
        "with AC = 0.3 vertical, BC = 0.4, AB = 0.5.\n"
        "* Two placements fit these velocities: B = (0.4, 0.3) with A = (0, 0) (A slides along "
        "the line through O) or its mirror B = (-0.4, 0.3), A = (0, 0.6). The first makes "
        "omega_BC = +2 rad/s (counter-clockwise), the sign RecurDyn's Z component shows; it is "
        "used here. The second gives -2 rad/s; the magnitude is the same.\n"
        "* Check: v_B/C = (1.2 - 0.6)/(3/4) = 0.8 (0.8), omega_BC = 0.8/0.4 = 2 (2); "
        "v_B/A = 0.6/(3/5) = 1.0 (1.0), omega_AB = 1.0/0.5 = 2 (2).\n"
        "* Model (two degrees of freedom, both driven): crank OC, links BC and AB, slider A "
        "(nominal masses); revolutes at O (axis -z, driven 2 t), C, B, A and a translational joint "
        "of the slider along x (driven 1.2 t). The run covers 0.2 s and the rate is read at the "
        "instant shown, t = 0."
    ),
    discrepancies=[
        "The heading 'The Angular Acceleration of Link AB' is mislabelled: it computes the angular "
        "velocity omega_AB = 2 rad/s.",
        "'Initial velocity v_A' in the given data is the slider's (constant) speed at the instant "
        "considered, not an initial condition of a dynamic problem.",
    ],
    notes=["Exact rigid-body kinematics; no approximation."],
)


def geometry():
    """O, C, B, A [m] in ground at the instant shown."""
    O = np.zeros(3)
    C = np.array([0.0, OC, 0.0])
    B = C + np.array([BC, 0.0, 0.0])
    A = B - AB * np.array([BC, OC, 0.0]) / np.hypot(BC, OC)
    return O, C, B, A


def theory() -> dict:
    """The manual's velocity-triangle solution in full precision [rad/s], counter-clockwise positive."""
    O, C, B, A = geometry()
    tan_theta = (B[1] - A[1]) / (B[0] - A[0])     # 3/4
    v_C = OMEGA_OC * OC
    v_BC = (V_A - v_C) / tan_theta
    return {"omega_BC": float(v_BC / BC)}


def build_model():
    """The linkage at the instant shown with both inputs driven."""
    import mbdsim as mb

    O, C, B, A = geometry()
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    ang = lambda p, q: np.arctan2(q[1] - p[1], q[0] - p[0])
    model = mb.Model("case16_two_input", gravity=(0.0, 0.0, 0.0))
    links = {}
    for name, p, q in (("crank_OC", O, C), ("link_BC", C, B), ("link_AB", A, B)):
        ln = float(np.linalg.norm(q - p))
        links[name] = model.add_body(name, mass=1.0, inertia=(1e-5, ln**2 / 12, ln**2 / 12),
                                     position=(p + q) / 2, orientation=rz(ang(p, q)))
    slider = model.add_body("slider_A", mass=0.5, inertia=(1e-4, 1e-4, 1e-4), position=A)
    g = model.ground
    model.add_revolute("rev_O", g, links["crank_OC"], point=O, axis=(0, 0, -1))
    model.add_revolute("rev_C", links["crank_OC"], links["link_BC"], point=C, axis=(0, 0, 1))
    model.add_revolute("rev_B", links["link_BC"], links["link_AB"], point=B, axis=(0, 0, 1))
    model.add_revolute("rev_A", links["link_AB"], slider, point=A, axis=(0, 0, 1))
    model.add_translational("slide_A", g, slider, point=A, axis=(1, 0, 0))
    model.add_motion("crank_drive", "rev_O", displacement="2*t")
    model.add_motion("slider_drive", "slide_A", displacement="1.2*t")
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    bc = model.bodies["link_BC"]
    res = mb.kinematics(model, end_time=0.2, output_step=0.002)
    w = float(res.at(0.0).angular_velocity(bc)[0, 2])
    th = theory()
    q = [Quantity("omega_BC", "rad/s", th["omega_BC"], *MANUAL["omega_BC"], w,
                  note="z component at the instant shown (counter-clockwise)")]
    plots = [Plot("Angular velocity (Z) of BC", res.time, res.angular_velocity(bc)[:, 2],
                  "time [s]", "omega_BC [rad/s]", mark=(0.0, w), mark_label="instant shown")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
