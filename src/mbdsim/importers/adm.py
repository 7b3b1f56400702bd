"""`from_adm(path)`: an Adams/Solver dataset (.adm) as an mbdsim Model (SI units).

    model = mb.from_adm("slider_crank.adm")
    model.import_notes          # what was approximated or ignored, one line per statement
    mb.simulate(model, 2.0)

The file is only read and split (mbdsim.importers.adm_lexer), never executed; function expressions are
rewritten for mbdsim's whitelist parser (adm_expr).  UNITS are converted to SI.  Entities take their
Adams View names (`adams_view_name` comments), else PART_2, JOINT_1, MARKER_3 ...; the ground part is
mbdsim's ground.  A statement mbdsim cannot represent, an unknown statement, argument or function is a
ModelFileError naming the file, the line and the statement.  The mapping of every statement:
docs/import-adm.md.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import ModelFileError
from . import adm_contact
from . import adm_forces as forces
from . import adm_joints as joints
from . import adm_parts as parts
from . import adm_spline
from .adm_context import AdmImport
from .adm_lexer import read_statements

if TYPE_CHECKING:
    from .._types import PathLike
    from ..model.model import Model

__all__ = ["from_adm", "IGNORED", "REFUSED"]

# read but without effect on the model (analysis settings, outputs): noted
IGNORED = ("REQUEST", "OUTPUT", "RESULTS", "INTEGRATOR", "KINEMATICS", "EQUILIBRIUM", "IC", "DEBUG", "LSOLVER",
           "PREFERENCES", "ENVIRONMENT", "STRING", "ARRAY", "MATRIX", "SENSOR", "LIST", "NOLIST",
           "SECTION", "MATERIAL", "UNITS_CONSISTENCY")
# Adams statements mbdsim cannot represent: refused with the file and line
REFUSED = ("BEAM", "NFORCE", "CVCV", "PTCV", "FLEX_BODY", "POINT_MASS", "GCON", "UCON", "CLEARANCE", "MFORCE",
           "CURVE", "SURFACE", "DIFF", "GSE", "LSE", "TFSISO", "PINPUT", "POUTPUT", "FE_PART", "FE_LOAD",
           "MODAL_FORCE", "FEMDATA", "MREQUEST", "USER", "CBKSUB")
ORDER = ("UNITS", "SPLINE", "VARIABLE", "PART", "MARKER", "ACCGRAV", "GRAPHICS", "JOINT", "JPRIM", "COUPLER", "GEAR",
         "MOTION", "SFORCE", "SPRINGDAMPER", "BUSHING", "FIELD", "VFORCE", "VTORQUE", "GFORCE", "FRICTION", "CONTACT")


def from_adm(path: PathLike) -> Model:
    """Read the Adams/Solver dataset at `path` (.adm) and build an mbdsim.Model in SI units: lengths in m,
    masses in kg, forces in N, times in s, angles in rad, whatever the dataset's UNITS; positions and
    axes in ground at t=0, as in every Model.  Entities take the dataset's Adams View names.

    The model gets `import_notes`: a list of what was approximated or ignored.  Errors:
    ModelFileError naming the file, the line and the statement (an unknown statement, argument or
    function; a missing marker; something mbdsim cannot represent)."""
    from ..io.files import read_bytes
    from ..model.model import Model
    path = Path(path)
    source = path.name
    try:
        raw = read_bytes(path)
    except OSError as exc:
        raise ModelFileError("file", "path", f"cannot read {str(path)!r}: {exc}", source) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    if "\x00" in text:
        raise ModelFileError("file", "path", "a binary file, not an Adams dataset", source)
    statements = read_statements(text, source)
    imp = AdmImport(source, Model(path.stem or "model"))
    imp.folder = str(path.resolve().parent)
    by_name: dict = {}
    for st in statements:
        if st.name in REFUSED:
            raise ModelFileError(st.label, st.name, f"the {st.name} statement is not supported by mbdsim", source,
                                 st.line)
        if st.name in IGNORED:
            imp.note(st, "ignored (analysis settings or output)")
            continue
        if st.name not in ORDER:
            raise ModelFileError(st.label, st.name, f"unknown statement {st.name!r} (mbdsim reads "
                                 f"{', '.join(ORDER)}; ignores {', '.join(IGNORED)})", source, st.line)
        table = by_name.setdefault(st.name, {})
        key = st.id if st.id is not None else len(table)
        if st.id is None and st.name not in ("UNITS", "ACCGRAV"):
            raise ModelFileError(st.label, "id", f"{st.name} needs an id ({st.name}/1)", source, st.line)
        if key in table:
            raise ModelFileError(st.label, "id", f"{st.label} is defined twice (first on line {table[key].line})",
                                 source, st.line)
        table[key] = st
    _build(imp, by_name)
    imp.model.import_notes = imp.notes
    return imp.model


def _build(imp, by_name) -> None:
    get = lambda name: list(by_name.get(name, {}).values())   # noqa: E731
    for st in get("UNITS")[:1]:
        parts.units(imp, st)
    for st in get("SPLINE"):
        adm_spline.spline(imp, st)
    for st in get("VARIABLE"):
        parts.variable(imp, st)
    parts.parts_and_markers(imp, by_name.get("PART", {}), by_name.get("MARKER", {}))
    for st in get("ACCGRAV"):
        parts.accgrav(imp, st)
    graphics: dict = {}
    for st in get("GRAPHICS"):
        adm_contact.graphics(imp, st, graphics)
    later: list = []
    for st in get("JOINT"):
        joints.joint(imp, st, later)
    for st in get("JPRIM"):
        joints.jprim(imp, st)
    for item in later:
        joints.screw_rackpin(imp, *item)
    for st in get("COUPLER"):
        joints.coupler(imp, st)
    for st in get("GEAR"):
        joints.gear(imp, st)
    for st in get("MOTION"):
        joints.motion(imp, st)
    for st in get("SFORCE"):
        forces.sforce(imp, st)
    for st in get("SPRINGDAMPER"):
        forces.springdamper(imp, st)
    for st in get("BUSHING"):
        forces.bushing(imp, st)
    for st in get("FIELD"):
        forces.field(imp, st)
    for name in ("VFORCE", "VTORQUE", "GFORCE"):
        for st in get(name):
            forces.vector_force(imp, st)
    for st in get("FRICTION"):
        forces.friction(imp, st)
    for st in get("CONTACT"):
        adm_contact.contact(imp, st, graphics)
