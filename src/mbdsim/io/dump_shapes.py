"""Shapes and shape contacts -> model-file data (issue 30), for mbdsim.io.dump: a body's placed shapes with
their geometry (a mesh file by its path relative to the model file's folder, a mesh made from arrays by
its vertices and faces), placement as given and density; a ShapeContact with its law and its sides."""
from __future__ import annotations

import os

import numpy as np

from ..errors import ModelError


def _axis(v, vec, unit):
    """"x", "y", "z" for a coordinate axis, else the vector (one whose normalisation gives it exactly)."""
    for k, e in enumerate(np.eye(3)):
        if np.array_equal(np.asarray(v, float), e):
            return "xyz"[k]
    return unit(v)


def geometry(entity, g, base_dir, vec, unit) -> dict:
    from ..geometry.meshes import ConvexMesh, Mesh
    from ..geometry.primitives import Capsule, Ellipsoid
    from ..model.shapes import Box, Cylinder, Sphere
    if isinstance(g, Box):
        return {"type": "box", "size": vec(g.size)}
    if isinstance(g, Cylinder):
        axis = g.axis if isinstance(g.axis, str) else _axis(g.axis, vec, unit)
        return {"type": "cylinder", "radius": g.radius, "length": g.length, "axis": axis}
    if isinstance(g, Capsule):
        return {"type": "capsule", "radius": g.radius, "length": g.length, "axis": _axis(g.axis, vec, unit)}
    if isinstance(g, Ellipsoid):
        return {"type": "ellipsoid", "radii": vec(g.radii)}
    if isinstance(g, Sphere):
        return {"type": "sphere", "radius": g.radius}
    if isinstance(g, ConvexMesh):
        return {"type": "convex_mesh", "vertices": [vec(p) for p in g.vertices]}
    if isinstance(g, Mesh):
        if g.abspath is None:   # made from arrays: vertices as stored (scale already applied)
            return {"type": "mesh", "vertices": [vec(p) for p in g.vertices],
                    "faces": [[int(i) for i in f] for f in g.faces]}
        path = g.abspath if base_dir is None else os.path.relpath(g.abspath, os.path.abspath(base_dir))
        d = {"type": "mesh", "path": path.replace(os.sep, "/")}
        if g.scale != 1.0:
            d["scale"] = g.scale
        return d
    raise ModelError(entity, "geometry", f"{type(g).__name__} cannot be stored in a model file")


def base_mass(b):
    """(mass [kg], inertia [kg m^2], True) the body had before its shapes with a density added theirs, when
    replaying those additions gives exactly its present mass and inertia; else (mass, inertia, False): the
    present values, the shapes then written without density."""
    added = [s.added_mass for s in b.shapes.values() if s.added_mass is not None]
    if not added:
        return b.mass, b.inertia, True
    m, J = added[0][0], added[0][1]
    for m0, J0, dm, dJ in added:
        if m0 != m or not np.array_equal(J0, J):
            return b.mass, b.inertia, False
        m, J = float(m + dm), J + (0.0 if b.is_particle else dJ)
    if m == b.mass and np.array_equal(J, np.asarray(b.inertia, float)):
        return added[0][0], added[0][1], True
    return b.mass, b.inertia, False


def shapes(b, base_dir, with_density, vec, unit, matrix) -> list:
    out = []
    for s in b.shapes.values():
        entity = f"shape '{b.name}.{s.name}'"
        d = {"name": s.name, "geometry": geometry(entity, s.geometry, base_dir, vec, unit)}
        if s.given_center is not None:
            d["center"] = vec(s.given_center)
        if s.given_orientation is not None:
            d["orientation"] = [vec(row) for row in s.given_orientation]
        if with_density and s.density is not None:
            d["density"] = s.density
        out.append(d)
    return out


def _ref(entity, field, s, legacy):
    from ..geometry.shape import Shape
    if isinstance(s, Shape):
        if s.body.shapes.get(s.name) is not s:
            raise ModelError(entity, field, f"shape {s.name!r} is not among the shapes of body {s.body.name!r}")
        return f"{s.body.name}.{s.name}"
    return legacy(s)


def shape_contact(e, legacy) -> dict:
    """A ShapeContact as a "contact" item; `legacy` writes an mb.Sphere / mb.Plane side."""
    entity = f"contact '{e.name}'"
    sides = []
    for field, side in (("shape_i", e.shapes_i), ("shape_j", e.shapes_j)):
        sides.append([_ref(entity, field, s, legacy) for s in side])
    # one shape per side is written as itself, unless the file would then build the exact sphere/plane Contact
    plain = all(not isinstance(x, str) for side in sides for x in side) and e.restitution is None \
        and e.friction_mode == 0
    if not plain:
        sides = [side[0] if len(side) == 1 else side for side in sides]
    d = {"name": e.name, "type": "contact", "shape_i": sides[0], "shape_j": sides[1], "stiffness": e.stiffness,
         "exponent": e.exponent, "damping": e.damping, "penetration": e.penetration, "mu": e.mu,
         "friction_velocity": e.friction_velocity}
    if e.restitution is not None:
        d["restitution"] = e.restitution
    if e.friction_mode == 1:
        d.update(mu_static=e.mu_static, mu_dynamic=e.mu_dynamic, stiction_velocity=e.stiction_velocity,
                 transition_velocity=e.transition_velocity)
    return d
