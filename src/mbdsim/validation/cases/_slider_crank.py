"""Shared builder of the in-line slider-crank used by several validation cases (11, 13, 19).

Geometry in the x-y plane: crank pivot O at the origin, crank OB of length R, connecting rod BA of
length L, piston A sliding on the -x axis; theta0 is the angle AOB [rad] at t = 0 and the crank is
driven clockwise (revolute axis -z) by the displacement expression `drive` (e.g. "3*t") [rad].
Bodies: "crank", "rod", slider named `slider` (CM at A); joints rev_O, rev_B, rev_A, slider_A and
the motion crank_drive.  Inertias about the CM in body axes; x is along each link.
"""
from __future__ import annotations

import numpy as np


def rz(a: float) -> np.ndarray:
    """Rotation matrix about z by a [rad]."""
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])


def slider_crank_points(R: float, L: float, theta: float):
    """O, B, A [m] in ground and the rod angle beta [rad] for the crank angle theta = angle AOB."""
    beta = np.arcsin(R / L * np.sin(theta))
    B = np.array([-R * np.cos(theta), R * np.sin(theta), 0.0])
    A = np.array([-(R * np.cos(theta) + L * np.cos(beta)), 0.0, 0.0])
    return np.zeros(3), B, A, beta


def build_slider_crank(name, R, L, theta0, drive, masses=(1.0, 2.0, 1.5), rod_cm_from_A=None,
                       slider="piston", axial_inertia=1e-4):
    """The driven slider-crank model (no gravity); rod CM at `rod_cm_from_A` [m] from A (default mid-rod)."""
    import mbdsim as mb

    O, B, A, beta = slider_crank_points(R, L, theta0)
    m_c, m_r, m_p = masses
    u = np.array([np.cos(beta), np.sin(beta), 0.0])            # unit vector A -> B
    G = (A + B) / 2 if rod_cm_from_A is None else A + rod_cm_from_A * u
    model = mb.Model(name, gravity=(0.0, 0.0, 0.0))
    crank = model.add_body("crank", mass=m_c, inertia=(axial_inertia, m_c * R**2 / 12, m_c * R**2 / 12),
                           position=(O + B) / 2, orientation=rz(np.pi - theta0))
    rod = model.add_body("rod", mass=m_r, inertia=(axial_inertia, m_r * L**2 / 12, m_r * L**2 / 12),
                         position=G, orientation=rz(beta))
    piston = model.add_body(slider, mass=m_p, inertia=(1e-3, 1e-3, 1e-3), position=A)
    model.add_revolute("rev_O", model.ground, crank, point=O, axis=(0, 0, -1))
    model.add_revolute("rev_B", crank, rod, point=B, axis=(0, 0, 1))
    model.add_revolute("rev_A", rod, piston, point=A, axis=(0, 0, 1))
    model.add_translational("slider_A", model.ground, piston, point=A, axis=(1, 0, 0))
    model.add_motion("crank_drive", "rev_O", displacement=drive)
    return model
