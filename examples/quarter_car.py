"""Quarter-car suspension over a 5 cm road step: body (sprung) and wheel (unsprung) masses on vertical guides,
suspension spring-damper body-wheel, tyre spring wheel-road; the road is a driven platform.

Spring preloads carry the weights, so the car starts in static equilibrium and stays at rest until the
road rises (smooth STEP from t = 0.5 s to 0.6 s); it then settles 5 cm higher.  Same model as
quarter_car.yaml.  Run: python examples/quarter_car.py
"""
import mbdsim as mb

M_BODY, M_WHEEL, K_SUSP, C_SUSP, K_TYRE, G = 250.0, 35.0, 16000.0, 1000.0, 160000.0, 9.81


def build() -> mb.Model:
    """z up; road platform at z = 0, wheel centre at 0.3 m, body at 0.7 m."""
    model = mb.Model("quarter_car", gravity=(0, 0, -G))
    # inertias of solid boxes (drawn so by the viewer): road plate 0.4 x 0.4 x 0.05 m, wheel 0.44 x 0.2 x
    # 0.44 m, body 0.6 x 0.6 x 0.3 m; every joint is translational, so rotation plays no part
    road = model.add_body("road", mass=10.0, inertia=(0.135417, 0.135417, 0.266667), position=(0, 0, 0))
    wheel = model.add_body("wheel", mass=M_WHEEL, inertia=(0.681333, 1.129333, 0.681333), position=(0, 0, 0.3))
    body = model.add_body("body", mass=M_BODY, inertia=(9.375, 9.375, 15.0), position=(0, 0, 0.7))
    for name, b in (("road_guide", road), ("wheel_guide", wheel), ("body_guide", body)):
        model.add_translational(name, model.ground, b, point=b.position, axis=(0, 0, 1))
    model.add_motion("road_profile", "road_guide", displacement="0.05*STEP(t, 0.5, 0, 0.6, 1)")
    model.add_spring_damper("suspension", (wheel, (0, 0, 0.3)), (body, (0, 0, 0.7)), stiffness=K_SUSP,
                            damping=C_SUSP, preload=-M_BODY * G)
    model.add_spring_damper("tyre", (road, (0, 0, 0)), (wheel, (0, 0, 0.3)), stiffness=K_TYRE,
                            preload=-(M_BODY + M_WHEEL) * G)
    return model


if __name__ == "__main__":
    res = mb.simulate(build(), end_time=4.0, output_step=0.01)
    print("body rise after 4 s [m]:", res.joint_coordinate("body_guide")[-1], "(road step 0.05 m)")
