"""Per-point histories of shape contacts (issue 30): Result.contact_points, Result.contact_force and the
to_dataframe columns of each shape contact, per output time (ground axes, SI units):

"<contact>.Fx [N]" .Fy .Fz      total contact force on the shape_j side (normal plus friction)
"<contact>.x [m]" .y .z         centre of pressure: the touching points' mean weighted by their normal
                                forces (the plain mean while they carry no normal force)
"<contact>.nx [-]" .ny .nz      unit normal of the resultant normal force, from shape_i towards shape_j
"<contact>.points [-]"          number of touching points
"<contact>.penetration [m]"     penetration of the deepest point (0 when not touching)
"<contact>.slip_velocity [m/s]" fastest tangential slip speed of a touching point (0 when not touching)

Centre of pressure and normal are NaN at times without a touching point.  A contact between lists of
shapes pools all its pairs' points (per pair: Result.contact_points).  Everything is recomputed from the
result's states by the same compiled kernel as the run (solvers.fastcontact), so it is exactly the load
the integrator saw."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError

COLUMNS = ("time", "pair", "shape_i", "shape_j", "x", "y", "z", "nx", "ny", "nz", "penetration", "normal_force",
           "friction_x", "friction_y", "friction_z", "slip_velocity")


def _element(res, name):
    from ..model.contacts import ShapeContact
    el = res._element(name)
    if not isinstance(el, ShapeContact):
        raise ModelError(f"force element {el.name!r}", "contact", f"a {type(el).__name__} is not a shape contact "
                         "(per-point results are for Model.add_contact between shapes; a sphere-plane or "
                         "sphere-sphere contact reports through Result.spring_force)")
    return el


def _records(res, el) -> list:
    cache = res.__dict__.setdefault("_contact_records", {})
    if el.name not in cache:
        from ..system.force_elements.shape_contact import records
        cache[el.name] = records(res.system, res.frames, el)
    return cache[el.name]


def _label(shape) -> str:
    name = getattr(shape, "name", None) or getattr(getattr(shape, "source", None), "__class__", type(shape)).__name__
    return f"{shape.body.name}.{name}"


def contact_points(res, name):
    """pandas DataFrame, one row per touching point and output time (COLUMNS): the point [m] and the unit
    normal (from shape_i towards shape_j) in ground, the penetration [m], the normal force [N], the friction
    force on shape_j [N] (ground axes) and the slip speed [m/s]."""
    import pandas as pd
    el = _element(res, name)
    recs = _records(res, el)
    rows = [np.column_stack([np.full(len(rc), t), rc]) for t, rc in zip(res.time, recs) if len(rc)]
    data = np.concatenate(rows) if rows else np.zeros((0, 16))
    pair = data[:, 1].astype(int)
    labels = [(_label(a), _label(b)) for a, b in el.pairs]
    df = pd.DataFrame({"time": data[:, 0], "pair": pair,
                       "shape_i": [labels[p][0] for p in pair], "shape_j": [labels[p][1] for p in pair]})
    for k, col in enumerate(("x", "y", "z", "nx", "ny", "nz", "penetration", "normal_force", "friction_x",
                             "friction_y", "friction_z", "slip_velocity")):
        df[col] = data[:, 2 + k]
    return df


def contact_force(res, name) -> np.ndarray:
    """Total contact force [N] on the shape_j side, ground axes, (N, 3)."""
    el = _element(res, name)
    return np.array([(rc[:, 8:9] * rc[:, 4:7] + rc[:, 9:12]).sum(axis=0) if len(rc) else np.zeros(3)
                     for rc in _records(res, el)])


def pressure_centre(rc) -> tuple[np.ndarray, np.ndarray]:
    """(centre of pressure [m], unit normal of the resultant normal force) of one sample's records (k, NREC),
    ground; NaN without touching points (see the module docstring)."""
    if not len(rc):
        return np.full(3, np.nan), np.full(3, np.nan)
    Fn = np.clip(rc[:, 8], 0.0, None)
    w = Fn / Fn.sum() if Fn.sum() > 0 else np.full(len(rc), 1.0 / len(rc))
    n = w @ rc[:, 4:7]
    norm = np.linalg.norm(n)
    return w @ rc[:, 1:4], (n / norm if norm > 0 else np.full(3, np.nan))


def contact_columns(res, el) -> dict:
    """to_dataframe columns of one shape contact (module docstring)."""
    recs = _records(res, el)
    F = contact_force(res, el)
    cols = {f"{el.name}.F{c} [N]": F[:, k] for k, c in enumerate("xyz")}
    cp = [pressure_centre(rc) for rc in recs]
    P = np.array([c[0] for c in cp]).reshape(-1, 3)
    N = np.array([c[1] for c in cp]).reshape(-1, 3)
    cols.update({f"{el.name}.{c} [m]": P[:, k] for k, c in enumerate("xyz")})
    cols.update({f"{el.name}.n{c} [-]": N[:, k] for k, c in enumerate("xyz")})
    cols[f"{el.name}.points [-]"] = np.array([len(rc) for rc in recs], float)
    cols[f"{el.name}.penetration [m]"] = np.array([rc[:, 7].max() if len(rc) else 0.0 for rc in recs])
    cols[f"{el.name}.slip_velocity [m/s]"] = np.array([rc[:, 12].max() if len(rc) else 0.0 for rc in recs])
    return cols
