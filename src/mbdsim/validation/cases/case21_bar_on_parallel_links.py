"""Case 21: bar BD on two light parallel links driven by a torque, force at D and link acceleration.

Meriam & Kraige 7th ed., p.428, P6/25.  Planar dynamics in the ground x-y plane, z out of the
plane, gravity (0, -9.81, 0).  Units: SI (m, kg, s, rad, N); table units N and rad/s^2.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
G = 9.81            # [m/s^2], as in the derivation
M_BAR = 25.0        # bar BD [kg]
TORQUE = 200.0      # clockwise torque M on the lower link AB at A [N m]
OMEGA = 5.0         # angular velocity of both links at the horizontal position [rad/s]
R_LINK = 0.6        # AB = CD [m]
H_BD = 0.8          # B to D along the bar (vertical) [m]
H_BG = 0.5          # B to the centre of mass G of the bar (vertical) [m]

# printed in the manual's comparison table: (theory, RecurDyn)
MANUAL = {"R_D": (235.375, 234.375), "alpha": (5.871, 5.872)}

CASE = CaseInfo(
    number=21,
    slug="bar_on_parallel_links",
    title="Bar on two light parallel links: force at D and angular acceleration of the links",
    reference="Meriam & Kraige, Dynamics 7th ed., p.428, P6/25",
    analysis="dynamics",
    statement=(
        "The 25-kg bar BD is attached to two light links AB and CD and moves in the vertical "
        "plane. The lower link AB is driven by a clockwise torque M = 200 N m applied through its "
        "shaft at A. Each link has an angular velocity omega = 5 rad/s as it passes the "
        "horizontal position. Calculate the force which the upper link CD exerts on the bar at D "
        "at this instant, and the angular acceleration of the links."
    ),
    reconstruction=(
        "* Links AB (lower) and CD (upper), both 0.6 m (a_n = 0.6*5^2 = 15 and B_t = 200/0.6 use "
        "this length for both), horizontal at the instant considered; their fixed pivots A and C "
        "lie on one vertical line, 0.8 m apart, so ABDC is a parallelogram and the bar translates.\n"
        "* Ground frame: B = (0, 0), D = (0, 0.8), A = (0.6, 0), C = (0.6, 0.8); the bar BD is "
        "vertical with its centre of mass G = (0, 0.5), 0.5 m above B (the manual's moment arm "
        "d = 0.5), D 0.8 m above B (arm 0.8). The bar's moment of inertia does not enter (pure "
        "translation); a nominal value is used.\n"
        "* Consistency: the links being horizontal makes their tangential direction vertical, so "
        "B_t - mg = m r alpha holds; G vertically above B makes the moments of mg and m a_t about B "
        "vanish, leaving D_n*0.8 = m a_n*0.5 exactly as printed; the light link CD is a two-force "
        "member, so the force at D is horizontal (D = D_n). The torque is clockwise and the bar "
        "is on the left of the pivots, so B_t lifts the bar; the links turn clockwise (omega_z = "
        "-5 rad/s, the bar moving up at 3 m/s). The direction of omega does not enter the results.\n"
        "* Model: bar (25 kg), links AB and CD as massless rigid bodies (mass 0, inertia 0); "
        "revolutes A (ground-AB), B (AB-bar), D (bar-CD), C (ground-CD), axis z; torque "
        "(0, 0, -200) N m on AB. Dynamics from t = 0; both quantities are read at t = 0."
    ),
    discrepancies=[
        "Arithmetic slip: D_n = 187.5/0.8 = 234.375 N, printed 235.375 N (derivation and table). "
        "RecurDyn's 234.375 N is exact; the printed 0.425 % error is an artefact of the slip "
        "(recomputed commercial error 0 %).",
        "Table unit of R_D printed as m/s^2; it is a force in N.",
        "alpha = (333.33 - 245.25)/15 = 5.87222 rad/s^2: the derivation prints 5.872, the table's "
        "theory column 5.871 (slip); RecurDyn's 5.872 is within 0.004 %, not 0.017 %.",
        "Given-data table calls the 200 N m torque a 'Momentum'; it is a moment (torque).",
    ],
    notes=[
        "The links are light in the problem statement itself, and the derivation treats them as "
        "massless (AB transmits M as B_t = M/0.6, CD is a two-force member); the model does "
        "exactly that. No link masses are given, so there is no full-physics variant.",
    ],
)


def theory() -> dict:
    """The manual's formulas in full precision: R_D [N], alpha [rad/s^2] (clockwise)."""
    a_n = R_LINK * OMEGA**2                                   # normal acceleration of the bar
    D_n = M_BAR * a_n * H_BG / H_BD                           # sum M_B = 0 with G above B
    B_t = TORQUE / R_LINK                                     # light link AB
    alpha = (B_t - M_BAR * G) / (M_BAR * R_LINK)              # sum F_t = m r alpha
    return {"R_D": float(D_n), "alpha": float(alpha)}


def build_model():
    """The parallelogram at the instant the links are horizontal, links turning clockwise."""
    import mbdsim as mb

    model = mb.Model("case21_parallel_links", gravity=(0.0, -G, 0.0))
    A, B = np.array([R_LINK, 0.0, 0.0]), np.zeros(3)
    C, D = np.array([R_LINK, H_BD, 0.0]), np.array([0.0, H_BD, 0.0])
    w = np.array([0.0, 0.0, -OMEGA])                          # clockwise
    v_bar = np.cross(w, B - A)                                # (0, 3, 0) m/s
    L_bar = 2 * H_BG                                          # nominal slender bar, 1 m
    bar = model.add_body("bar_BD", mass=M_BAR, inertia=(M_BAR * L_bar**2 / 12, 1e-3, M_BAR * L_bar**2 / 12),
                         position=(0.0, H_BG, 0.0), velocity=v_bar)
    ab = model.add_body("link_AB", mass=0.0, inertia=(0.0, 0.0, 0.0), position=(A + B) / 2,
                        velocity=np.cross(w, (B - A) / 2), angular_velocity=w)
    cd = model.add_body("link_CD", mass=0.0, inertia=(0.0, 0.0, 0.0), position=(C + D) / 2,
                        velocity=np.cross(w, (D - C) / 2), angular_velocity=w)
    z = (0.0, 0.0, 1.0)
    model.add_revolute("rev_A", model.ground, ab, point=A, axis=z)
    model.add_revolute("rev_B", ab, bar, point=B, axis=z)
    model.add_revolute("rev_D", bar, cd, point=D, axis=z)
    model.add_revolute("rev_C", model.ground, cd, point=C, axis=z)
    model.add_torque("M", ab, (0.0, 0.0, -TORQUE))
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    bar, cd, rev_D = model.bodies["bar_BD"], model.bodies["link_CD"], model.joints["rev_D"]
    res = mb.simulate(model, 0.1, output_step=0.001, method="dop853", rtol=1e-10, atol=1e-12)
    at0 = res.at(0.0)
    F_D = at0.reaction_force(rev_D, on=bar)[0]
    R_D = float(np.hypot(F_D[0], F_D[1]))
    alpha = float(-at0.angular_acceleration(cd)[0, 2])       # clockwise positive
    th = theory()
    q = [
        Quantity("R_D", "N", th["R_D"], *MANUAL["R_D"], R_D,
                 note="in-plane magnitude of the force of link CD on the bar at D, t = 0"),
        Quantity("alpha", "rad/s^2", th["alpha"], *MANUAL["alpha"], alpha,
                 note="angular acceleration of link CD at t = 0, clockwise positive"),
    ]
    F = res.reaction_force(rev_D, on=bar)
    plots = [
        Plot("Force of link CD on the bar at D", res.time, np.hypot(F[:, 0], F[:, 1]), "time [s]",
             "R_D [N]", mark=(0.0, R_D), mark_label="links horizontal (t = 0)"),
        Plot("Angular acceleration of link CD (clockwise)", res.time,
             -res.angular_acceleration(cd)[:, 2], "time [s]", "alpha [rad/s^2]",
             mark=(0.0, alpha), mark_label="links horizontal (t = 0)"),
    ]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
