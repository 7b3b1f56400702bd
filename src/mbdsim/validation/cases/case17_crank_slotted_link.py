"""Case 17: crank OA driving the slotted link CB; angular velocity of CB and speed of its end B.

Meriam & Kraige 7th ed., p.405, Problem 5/198.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); compared quantities in rad/s and m/s.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.cases._common import one_revolution
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
OMEGA_OA = 3.0                # crank OA [rad/s], constant
THETA = np.radians(30.0)      # crank angle to the horizontal (OC vertical)
OA, OC, BC = 0.1, 0.3, 0.5    # crank, pivot distance, slotted link C->B [m] (derivation)

MANUAL = {"omega_BC": (0.576, 0.577), "v_B": (0.288, 0.286)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=17,
    slug="crank_slotted_link",
    title="Crank and slotted link: angular velocity of CB and speed of B",
    reference="Meriam & Kraige, Dynamics 7th ed., p.405, Problem 5/198",
    analysis="kinematics",
    statement=(
        "The crank OA (0.1 m) turns at a constant 3 rad/s; its pin A slides in the slot of the link "
        "CB, pivoted at C, 0.3 m from O on the vertical through O. For theta = 30 deg (crank to the "
        "horizontal, angle AOC = 120 deg) find the angular velocity of CB and the speed of its end "
        "B, 0.5 m from C."
    ),
    reconstruction=(
        "* Ground frame: O at the origin, C = (0, -0.3) directly below O, A = 0.1(cos 30, sin 30) "
        "so that the angle AOC = 90 + 30 = 120 deg as in the manual's law of cosines. The slotted "
        "link is straight along C->A; B is on it at 0.5 m from C (v_B = omega_BC * 0.5).\n"
        "* The crank turns counter-clockwise, which makes CB turn counter-clockwise (+z), the sign "
        "RecurDyn's Z value shows.\n"
        "* Check: CA^2 = 0.09 + 0.01 - 2(0.03) cos 120 = 0.13 (0.13), CA = 0.360555 (0.361); "
        "beta = asin(0.1 sin 120/CA) = 13.898 deg (printed 13.88), gamma = 46.102 deg (46.12); "
        "v_A = 0.3 m/s; omega_BC = 0.3 cos gamma/CA = 0.576923 (0.576) = 3*0.1(0.1 - 0.3 cos 120)/0.13 "
        "exactly 7.5/13; v_B = 0.288462 (0.288).\n"
        "* Model: crank, slotted link and a slider block at A (nominal masses); revolutes at O "
        "(axis z, driven 3 t), C and crank-block at A, translational joint block-link along C->A. "
        "The crank turns fully (0.1 < 0.3); the values are read one revolution after the start "
        "(driven coordinate = 2 pi), i.e. again at theta = 30 deg."
    ),
    discrepancies=[
        "beta = asin(0.1 sin 120/0.361) is 13.90 deg, not 13.88 deg; hence gamma = 46.10 deg, not "
        "46.12 deg.",
        "Rounded theory: omega_BC = 0.576923 rad/s (0.577), not 0.576 (the slip above and CA = 0.361 "
        "lower it); RecurDyn's 0.577 is within 0.013 % (printed error 0.174 % is an artefact). "
        "v_B = 0.288462 m/s; RecurDyn's 0.286 is 0.85 % off (printed 0.694 %).",
        "Unit slip: v_A = omega_OA * OA = 0.3 is in m/s, printed 'rad/s'.",
        "The plot description says 'acceleration in the Z direction of CB', but the compared "
        "quantity is the angular velocity of CB.",
    ],
    notes=["Exact rigid-body kinematics with the prescribed constant crank speed; no approximation."],
)


def geometry(theta: float = THETA):
    """O, C, A, B [m] in ground for crank angle theta above the horizontal."""
    O = np.zeros(3)
    C = np.array([0.0, -OC, 0.0])
    A = OA * np.array([np.cos(theta), np.sin(theta), 0.0])
    u = (A - C) / np.linalg.norm(A - C)
    return O, C, A, C + BC * u


def theory() -> dict:
    """The manual's law-of-cosines / law-of-sines solution in full precision."""
    aoc = np.pi / 2 + THETA                                   # 120 deg
    CA = np.sqrt(OC**2 + OA**2 - 2 * OA * OC * np.cos(aoc))
    beta = np.arcsin(OA / CA * np.sin(aoc))
    gamma = np.pi - aoc - beta
    v_A = OMEGA_OA * OA
    w_BC = v_A * np.cos(gamma) / CA
    return {"omega_BC": float(w_BC), "v_B": float(w_BC * BC)}


def build_model(theta0: float = THETA):
    """Crank + slotted link at crank angle theta0, crank driven counter-clockwise at OMEGA_OA."""
    import mbdsim as mb

    O, C, A, B = geometry(theta0)
    u = (B - C) / BC
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    phi = np.arctan2(u[1], u[0])
    model = mb.Model("case17_slotted_link", gravity=(0.0, 0.0, 0.0))
    crank = model.add_body("crank_OA", mass=0.5, inertia=(1e-5, 5e-4, 5e-4), position=(O + A) / 2,
                           orientation=rz(theta0))
    link = model.add_body("link_CB", mass=1.0, inertia=(1e-5, BC**2 / 12, BC**2 / 12),
                          position=(C + B) / 2, orientation=rz(phi))
    block = model.add_body("block_A", mass=0.1, inertia=(1e-5, 1e-5, 1e-5), position=A, orientation=rz(phi))
    model.add_revolute("rev_O", model.ground, crank, point=O, axis=(0, 0, 1))
    model.add_revolute("rev_C", model.ground, link, point=C, axis=(0, 0, 1))
    model.add_revolute("rev_A", crank, block, point=A, axis=(0, 0, 1))
    model.add_translational("slot", link, block, point=A, axis=u)
    model.add_motion("crank_drive", "rev_O", displacement="3*t")
    return model


def run() -> CaseOutcome:
    O, C, A, B = geometry()
    model = build_model()
    link, crank_joint = model.bodies["link_CB"], model.joints["rev_O"]
    mB = link.add_marker("B", point=B)          # end B of the link
    res, t30 = one_revolution(model, crank_joint, OMEGA_OA)
    at = res.at(t30)
    w = float(at.angular_velocity(link)[0, 2])
    v_B = float(np.linalg.norm(at.velocity(mB)[0]))
    th = theory()
    q = [
        Quantity("omega_BC", "rad/s", th["omega_BC"], *MANUAL["omega_BC"], w,
                 note="z component at theta = 30 deg"),
        Quantity("v_B", "m/s", th["v_B"], *MANUAL["v_B"], v_B, note="speed of B at theta = 30 deg"),
    ]
    plots = [
        Plot("Angular velocity (Z) of CB", res.time, res.angular_velocity(link)[:, 2], "time [s]",
             "omega_BC [rad/s]", mark=(t30, w), mark_label="theta = 30 deg"),
        Plot("Speed of B", res.time, np.linalg.norm(res.velocity(mB), axis=1), "time [s]",
             "v_B [m/s]", mark=(t30, v_B), mark_label="theta = 30 deg"),
    ]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
