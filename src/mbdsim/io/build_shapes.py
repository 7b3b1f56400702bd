"""Shapes and shape contacts of a model file (issue 30), for mbdsim.io.build: a body's `shapes` become
Body.add_shape calls (mesh files resolved against the model file's folder), a contact's sides become
shapes or lists of shapes for Model.add_contact.  Errors are ItemErrors at the field's path."""
from __future__ import annotations

import os

from ..errors import ModelError


def geometry(builder, entity, g, path):
    """The mb geometry of a geometry spec; a mesh path is resolved against builder.base_dir."""
    mb = builder.mb
    if g.type == "box":
        return mb.Box(g.size)
    if g.type == "cylinder":
        return mb.Cylinder(g.radius, g.length, g.axis)
    if g.type == "capsule":
        return mb.Capsule(g.radius, g.length, g.axis)
    if g.type == "ellipsoid":
        return mb.Ellipsoid(g.radii)
    if g.type == "sphere":
        return mb.Sphere(None, g.radius)
    if g.type == "convex_mesh":
        return mb.ConvexMesh(g.vertices)
    if (g.path is None) == (g.vertices is None):
        builder.fail_at(entity, "geometry.path", "give a mesh either a file `path` or `vertices` and `faces`",
                        path + ("path",))
    if g.path is None:
        if g.faces is None:
            builder.fail_at(entity, "geometry.faces", "give the triangles (vertex index triples) with the vertices",
                            path + ("vertices",))
        return mb.Mesh(g.vertices, g.faces, scale=g.scale)
    file = g.path if builder.base_dir is None else os.path.join(builder.base_dir, g.path)
    if not os.path.isfile(file):
        where = "" if builder.base_dir is None else f" (relative to the model file's folder {builder.base_dir!r})"
        builder.fail_at(entity, "geometry.path", f"mesh file {g.path!r} not found: no file {file!r}{where}",
                        path + ("path",))
    return mb.Mesh(file, scale=g.scale)


def add_shapes(builder, body, shapes, path):
    """Body.add_shape for each ShapeSpec; `path` is the body's item path (section, index)."""
    from .build import ItemError, rotation_matrix
    for k, s in enumerate(shapes):
        at = path + ("shapes", k)
        entity = f"shape '{body.name}.{s.name}'"
        try:
            geo = geometry(builder, entity, s.geometry, at + ("geometry",))
        except ItemError:
            raise
        except ModelError as exc:
            msg = str(exc)[len(f"{exc.entity}.{exc.field}: "):]
            builder.fail_at(entity, f"geometry.{exc.field}", msg, at + ("geometry", exc.field))
        try:
            body.add_shape(s.name, geo, s.center, rotation_matrix(entity, "orientation", s.orientation), s.density)
        except ModelError as exc:
            msg = str(exc)[len(f"{exc.entity}.{exc.field}: "):]
            builder.fail_at(exc.entity, exc.field, msg, at + (exc.field,))


def shape_ref(builder, entity, field, ref):
    """A body's shape from "body.shape", or an inline sphere / plane spec."""
    if not isinstance(ref, str):
        return builder.contact_shape(entity, field, ref)
    body_name, _, name = ref.partition(".")
    body = builder.body(entity, field, body_name)
    if name not in body.shapes:
        listed = ", ".join(f"{body_name}.{n}" for n in body.shapes) or "(none)"
        builder.fail(entity, field, f"shape {ref!r} not found; shapes of {body_name!r} are: {listed}")
    return body.shapes[name]


def contact_side(builder, entity, field, side):
    """One shape, or a list of shapes, of a contact's side."""
    if isinstance(side, list):
        return [shape_ref(builder, entity, field, r) for r in side]
    return shape_ref(builder, entity, field, side)
