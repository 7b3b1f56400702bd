"""Case 24: bar AB driven by a crank OA at constant speed, roller B on a horizontal floor, normal force at B.

Meriam & Kraige 7th ed., p.454, P6/92.  Planar, fully driven (kinematics with reactions from the
equations of motion) in the ground x-y plane, z out of the plane, gravity (0, -9.81, 0).
Units: SI (m, kg, s, rad, N); table unit N.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
G = 9.81
MASS = 10.0          # uniform slender bar AB [kg]
OMEGA0 = 4.5         # constant crank speed [rad/s]
OA = 0.4             # crank [m]
AB = 1.0             # bar [m]
BX, BY = 0.6, 0.8    # horizontal and vertical projections of AB (tan = 3/4) [m]

# printed in the manual's comparison table: (theory, RecurDyn)
MANUAL = {"N_B": (36.38, 36.38)}

CASE = CaseInfo(
    number=24,
    slug="crank_driven_bar_roller",
    title="Bar driven by a crank with its lower end on a roller: normal force at the roller",
    reference="Meriam & Kraige, Dynamics 7th ed., p.454, P6/92",
    analysis="kinematics (fully driven) with reaction forces",
    statement=(
        "The uniform 10-kg bar AB (1.0 m) is pinned at A to the crank OA (0.4 m), which turns at "
        "the constant rate omega0 = 4.5 rad/s in the vertical plane; the end B carries a small "
        "roller on a horizontal surface. For the position where OA is horizontal and the bar "
        "makes the 3-4-5 slope (0.6 m across, 0.8 m down from A to B), find the normal force "
        "N_B under the roller."
    ),
    reconstruction=(
        "* Ground frame: A = (0, 0.8), O = A + (0.4, 0) = (0.4, 0.8) (crank horizontal, O to the "
        "right of A so that a_A = 0.4*4.5^2 = 8.1 m/s^2 points along +x), B = (0.6, 0) on the "
        "floor y = 0; G = (0.3, 0.4).\n"
        "* Consistency: v_A = 1.8 m/s is vertical and v_B horizontal, so omega_AB*0.6 = 1.8 gives "
        "omega_AB = 3 rad/s (the given value); the vertical component of a_B vanishes: "
        "3^2*0.8 = alpha*0.6, alpha = 12 rad/s^2 (the manual's tan = (a_B/A)_n/(a_B/A)_t = 3/4 "
        "with 9 and 12 m/s^2). Moment arms about A: mg 0.3 (half of 0.6), N_B 0.6, m a_A 0.4 "
        "(half of 0.8), m(a_G/A)_t 0.5; (a_G/A)_n passes through A. That is the printed "
        "equation: N_B = (29.43 - (10 + 30 - 32.4))/0.6 = 36.383 N.\n"
        "* The crank turns counter-clockwise (A moving down, omega_AB = +3 rad/s, B moving to "
        "+x); the sense does not enter N_B.\n"
        "* Model: crank (nominal 1 kg, driven), bar AB (10 kg, I_G = m l^2/12), roller B as a "
        "massless body; revolutes O (ground-crank), A (crank-bar), B (bar-roller), translational "
        "joint roller-ground along x; motion 4.5 t on O. mb.kinematics from this position, N_B "
        "read at t = 0 as the y component of the floor's reaction on the roller."
    ),
    discrepancies=[
        "(a_G/A)_t = r alpha_AB = 6 is printed with unit rad/s^2; it is 6 m/s^2.",
        "The section titled 'The Equation of Relative Velocity' is the relative-acceleration "
        "equation.",
    ],
    notes=[
        "The derivation is exact for the stated constant crank speed and a massless roller "
        "(the crank's mass does not enter: the crank is driven). No variant.",
    ],
)


def theory() -> dict:
    """The manual's moment equation about A in full precision: N_B [N]."""
    a_A = OA * OMEGA0**2                                      # crank at constant speed
    w_AB = OA * OMEGA0 / BX                                   # from v_B horizontal
    a_BA_n = AB * w_AB**2
    a_BA_t = a_BA_n / (BX / BY)                               # tan = (a_B/A)_n / (a_B/A)_t = 3/4
    alpha = a_BA_t / AB
    a_GA_t = AB / 2 * alpha
    I_G = MASS * AB**2 / 12
    rhs = I_G * alpha + MASS * a_GA_t * AB / 2 - MASS * a_A * BY / 2
    N_B = (MASS * G * BX / 2 - rhs) / BX
    return {"N_B": float(N_B), "alpha_AB": float(alpha), "omega_AB": float(w_AB)}


def build_model():
    """Crank horizontal, bar at 3-4-5 slope, crank driven counter-clockwise at OMEGA0."""
    import mbdsim as mb

    model = mb.Model("case24_crank_bar_roller", gravity=(0.0, -G, 0.0))
    A, B = np.array([0.0, BY, 0.0]), np.array([BX, 0.0, 0.0])
    O = A + np.array([OA, 0.0, 0.0])
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    crank = model.add_body("crank", mass=1.0, inertia=(1e-4, 1.0 * OA**2 / 12, 1.0 * OA**2 / 12),
                           position=(O + A) / 2, orientation=rz(np.pi))
    bar = model.add_body("bar_AB", mass=MASS, inertia=(1e-4, MASS * AB**2 / 12, MASS * AB**2 / 12),
                         position=(A + B) / 2, orientation=rz(np.arctan2(-BY, BX)))
    roller = model.add_body("roller_B", mass=0.0, inertia=(0.0, 0.0, 0.0), position=B)
    z = (0.0, 0.0, 1.0)
    model.add_revolute("rev_O", model.ground, crank, point=O, axis=z)
    model.add_revolute("rev_A", crank, bar, point=A, axis=z)
    model.add_revolute("rev_B", bar, roller, point=B, axis=z)
    model.add_translational("floor", model.ground, roller, point=B, axis=(1.0, 0.0, 0.0))
    model.add_motion("crank_drive", "rev_O", displacement=f"{OMEGA0}*t")
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    roller, floor = model.bodies["roller_B"], model.joints["floor"]
    res = mb.kinematics(model, 0.4, 0.004)
    N_B = float(res.at(0.0).reaction_force(floor, on=roller)[0, 1])
    th = theory()
    q = [Quantity("N_B", "N", th["N_B"], *MANUAL["N_B"], N_B,
                  note="vertical force of the floor on roller B with OA horizontal (t = 0)")]
    crank_deg = np.degrees(res.joint_coordinate(model.joints["rev_O"]))
    plots = [Plot("Normal force on roller B", crank_deg, res.reaction_force(floor, on=roller)[:, 1],
                  "crank rotation from OA horizontal [deg]", "N_B [N]", mark=(0.0, N_B),
                  mark_label="OA horizontal")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
