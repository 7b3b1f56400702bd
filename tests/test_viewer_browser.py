"""The animation page in a real headless Chromium (Debian `chromium` + `chromium-driver`, Selenium).

Loads the page from file:// (no network), checks the browser console is clean, poses the mechanism at
two times through `window.mbdsimViewer.setTime`, and compares two screenshots where the body moved.
Skipped only when Chromium is absent and the CI environment variable is unset; in CI it must run.
"""
import io
import os
import shutil
import time

import numpy as np
import pytest

import mbdsim as mb

CHROMIUM = next((p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None)
DRIVER = shutil.which("chromedriver")
SELENIUM = True
try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
except ImportError:   # pragma: no cover
    SELENIUM = False

if not (CHROMIUM and DRIVER and SELENIUM) and not os.environ.get("CI"):
    pytest.skip("headless Chromium test skipped: needs Debian packages chromium + chromium-driver and "
                "selenium (apt-get install -y chromium chromium-driver; pip install selenium)",
                allow_module_level=True)


def pendulum():
    """Rod of 1 m pinned at the origin, released horizontal along +x, swinging in the x-y plane (y up)."""
    model = mb.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = model.add_body("rod", mass=2.0, inertia=(1e-3, 2.0 / 12, 2.0 / 12), position=(0.5, 0, 0))
    model.add_revolute("pin", model.ground, rod, point=(0, 0, 0), axis=(0, 0, 1))
    bob = model.add_particle("bob", mass=0.2, position=(1.0, -0.4, 0))
    model.add_spring_damper("spring", (rod, (1.0, 0, 0)), bob, stiffness=50.0, damping=0.5)
    return model


@pytest.fixture(scope="module")
def driver():
    assert CHROMIUM and DRIVER and SELENIUM, "CI must run the browser test: install chromium, chromium-driver, selenium"
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1000,700",
                "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
                "--disable-background-networking", "--force-device-scale-factor=1"):
        opts.add_argument(arg)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service(DRIVER), options=opts)
    yield d
    d.quit()


def _png(driver):
    from PIL import Image
    return np.asarray(Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB"), dtype=float)


def _patch(img, xy, r=6):
    x, y = int(round(xy[0])), int(round(xy[1]))
    return img[max(y - r, 0):y + r + 1, max(x - r, 0):x + r + 1]


def test_page_plays_in_chromium(driver, tmp_path):
    res = mb.simulate(pendulum(), end_time=1.0, output_step=0.005)
    page = mb.animate(res, tmp_path / "pendulum.html", signal=lambda r: r.joint_coordinate("pin"))
    driver.get(page.resolve().as_uri())
    t_end = time.monotonic() + 30
    while not driver.execute_script("return !!(window.mbdsimViewer && window.mbdsimViewer.ready)"):
        assert time.monotonic() < t_end, "viewer did not start: " + str(driver.get_log("browser"))
        time.sleep(0.05)
    assert driver.execute_script("return document.getElementById('error').textContent") == ""
    v = "window.mbdsimViewer"
    assert driver.execute_script(f"return {v}.frames") == len(res.time)
    assert driver.execute_script(f"return {v}.duration") == pytest.approx(1.0)

    shots, where = [], []
    for t in (0.0, 0.5):
        assert driver.execute_script(f"return {v}.setTime({t})") == pytest.approx(t)
        assert driver.execute_script(f"return {v}.playing") is False
        where.append(driver.execute_script(f"return {v}.project('rod')"))
        shots.append(_png(driver))
        text = driver.execute_script("return document.getElementById('time').textContent")
        assert text == f"t = {t:.3f} s"
    # the signal readout shows the Result's own value at that time
    angle = float(res.at(0.5).joint_coordinate("pin")[0])
    readout = driver.execute_script("return document.getElementById('signal').textContent")
    assert readout.startswith("pin angle = ") and float(readout.split("=")[1].split()[0]) == pytest.approx(angle, abs=2e-3)

    logs = [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]
    assert logs == [], logs

    a, b = shots
    background = np.array([0xf4, 0xf5, 0xf7], float)
    # the rod's centre moved on screen (it swings down through ~60 degrees in 0.5 s)
    assert np.hypot(where[1][0] - where[0][0], where[1][1] - where[0][1]) > 30
    # at each time the rod covers its centre; at the other time that spot shows something else
    for k, (xy, img, other) in enumerate(((where[0], a, b), (where[1], b, a))):
        own, there = _patch(img, xy), _patch(other, xy)
        assert np.abs(own - background).sum(-1).mean() > 60, f"no body drawn at its centre (shot {k})"
        assert np.abs(own - there).sum(-1).mean() > 40, f"screenshots do not differ where the rod moved (shot {k})"
    # the rest of the 3D view (far from the rod, below the title) is unchanged: the camera did not move
    assert np.abs(a[60:120, :150] - b[60:120, :150]).max() == 0
    # the signal chart's cursor moved with the time
    assert np.abs(a[-140:-60] - b[-140:-60]).sum() > 0

    # playback advances time
    driver.execute_script(f"{v}.setTime(0); {v}.play()")
    time.sleep(0.3)
    assert driver.execute_script(f"return {v}.time") > 0.0
    if os.environ.get("MBDSIM_SHOTS"):   # keep the screenshots to look at
        from PIL import Image
        for k, img in enumerate(shots):
            Image.fromarray(img.astype(np.uint8)).save(os.path.join(os.environ["MBDSIM_SHOTS"], f"viewer_{k}.png"))


def test_contact_force_arrows_render_in_chromium(driver, tmp_path):
    """Issue 30: with contact_forces=True the page draws an arrow per touching point (a box resting on a
    plane: four) without console errors; without it, none."""
    model = mb.Model("box", gravity=(0, 0, -9.81))
    box = model.add_body("box", 1.0, (1 / 600,) * 3, position=(0, 0, 0.05 - 9.81 / 4e5))
    model.add_contact("floor", mb.Plane(model.ground, (0, 0, 0), (0, 0, 1)), box.add_shape("g", mb.Box((0.1,) * 3)),
                      1e5, 1.0, 200.0, 1e-4, mu=0.3)
    res = mb.simulate(model, end_time=0.1, output_step=0.01)
    v = "window.mbdsimViewer"
    for flag, arrows in ((True, 4), (False, 0)):
        page = mb.animate(res, tmp_path / f"box_{flag}.html", signal=None, contact_forces=flag)
        driver.get(page.resolve().as_uri())
        t_end = time.monotonic() + 30
        while not driver.execute_script("return !!(window.mbdsimViewer && window.mbdsimViewer.ready)"):
            assert time.monotonic() < t_end, "viewer did not start: " + str(driver.get_log("browser"))
            time.sleep(0.05)
        driver.execute_script(f"{v}.setTime(0.1)")
        assert driver.execute_script(f"return {v}.contactArrows") == arrows
        drawn = driver.execute_script(f"return {v}.scene.getObjectByName('contact-forces').children"
                                      ".filter((a) => a.visible).length")
        assert drawn == arrows
        logs = [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]
        assert logs == [], logs


def test_add_shape_shapes_render_where_their_body_is(driver, tmp_path):
    """Issue 30: shapes placed with Body.add_shape (a box and a cylinder on a falling body, a box on ground)
    are meshes of the page named shape:<body>.<name>; their vertices, posed by the page at a time, lie where
    the Result puts the shape (the box's corners at the body's pose), without console errors."""
    model = mb.Model("shapes", gravity=(0, 0, -9.81))
    body = model.add_body("b", 1.0, (0.01,) * 3, position=(0.0, 0.0, 0.5), angular_velocity=(1.0, 2.0, 0.5))
    body.add_shape("cube", mb.Box((0.2, 0.1, 0.05)), center=(0.1, 0.0, 0.5))
    body.add_shape("rod", mb.Cylinder(0.02, 0.3, "x"))
    model.ground.add_shape("base", mb.Box((0.4, 0.4, 0.02)), center=(0.0, 0.0, -0.01))
    res = mb.simulate(model, end_time=0.3, output_step=0.01)
    page = mb.animate(res, tmp_path / "shapes.html", signal=None)
    driver.get(page.resolve().as_uri())
    t_end = time.monotonic() + 30
    while not driver.execute_script("return !!(window.mbdsimViewer && window.mbdsimViewer.ready)"):
        assert time.monotonic() < t_end, "viewer did not start: " + str(driver.get_log("browser"))
        time.sleep(0.05)
    v = "window.mbdsimViewer"
    driver.execute_script(f"{v}.setTime(0.3)")
    names = driver.execute_script(f"const out = []; {v}.scene.traverse((o) => {{ if (o.name.startsWith('shape:')) "
                                  "out.push(o.name); }); return out.sort();")
    assert names == ["shape:b.cube", "shape:b.rod", "shape:ground.base"], names
    world = driver.execute_script(
        f"const m = {v}.scene.getObjectByName('shape:b.cube'); m.updateMatrixWorld(true);"
        "const p = m.geometry.attributes.position, out = [];"
        "for (let i = 0; i < p.count; i++) { const w = new m.position.constructor(p.getX(i), p.getY(i), p.getZ(i));"
        " m.localToWorld(w); out.push([w.x, w.y, w.z]); } return out;")
    world = np.array(world)
    r, R = res.position("b")[-1], res.orientation("b")[-1]
    corners = np.array([[sx * 0.1, sy * 0.05, sz * 0.025] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    expected = r + (corners + [0.1, 0.0, 0.0]) @ R.T   # the cube's centre 0.1 m along the body's x axis
    # every drawn vertex of the cube is on it (bounded by its corners in the cube's axes), the corners drawn
    local = (world - (r + R @ [0.1, 0.0, 0.0])) @ R
    assert np.all(np.abs(local) <= np.array([0.1, 0.05, 0.025]) + 1e-5)
    assert all(np.min(np.linalg.norm(world - c, axis=1)) < 1e-5 for c in expected)
    logs = [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]
    assert logs == [], logs
