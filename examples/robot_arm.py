"""Two-link arm in the vertical x-z plane with driven shoulder and elbow (fully driven: kinematics).

Tip position (forward kinematics): x = L1 cos q1 + L2 cos(q1 + q2), z = L1 sin q1 + L2 sin(q1 + q2),
both joints about -y so positive angles lift the arm.  Same model as robot_arm.yaml.
Run: python examples/robot_arm.py
"""
import mbdsim as mb

L1, L2 = 0.5, 0.4
Q1, Q2 = "0.5*sin(pi*t)", "0.8*(1-cos(pi*t))"   # shoulder and elbow angles [rad], t in s


def build() -> mb.Model:
    """Upper arm from the shoulder at the origin to the elbow at (0.5, 0, 0), forearm to the tip at (0.9, 0, 0)."""
    model = mb.Model("robot_arm", gravity=(0, 0, -9.81))
    upper = model.add_body("upper_arm", shape=mb.Box((0.5, 0.05, 0.05)), density=2700.0, position=(0.25, 0, 0))
    fore = model.add_body("forearm", shape=mb.Box((0.4, 0.04, 0.04)), density=2700.0, position=(0.7, 0, 0))
    fore.add_marker("tip", point=(L1 + L2, 0, 0))
    model.add_revolute("shoulder", model.ground, upper, point=(0, 0, 0), axis=(0, -1, 0))
    model.add_revolute("elbow", upper, fore, point=(L1, 0, 0), axis=(0, -1, 0))
    model.add_motion("shoulder_drive", "shoulder", displacement=Q1)
    model.add_motion("elbow_drive", "elbow", displacement=Q2)
    return model


if __name__ == "__main__":
    res = mb.kinematics(build(), end_time=2.0, output_step=0.01)
    print("tip at t = 1 s [m]:", res.at(1.0).position("forearm.tip")[0])
    print("shoulder torque range [N m]:", res.driver_effort("shoulder_drive").min(), res.driver_effort("shoulder_drive").max())
