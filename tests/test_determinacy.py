"""Issue 10, redundancy done honestly: reaction components of redundant constraint sets classified as
determinate or indeterminate (Wojtyra-Fraczek: c^T lambda is unique iff c is orthogonal to null(phi_q^T)),
flagged on Result.reaction_force / reaction_torque and reported by `mbdsim info`."""
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import mbdsim as mb
from mbdsim.cli.app import app
from mbdsim.system.determinacy import IndeterminateReactionWarning


def door(hinge="spherical"):
    """A door on two hinges on the vertical z axis, 1 m apart, CM 0.5 m off the axis; gravity -z.
    Two spherical joints: one redundant row (only the sum of the axial forces Fz is determined)."""
    m = mb.Model("door", gravity=(0.0, 0.0, -9.81))
    d = m.add_body("door", 10.0, inertia=(1.0, 1.0, 1.0), position=(0.5, 0.0, 0.5))
    m.add_spherical("top", m.ground, d, (0, 0, 1))
    m.add_spherical("bottom", m.ground, d, (0, 0, 0))
    return m


def test_two_spherical_hinges_axial_force_indeterminate():
    m = door()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(m, 0.5, 0.05)
    for name in ("top", "bottom"):
        flags = res.reaction_determinacy(name)
        assert flags.shape == (len(res.time), 6)
        assert np.all(flags[:, 2]) and not np.any(flags[:, [0, 1, 3, 4, 5]])   # only Fz indeterminate
        with pytest.warns(IndeterminateReactionWarning, match=rf"joint '{name}': reaction components Fz "):
            F = res.reaction_force(name)
        assert F.indeterminate.shape == F.shape and np.all(F.indeterminate[:, 2]) and not F.indeterminate[:, :2].any()
    # the determinate parts are physics: the door turns about z only, so the hinge loads balance gravity
    # along z in sum (the sum of the two indeterminate components is determinate) ...
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IndeterminateReactionWarning)
        Fz = res.reaction_force("top")[:, 2] + res.reaction_force("bottom")[:, 2]
    assert np.allclose(Fz, 10.0 * 9.81, rtol=1e-9)
    # ... and no torque about the spherical joints' points
    with warnings.catch_warnings():
        warnings.simplefilter("error", IndeterminateReactionWarning)
        assert np.allclose(res.reaction_torque("top"), 0.0, atol=1e-9)


def test_frame_axes_follow_the_components():
    m = door()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(m, 0.3, 0.05)
    # in the door's own axes (its z is the hinge axis, it turns about it) the same component is indeterminate
    flags = res.reaction_determinacy("top", frame="door")
    assert np.all(flags[:, 2]) and not np.any(flags[:, :2])


def test_no_redundancy_no_flags():
    m = mb.Model("p", gravity=(0.0, -9.81, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.0, 0.0, 0.0))
    m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
    res = mb.simulate(m, 0.2, 0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error", IndeterminateReactionWarning)
        F = res.reaction_force("j")
    assert not F.indeterminate.any() and not res.reaction_determinacy("j").any()


def test_info_reports_determinacy(tmp_path):
    f = tmp_path / "door.yaml"
    mb.save_model(door(), f)
    r = CliRunner().invoke(app, ["info", str(f)])
    assert r.exit_code == 0, r.output
    assert "reaction determinacy" in r.output
    line = next(x for x in r.output.splitlines() if "bottom" in x and "Fz" in x)
    assert "Fx Fy Tx Ty Tz" in line and line.rstrip(" │|").endswith("Fz")
