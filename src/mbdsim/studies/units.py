"""Units of a study's columns, for plot labels: parameters (from their quantity strings or `unit`, else
from the model-file schema field a path points at) and outputs (from the measure an expression reads).
Every unit is the SI unit of the column's values ("m", "kg", "rad/s", "N"); "" when unknown."""
from __future__ import annotations

import ast
import typing

__all__ = ["parameter_unit", "output_unit", "schema_unit", "study_units"]

# preferred SI names by dimensionality (pint's base units would write a force as kg*m/s**2)
_NAMED = ("N", "N*m", "N/m", "N*m/rad", "N*s/m", "N*m*s/rad", "J", "W", "Pa", "m/s", "m/s**2", "rad/s",
          "rad/s**2", "kg*m**2", "kg/m**3", "m", "kg", "s", "rad")

MEASURE_UNITS = {"position": "m", "velocity": "m/s", "acceleration": "m/s**2", "angular_velocity": "rad/s",
                 "angular_acceleration": "rad/s**2", "reaction_force": "N", "reaction_torque": "N*m",
                 "spring_length": "m", "spring_velocity": "m/s", "kinetic_energy": "J", "potential_energy": "J",
                 "t": "s"}
# functions that keep their argument's unit; those that give a time
_SAME = {"x", "y", "z", "norm", "abs", "max", "min", "peak", "mean", "rms", "std", "initial", "final"}
_TIME = {"time_of_max", "time_of_min", "crossing"}


def pretty(unit: str) -> str:
    """'m/s**2' -> 'm/s²', 'N*m' -> 'N·m' (for labels)."""
    return unit.replace("**2", "²").replace("**3", "³").replace("*", "·")


def _si_name(units) -> str:
    from ..io.units import registry
    ureg = registry()
    dim = ureg.Quantity(1.0, units).dimensionality
    for name in _NAMED:
        if ureg.Quantity(1.0, name).dimensionality == dim:
            return name
    return f"{ureg.Quantity(1.0, units).to_base_units().units:~C}"


def _quantity_unit(value) -> str | None:
    from ..io.units import bounded, registry
    from .design import _QUANTITY
    if not isinstance(value, str):
        return None
    m = _QUANTITY.match(value)
    if m is None or not m.group(2):
        return None
    try:
        units = registry().parse_units(bounded(m.group(2)))
    except Exception:  # noqa: BLE001 - not a quantity (an expression)
        return None
    return "" if units.dimensionless else _si_name(units)


def schema_unit(path: str) -> str:
    """SI unit of the model-file field at `path` ('bodies.rod.mass' -> 'kg', 'gravity.1' -> 'm/s**2');
    "" when the field has no fixed unit (raw values, expressions, pure numbers) or is unknown."""
    from ..io.schema import ModelSpec, UnitMark

    def walk(ann, keys):
        origin, args = typing.get_origin(ann), typing.get_args(ann)
        if origin is typing.Annotated:
            marks = [m for m in ann.__metadata__ if isinstance(m, UnitMark)]
            return (str(marks[0]) or None) if marks and not keys else walk(args[0], keys)
        if origin is typing.Union or str(origin) == "types.UnionType":
            for arg in args:
                found = walk(arg, keys)
                if found:
                    return found
            return None
        if origin is list and keys:
            return walk(args[0], keys[1:])          # an item by name or by index
        if isinstance(ann, type) and hasattr(ann, "model_fields") and keys:
            field = ann.model_fields.get(keys[0])
            if field is None:
                return None
            marks = [m for m in field.metadata if isinstance(m, UnitMark)]   # pydantic unwraps Annotated
            return (str(marks[0]) or None) if marks and len(keys) == 1 else walk(field.annotation, keys[1:])
        return None
    try:
        return walk(ModelSpec, path.split(".")) or ""
    except Exception:  # noqa: BLE001 - a label is best effort
        return ""


def parameter_unit(name: str, spec, path_is_model: bool = True) -> str:
    """SI unit of a parameter's values: its `unit`, else its first quantity string, else (a path into a
    model file) the schema field's unit; "" when unknown."""
    if isinstance(spec, dict):
        if spec.get("unit"):
            u = _quantity_unit(f"1 {spec['unit']}")
            if u is not None:
                return u
        values = [v for k in ("values", "range", "mean", "low", "median") for v in
                  (spec.get(k) if isinstance(spec.get(k), (list, tuple)) else [spec.get(k)])]
    elif isinstance(spec, (list, tuple)):
        values = list(spec)
    else:
        values = [spec]
    for v in values:
        u = _quantity_unit(v)
        if u:
            return u
    return schema_unit(name) if path_is_model and "." in name else ""


def _expr_unit(node) -> str | None:
    if isinstance(node, ast.Name):
        return MEASURE_UNITS.get(node.id)
    if isinstance(node, ast.UnaryOp):
        return _expr_unit(node.operand)
    if isinstance(node, ast.Subscript):
        return _expr_unit(node.value)
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
        a, b = _expr_unit(node.left), _expr_unit(node.right)
        return a if a == b else None
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        fn = node.func.id
        if fn in _TIME:
            return "s"
        if fn in MEASURE_UNITS:
            return MEASURE_UNITS[fn]
        if fn == "degrees":
            return "deg" if _expr_unit(node.args[0]) == "rad" else None
        if fn == "integral" and node.args:
            inner = _expr_unit(node.args[0])
            return {"N": "N*s", "N*m": "N*m*s", "W": "J", "m/s": "m", "rad/s": "rad"}.get(inner) if inner else None
        if fn in _SAME and node.args:
            return _expr_unit(node.args[0])
    return None


def output_unit(expression) -> str:
    """SI unit of an output expression's value ("max(norm(reaction_force('j')))" -> "N"); "" when it
    cannot be told (callables, products, joint coordinates whose unit depends on the joint)."""
    if not isinstance(expression, str):
        return ""
    try:
        return _expr_unit(ast.parse(expression, mode="eval").body) or ""
    except SyntaxError:
        return ""


def study_units(parameters: dict, outputs: dict, model_file: bool = True) -> dict:
    """{column: SI unit} of a study's parameters and outputs (only the known ones)."""
    units = {k: parameter_unit(k, v, model_file) for k, v in parameters.items()}
    units.update({k: output_unit(v) for k, v in outputs.items()})
    return {k: u for k, u in units.items() if u}
