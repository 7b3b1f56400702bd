"""URDF reading: the file's links and joints as plain data (SI units, the file's frames), checked.

Parsed with the hardened reader of mbdsim.importers._xml; every error is a ModelFileError naming the
file, the line and the element.  Frames follow the URDF specification: a joint's origin places the
child link frame in the parent link frame (xyz [m], rpy [rad]: Rz(yaw) Ry(pitch) Rx(roll)); its axis is
in the child (joint) frame; an inertial origin places the centre of mass and the inertia axes in the
link frame.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._common import rpy_matrix
from ._xml import XmlDoc, floats

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
IGNORED = ("material", "transmission", "gazebo", "ros2_control", "sensor")


@dataclass
class Geometry:
    """A visual or collision geometry of a link: kind, size, mesh file reference and scale, pose in the link."""

    kind: str
    size: tuple
    origin: np.ndarray
    line: int | None
    file: str | None = None
    scale: tuple = (1.0, 1.0, 1.0)
    role: str = "visual"


@dataclass
class Link:
    """A URDF link: mass [kg], centre of mass and inertia axes (4x4 pose in the link frame), inertia
    about the centre of mass in the inertial axes [kg m^2]; `has_inertial` false when absent."""

    name: str
    line: int | None
    mass: float = 0.0
    inertial_origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    has_inertial: bool = False
    geometries: list = field(default_factory=list)


@dataclass
class UJoint:
    """A URDF joint: type, parent and child link names, origin (4x4 child frame in parent frame), unit
    axis in the joint frame, limits [rad or m], damping [N m s/rad or N s/m], friction [N m or N],
    mimic (joint, multiplier, offset)."""

    name: str
    type: str
    parent: str
    child: str
    line: int | None
    origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    lower: float | None = None
    upper: float | None = None
    damping: float = 0.0
    friction: float = 0.0
    mimic: tuple | None = None


@dataclass
class Robot:
    """A parsed URDF file: its name, links and joints by name (file order), the root link."""

    name: str
    links: dict
    joints: dict
    root: str
    doc: XmlDoc


def parse_robot(doc: XmlDoc, notes: list) -> Robot:
    """The Robot of a parsed URDF document; ModelFileError naming file and line on any defect."""
    root = doc.root
    if root.tag != "robot":
        raise doc.error(root, "file", "(root)", f"a URDF file's root element is <robot>, got <{root.tag}>")
    links, joints = {}, {}
    for el in root:
        if el.tag == "link":
            lk = _link(doc, el)
            if lk.name in links:
                raise doc.error(el, f"link '{lk.name}'", "name", "a link of this name is already defined "
                                f"(line {links[lk.name].line})")
            links[lk.name] = lk
        elif el.tag == "joint":
            jt = _joint(doc, el)
            if jt.name in joints:
                raise doc.error(el, f"joint '{jt.name}'", "name", "a joint of this name is already defined "
                                f"(line {joints[jt.name].line})")
            joints[jt.name] = jt
        elif el.tag in IGNORED:
            if el.tag != "material":
                notes.append(f"<{el.tag}> at line {doc.line(el)} is not read")
        elif isinstance(el.tag, str):
            notes.append(f"unknown element <{el.tag}> at line {doc.line(el)} is not read")
    if not links:
        raise doc.error(root, f"robot '{root.get('name', '')}'", "link", "the file defines no link")
    return Robot(root.get("name") or "robot", links, joints, _root_link(doc, links, joints), doc)


def _name(doc, el, what) -> str:
    name = el.get("name")
    if not name or not name.strip():
        raise doc.error(el, what, "name", f"a <{what}> needs a non-empty name attribute")
    return name


def _origin(doc, el, entity) -> np.ndarray:
    """4x4 pose of an <origin> child of `el` (identity when absent)."""
    o = el.find("origin")
    T = np.eye(4)
    if o is None:
        return T
    T[:3, 3] = floats(doc, o, "xyz", 3, [0.0, 0.0, 0.0], entity)
    T[:3, :3] = rpy_matrix(floats(doc, o, "rpy", 3, [0.0, 0.0, 0.0], entity))
    return T


def _number(doc, el, attr, entity, default=None, minimum=None):
    vals = floats(doc, el, attr, 1, None, entity)
    if vals is None:
        if default is None:
            raise doc.error(el, entity, attr, f"<{el.tag}> needs the attribute {attr!r}")
        return default
    if minimum is not None and vals[0] < minimum:
        raise doc.error(el, entity, attr, f"must be >= {minimum}, got {vals[0]!r}")
    return vals[0]


def _link(doc, el) -> Link:
    name = _name(doc, el, "link")
    entity = f"link '{name}'"
    lk = Link(name, doc.line(el))
    inertial = el.find("inertial")
    if inertial is not None:
        lk.has_inertial = True
        lk.inertial_origin = _origin(doc, inertial, entity)
        m = inertial.find("mass")
        lk.mass = 0.0 if m is None else _number(doc, m, "value", entity, minimum=0.0)
        it = inertial.find("inertia")
        if it is not None:
            c = {k: _number(doc, it, k, entity, default=0.0) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
            J = np.array([[c["ixx"], c["ixy"], c["ixz"]], [c["ixy"], c["iyy"], c["iyz"]],
                          [c["ixz"], c["iyz"], c["izz"]]])
            ev = np.linalg.eigvalsh(J)
            if ev[0] < -1e-9 * max(1.0, abs(ev[-1])):
                raise doc.error(it, entity, "inertia", f"is not positive semi-definite (principal moments "
                                f"{', '.join(f'{v:.6g}' for v in ev)})")
            lk.inertia = J
    for role in ("visual", "collision"):
        for v in el.findall(role):
            g = _geometry(doc, v, entity, role)
            if g is not None:
                lk.geometries.append(g)
    return lk


def _geometry(doc, v, entity, role) -> Geometry | None:
    geo = v.find("geometry")
    shape = None if geo is None else next((c for c in geo if isinstance(c.tag, str)), None)
    if shape is None:
        raise doc.error(v, entity, role, f"<{role}> needs a <geometry> with a shape")
    origin, line = _origin(doc, v, entity), doc.line(shape)
    kind = shape.tag
    if kind == "box":
        return Geometry("box", tuple(floats(doc, shape, "size", 3, None, entity) or _missing(doc, shape, entity, "size")),
                        origin, line, role=role)
    if kind == "sphere":
        return Geometry("sphere", (_number(doc, shape, "radius", entity, minimum=0.0),), origin, line, role=role)
    if kind in ("cylinder", "capsule"):
        return Geometry(kind, (_number(doc, shape, "radius", entity, minimum=0.0),
                               _number(doc, shape, "length", entity, minimum=0.0)), origin, line, role=role)
    if kind == "mesh":
        fn = shape.get("filename")
        if not fn:
            raise doc.error(shape, entity, "filename", "a <mesh> needs a filename")
        scale = floats(doc, shape, "scale", None, [1.0, 1.0, 1.0], entity)
        scale = scale * 3 if len(scale) == 1 else scale
        if len(scale) != 3:
            raise doc.error(shape, entity, "scale", "expected 1 or 3 numbers")
        return Geometry("mesh", (), origin, line, fn, tuple(scale), role)
    raise doc.error(shape, entity, role, f"unknown geometry <{kind}> (box, sphere, cylinder, capsule or mesh)")


def _missing(doc, el, entity, attr):
    raise doc.error(el, entity, attr, f"<{el.tag}> needs the attribute {attr!r}")


def _joint(doc, el) -> UJoint:
    name = _name(doc, el, "joint")
    entity = f"joint '{name}'"
    jtype = el.get("type")
    if jtype not in JOINT_TYPES:
        raise doc.error(el, entity, "type", f"unsupported joint type {jtype!r} (supported: {', '.join(JOINT_TYPES)})")
    ends = {}
    for tag in ("parent", "child"):
        e = el.find(tag)
        if e is None or not e.get("link"):
            raise doc.error(el, entity, tag, f"a joint needs <{tag} link=\"...\"/>")
        ends[tag] = e.get("link")
    jt = UJoint(name, jtype, ends["parent"], ends["child"], doc.line(el), _origin(doc, el, entity))
    ax = el.find("axis")
    if ax is not None:
        a = np.array(floats(doc, ax, "xyz", 3, [1.0, 0.0, 0.0], entity))
        n = float(np.linalg.norm(a))
        if n < 1e-12 and jtype not in ("fixed", "floating"):
            raise doc.error(ax, entity, "axis", "the axis must be a non-zero vector")
        jt.axis = a / n if n >= 1e-12 else np.array([1.0, 0.0, 0.0])
    lim = el.find("limit")
    if lim is not None and jtype in ("revolute", "prismatic"):
        lo, hi = _number(doc, lim, "lower", entity, 0.0), _number(doc, lim, "upper", entity, 0.0)
        if hi < lo:
            raise doc.error(lim, entity, "upper", f"the upper limit {hi!r} is below the lower limit {lo!r}")
        if hi > lo:
            jt.lower, jt.upper = lo, hi
    dyn = el.find("dynamics")
    if dyn is not None:
        jt.damping = _number(doc, dyn, "damping", entity, 0.0, minimum=0.0)
        jt.friction = _number(doc, dyn, "friction", entity, 0.0, minimum=0.0)
    mim = el.find("mimic")
    if mim is not None:
        if not mim.get("joint"):
            raise doc.error(mim, entity, "mimic", "<mimic> needs a joint attribute")
        jt.mimic = (mim.get("joint"), _number(doc, mim, "multiplier", entity, 1.0),
                    _number(doc, mim, "offset", entity, 0.0))
    return jt


def _root_link(doc, links, joints) -> str:
    """The one link that is no joint's child; ModelFileError for unknown links, two parents, loops."""
    parent_of = {}
    for jt in joints.values():
        el_entity = f"joint '{jt.name}'"
        for tag, lk in (("parent", jt.parent), ("child", jt.child)):
            if lk not in links:
                raise _err(doc, jt, el_entity, tag, f"no link named {lk!r} in the file")
        if jt.parent == jt.child:
            raise _err(doc, jt, el_entity, "child", "a joint needs two different links")
        if jt.child in parent_of:
            raise _err(doc, jt, el_entity, "child", f"link {jt.child!r} is already the child of joint "
                       f"{parent_of[jt.child].name!r}: URDF describes a tree (use MJCF or Adams for loops)")
        parent_of[jt.child] = jt
    roots = [n for n in links if n not in parent_of]
    if len(roots) != 1:
        what = "no root link (the joints form a loop)" if not roots else \
            f"{len(roots)} root links ({', '.join(roots[:5])}): every link but one must be a joint's child"
        lk = links[roots[1]] if len(roots) > 1 else next(iter(links.values()))
        raise _err(doc, lk, "robot", "link", what)
    return roots[0]


def _err(doc, item, entity, fld, message):
    """A ModelFileError at the line of a parsed link or joint."""
    from ..errors import ModelFileError
    return ModelFileError(entity, fld, message, doc.source, item.line)
