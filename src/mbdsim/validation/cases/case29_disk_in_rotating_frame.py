"""Case 29: disk spinning in a frame that turns about a vertical axis, acceleration of a rim point.

Meriam & Kraige 7th ed., p.536, P7/46.  3D kinematics (two constant-speed drivers); ground z
vertical (gravity (0, 0, -9.81), irrelevant here).  Units: SI (m, s, rad); table units m/s^2
and rad/s^2.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
P = 10 * np.pi                        # spin of the disk relative to the frame, about j [rad/s]
OMEGA = 4 * np.pi                     # rotation of the frame about the fixed vertical k [rad/s]
R_O = np.array([0.3, 0.0, 0.1])       # disk centre O from the fixed point on the axis [m]
R_AO = np.array([0.0, 0.0, 0.1])      # rim point A from O at the instant [m]
T_MEAS = 1.0                          # 2 frame and 5 disk revolutions: the t = 0 configuration [s]

# printed in the manual's comparison table: (theory, RecurDyn)
MANUAL = {"alpha_x": (-394.78, -394.78), "a_x": (-47.37, -47.37), "a_y": (78.96, 78.96),
          "a_z": (-98.70, -98.70)}

CASE = CaseInfo(
    number=29,
    slug="disk_in_rotating_frame",
    title="Disk spinning in a rotating frame: angular acceleration and acceleration of a rim point",
    reference="Meriam & Kraige, Dynamics 7th ed., p.536, P7/46",
    analysis="kinematics (3D, two drivers)",
    statement=(
        "A disk of radius 0.1 m spins at the constant rate p = 10 pi rad/s about its shaft (the "
        "j direction) relative to a frame which turns about the fixed vertical z axis at the "
        "constant rate Omega = 4 pi rad/s. At the instant considered the disk centre O is at "
        "R_O = 0.3 i + 0.1 k m from the fixed point on the axis and the rim point A is at the top "
        "of the disk, r_A/O = 0.1 k. Find the angular acceleration of the disk and the "
        "acceleration of A."
    ),
    reconstruction=(
        "* Ground frame = the manual's i, j, k at the instant (k vertical): the frame's revolute "
        "on the ground at the origin about +z, driven 4 pi t; the disk's revolute on the frame at "
        "O = (0.3, 0, 0.1) about +y (the shaft, fixed on the frame), driven 10 pi t (relative "
        "angle); marker A on the disk at (0.3, 0, 0.2).\n"
        "* Consistency with every printed number: a_O = Omega x (Omega x R_O) = -4.8 pi^2 i, "
        "v_rel = p x r = pi i, Coriolis 2 Omega x v_rel = 8 pi^2 j, a_rel = -10 pi^2 k, "
        "a_A = 2 pi^2(-2.4 i + 4 j - 5 k) = (-47.374, 78.957, -98.696) m/s^2, |a_A| = 134.98; "
        "alpha = Omega x p = -40 pi^2 i = -394.784 rad/s^2.\n"
        "* Masses are nominal (kinematics). The quantities are read at t = 1 s, after 2 frame "
        "and 5 disk revolutions, which is the t = 0 configuration again (a check on drift as well)."
    ),
    discrepancies=[
        "The angular-acceleration line reads 'p_dot = ... = -p Omega = -40 pi^2 i'; it should be "
        "Omega x p = (4 pi k) x (10 pi j) = -40 pi^2 i (the product p Omega is not a vector in -i).",
        "Table: the angular acceleration is printed '-394.78 t' (t for i) and its row is labelled "
        "alpha [rad/s^2] without saying it is the disk's x component.",
    ],
    notes=[
        "Pure kinematics with constant rates: exact, no variant.",
    ],
)


def theory() -> dict:
    """Acceleration of A [m/s^2] (components) and the disk's angular acceleration x [rad/s^2]."""
    W = np.array([0.0, 0.0, OMEGA])
    p = np.array([0.0, P, 0.0])
    a_O = np.cross(W, np.cross(W, R_O))
    v_rel = np.cross(p, R_AO)
    a_rel = np.cross(p, np.cross(p, R_AO))
    a_A = a_O + np.cross(W, np.cross(W, R_AO)) + 2 * np.cross(W, v_rel) + a_rel   # Omega_dot = 0
    alpha = np.cross(W, p)
    return {"alpha_x": float(alpha[0]), "a_x": float(a_A[0]), "a_y": float(a_A[1]), "a_z": float(a_A[2]),
            "a": float(np.linalg.norm(a_A))}


def build_model():
    """Frame and disk at the instant of the problem, both drivers at constant rate."""
    import mbdsim as mb

    model = mb.Model("case29_disk_frame", gravity=(0.0, 0.0, -9.81))
    frame = model.add_body("frame", mass=2.0, inertia=(0.05, 0.05, 0.05), position=(0.15, 0.0, 0.1))
    m_d, r_d = 1.0, 0.1
    disk = model.add_body("disk", mass=m_d, inertia=(m_d * r_d**2 / 4, m_d * r_d**2 / 2, m_d * r_d**2 / 4),
                          position=R_O)
    disk.add_marker("A", point=R_O + R_AO)
    model.add_revolute("rev_frame", model.ground, frame, point=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0))
    model.add_revolute("rev_disk", frame, disk, point=R_O, axis=(0.0, 1.0, 0.0))
    model.add_motion("Omega", "rev_frame", displacement="4*pi*t")
    model.add_motion("p", "rev_disk", displacement="10*pi*t")
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    disk = model.bodies["disk"]
    A = disk.markers["A"]
    res = mb.kinematics(model, 1.1, 0.005)
    at = res.at(T_MEAS)
    a_A = at.acceleration(A)[0]
    alpha = at.angular_acceleration(disk)[0]
    th = theory()
    q = [
        Quantity("alpha_x", "rad/s^2", th["alpha_x"], *MANUAL["alpha_x"], float(alpha[0]),
                 note="x component of the disk's angular acceleration (ground axes)"),
        Quantity("(a_A)_x", "m/s^2", th["a_x"], *MANUAL["a_x"], float(a_A[0])),
        Quantity("(a_A)_y", "m/s^2", th["a_y"], *MANUAL["a_y"], float(a_A[1])),
        Quantity("(a_A)_z", "m/s^2", th["a_z"], *MANUAL["a_z"], float(a_A[2])),
    ]
    acc = res.acceleration(A)
    plots = [
        Plot("Acceleration of the rim point A (ground axes)", res.time,
             {"x": acc[:, 0], "y": acc[:, 1], "z": acc[:, 2]}, "time [s]", "a_A [m/s^2]",
             mark=(T_MEAS, float(a_A[0])), mark_label="(a_A)_x at the problem's configuration"),
        Plot("Angular acceleration of the disk, x component", res.time,
             res.angular_acceleration(disk)[:, 0], "time [s]", "alpha_x [rad/s^2]",
             mark=(T_MEAS, float(alpha[0])), mark_label="problem's configuration"),
    ]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)
