"""The joint-kind registry against the rest of the code: the same kinds as the equation classes, a Model
method with the registry's fields for each, and the declared degrees of freedom equal to 6 minus the
independent constraint rows that the kind's equations produce between two rigid bodies (and the declared
translation constraints equal to the rows left when body_j is a particle)."""
from __future__ import annotations

import inspect

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.model.joint_kinds import JOINT_KINDS, axis_dofs
from mbdsim.system.assemble import assemble_system
from mbdsim.system.constraints.registry import JOINT_TYPES
from mbdsim.system.equations import constraint_terms

AXIS_I = np.array([0.3, -0.2, 0.93]) / np.linalg.norm([0.3, -0.2, 0.93])
AXIS_J = np.cross(AXIS_I, [1.0, 0.0, 0.0]) / np.linalg.norm(np.cross(AXIS_I, [1.0, 0.0, 0.0]))
VALUES = {"point": (0.1, 0.2, -0.1), "axis": AXIS_I, "axis_i": AXIS_I, "axis_j": AXIS_J, "normal": AXIS_I,
          "u_axis": AXIS_J, "lead": 0.01}


def test_registry_and_equation_classes_list_the_same_kinds():
    assert set(JOINT_KINDS) == set(JOINT_TYPES)


@pytest.mark.parametrize("kind", sorted(JOINT_KINDS))
def test_model_method_takes_the_registry_fields(kind):
    params = inspect.signature(getattr(mb.Model, JOINT_KINDS[kind].method)).parameters
    fields = [p for p in params if p not in ("self", "name", "body_i", "body_j")]
    assert tuple(fields[:len(JOINT_KINDS[kind].fields)]) == JOINT_KINDS[kind].fields


def _rank(kind, particle):
    m = mb.Model("k")
    a = m.add_body("a", 1.0, inertia=(1.0, 2.0, 3.0), position=(0.0, 0.0, 0.0))
    b = (m.add_particle("b", 1.0, position=(0.1, 0.2, -0.1)) if particle
         else m.add_body("b", 1.0, inertia=(1.0, 2.0, 3.0), position=(0.4, 0.1, 0.2)))
    args = [VALUES[f] for f in JOINT_KINDS[kind].fields]
    getattr(m, JOINT_KINDS[kind].method)("j", a, b, *args)
    sys = assemble_system(m)
    J = constraint_terms(sys, sys.q0, np.zeros(sys.nv), 0.0)[1]
    return np.linalg.matrix_rank(J[:, sys.frame_v_adr[2]:sys.frame_v_adr[2] + (3 if particle else 6)])


@pytest.mark.parametrize("kind", sorted(JOINT_KINDS))
def test_declared_freedoms_equal_the_equations(kind):
    k = JOINT_KINDS[kind]
    assert 6 - _rank(kind, particle=False) == k.dof
    pure_rotation = ("universal", "constant_velocity", "perpendicular", "orientation", "parallel_axes", "planar")
    if kind not in pure_rotation and not getattr(JOINT_TYPES[kind], "needs_orientation", False):
        assert _rank(kind, particle=True) == k.translation_constraints


def test_axis_dofs_of_motions_and_loads():
    assert axis_dofs("revolute") == ("rotation",) and axis_dofs("translational") == ("translation",)
    assert axis_dofs("screw") == ("rotation", "translation") and axis_dofs("screw", loads=True) == ()
    assert axis_dofs("spherical") == () and axis_dofs("nonesuch") == ()


def test_slide_and_coupled_freedoms_come_from_the_registry():
    from mbdsim.model.joint_kinds import coupled_dofs, has_slide
    assert [k for k in JOINT_KINDS if has_slide(k)] == ["translational", "cylindrical"]
    assert coupled_dofs("screw") == ("rotation",) and coupled_dofs("cylindrical") == ("rotation", "translation")
    assert coupled_dofs("spherical") == () and coupled_dofs("nonesuch") == ()
    # a slide coordinate moves along the axis: a translational joint's coordinate follows the body
    m = mb.Model(gravity=(0, 0, 0))
    b = m.add_body("b", 1.0, (1, 1, 1), position=(0, 0, 0), velocity=(0.3, 0, 0))
    m.add_translational("s", m.ground, b, (0, 0, 0), (1, 0, 0))
    res = mb.simulate(m, 1.0, 0.5)
    assert np.allclose(np.ravel(res.joint_coordinate("s")), 0.3 * res.time, atol=1e-9)
