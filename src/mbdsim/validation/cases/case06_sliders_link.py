"""Case 6: two sliders joined by a light rigid bar, driven by a force P (Meriam & Kraige 7th ed.).

Planar: the slots lie in a horizontal plane, taken as the ground x-y plane (A slides along x, B along y,
the slots meet at the origin O); gravity acts along -z, normal to the plane, and is carried by the
frictionless guides, so the model has no gravity.  Dynamics at one instant (t = 0); SI units.
"""
from __future__ import annotations

import numpy as np

import mbdsim as mb
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

L = 0.5            # [m] bar length AB
XA, XB = 0.4, 0.3  # [m] positions of A (on x) and B (on y) at the instant
VA = 0.9           # [m/s] velocity of A, +x (away from O)
MA, MB = 2.0, 3.0  # [kg] slider masses
P = 40.0           # [N] horizontal force on A, +x

MANUAL = {  # name -> (unit, manual theory, manual RecurDyn)
    "a_A": ("m/s^2", 1.36, 1.361),
    "a_B": ("m/s^2", -9.318, -9.315),
    "T": ("N", 46.59, 46.592),
}

CASE = CaseInfo(
    number=6,
    slug="sliders_link",
    title="Two sliders connected by a light rigid bar: accelerations and bar force",
    reference="Meriam & Kraige, Dynamics 7th ed., p.129, P3.2 (as printed; copied from case 5, see discrepancies)",
    analysis="dynamics (two particles with a massless link, instantaneous)",
    statement=(
        "Sliders A (2 kg) and B (3 kg) move without friction in perpendicular slots of a horizontal plane "
        "and are connected by a light rigid bar of length 0.5 m. A force P = 40 N acts on A along its slot. "
        "When x_A = 0.4 m and v_A = 0.9 m/s (away from the corner), find the accelerations of A and B and "
        "the force T in the bar."
    ),
    reconstruction=(
        "A = (0.4, 0) m on the x slot, B = (0, 0.3) m on the y slot, AB = 0.5 m (x_A^2 + x_B^2 = 0.5^2), "
        "cos(theta) = 4/5, sin(theta) = 3/5 for the bar angle with the x slot. Velocities: v_A = +0.9 m/s, "
        "v_B = -x_A v_A / x_B = -1.2 m/s (B moves toward O), bar omega = 3 rad/s counter-clockwise. "
        "P = 40 N along +x on A; no gravity in the plane.\n\n"
        "Consistency: omega = 0.9/0.3 = 1.2/0.4 = 3; x_A x_A'' + v_A^2 + x_B x_B'' + v_B^2 = 0 gives "
        "x_B'' = -7.5 - (4/3) x_A''; A: 40 - (4/5) T = 2 x_A''; B: -(3/5) T = 3 x_B''; hence "
        "x_A'' = 15/11 = 1.364, x_B'' = -9.318 m/s^2, T = 46.59 N (tension): all printed numbers follow.\n\n"
        "Model: A a 2 kg body on a translational joint (x), the bar a massless body with a revolute at A, "
        "B a 3 kg particle on the bar end (spherical) kept in the plane x = 0 (planar joint, normal x: "
        "the y slot, the out-of-plane direction being fixed by the bar). T = |reaction| at B."
    ),
    discrepancies=[
        "Given-data units are wrong: x_A, x_B = 0.4, 0.3 'mm' are metres, v_A, v_B = 0.9, 1.2 'mm/s' are m/s, "
        "omega_AB = 3 'deg/s' is rad/s; the 'decreasing rate' v_A belongs to an increasing x_A; "
        "the accelerations are printed with the unit m/s (m/s^2).",
        "The first time derivative of the constraint is printed 2 x_A x_A'' + 2 x_B x_B'' = 0; it is "
        "2 x_A x_A' + 2 x_B x_B' = 0 (velocities).",
        "v_B is printed +1.2 m/s; with x_B decreasing it is -1.2 m/s (only its square enters).",
        "The reference 'pp.129, P.3.2' is copied from case 5 (the crate on an incline); this is a "
        "different chapter-3 problem.",
        "Table a_A = 1.36 is truncated from 15/11 = 1.363636 m/s^2: RecurDyn's 1.361 is 0.193 % off the "
        "exact value (printed 0.074 %); a_B: 0.0341 % (printed 0.032 %); T = 46.590909 N: 0.0023 % "
        "(printed 0.004 %).",
    ],
    notes=["The derivation is exact for a massless bar and frictionless slots."],
)


def theory() -> dict[str, float]:
    """a_A [m/s^2] (x), a_B [m/s^2] (y) and T [N] from Newton's law for A and B and the bar constraint."""
    vb = -XA * VA / XB                       # x_A v_A + x_B v_B = 0
    c, s = XA / L, XB / L                    # bar direction cosines
    # unknowns (a_A, a_B, T):  m_A a_A + c T = P;  m_B a_B + s T = 0;  x_A a_A + x_B a_B = -(v_A^2 + v_B^2)
    lhs = np.array([[MA, 0.0, c], [0.0, MB, s], [XA, XB, 0.0]])
    rhs = np.array([P, 0.0, -(VA**2 + vb**2)])
    a_a, a_b, t = np.linalg.solve(lhs, rhs)
    return {"a_A": a_a, "a_B": a_b, "T": t}


def build_model():
    """Returns (model, slider A, slider B, joint at B)."""
    vb = -XA * VA / XB
    omega_z = VA / XB                        # v_B - v_A = omega k x (B - A) -> omega = 3 rad/s
    model = mb.Model("sliders_link", gravity=(0.0, 0.0, 0.0))
    a = model.add_body("slider_A", mass=MA, inertia=(1e-3, 1e-3, 1e-3), position=(XA, 0, 0), velocity=(VA, 0, 0))
    b = model.add_particle("slider_B", mass=MB, position=(0, XB, 0), velocity=(0, vb, 0))
    bar = model.add_body("bar", mass=0.0, inertia=(0.0, 0.0, 0.0), position=(XA / 2, XB / 2, 0),
                         velocity=(VA / 2, vb / 2, 0), angular_velocity=(0, 0, omega_z))
    model.add_translational("slot_A", model.ground, a, point=(XA, 0, 0), axis=(1, 0, 0))
    model.add_revolute("pin_A", a, bar, point=(XA, 0, 0), axis=(0, 0, 1))
    pin_b = model.add_spherical("pin_B", bar, b, point=(0, XB, 0))
    model.add_planar("slot_B", model.ground, b, point=(0, XB, 0), normal=(1, 0, 0))
    model.add_force("P", (a, (XA, 0, 0)), (P, 0.0, 0.0))
    return model, a, b, pin_b


def run() -> CaseOutcome:
    model, a, b, pin_b = build_model()
    res = mb.simulate(model, 0.05, output_step=5e-4, method="dop853", rtol=1e-10, atol=1e-12)
    now = res.at(0.0)
    measured = {"a_A": float(now.acceleration(a)[0, 0]), "a_B": float(now.acceleration(b)[0, 1]),
                "T": float(np.linalg.norm(now.reaction_force(pin_b, on=b)[0]))}
    th = theory()
    quantities = [Quantity(n, u, theory=th[n], manual_theory=mt, manual_commercial=mc, mbdsim=measured[n])
                  for n, (u, mt, mc) in MANUAL.items()]
    plots = [
        Plot("Accelerations of the sliders", res.time,
             {"a_A (x)": res.acceleration(a)[:, 0], "a_B (y)": res.acceleration(b)[:, 1]},
             "t [s]", "a [m/s^2]", mark=(0.0, measured["a_A"]), mark_label="x_A = 0.4 m"),
        Plot("Bar force (total reaction at B)", res.time, np.linalg.norm(res.reaction_force(pin_b, on=b), axis=1),
             "t [s]", "T [N]", mark=(0.0, measured["T"]), mark_label=f"T = {measured['T']:.5f} N"),
    ]
    return CaseOutcome(info=CASE, quantities=quantities, model=model, result=res, plots=plots)
