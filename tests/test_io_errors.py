"""Malformed model files (tests/bad_models/): one clear ModelFileError naming file, line, entity and field;
nothing in a file is ever executed (the hostile ones would create a file `x`)."""
from pathlib import Path

import pytest

import mbdsim as mb
from mbdsim.errors import ModelError, ModelFileError
from mbdsim.io import model_from_dict

BAD = Path(__file__).resolve().parent / "bad_models"

# file: (entity, field, line, words the message must contain)
CASES = {
    "typo_in_key.yaml": ("body 'rod'", "masss", 10, "did you mean 'mass'"),
    "unknown_body.yaml": ("joint 'pin'", "body_j", 17, "body 'rod2' not found; bodies are: ground, crank, rod"),
    "wrong_units.yaml": ("body 'rod'", "position[1]", 12, "'2 kg' is not a length [m]"),
    "bad_expression.yaml": ("motion 'drive'", "displacement", 21, "syntax error"),
    "hostile_expression.yaml": ("motion 'drive'", "displacement", 23, "not allowed"),
    "python_object_tag.yaml": ("motion 'drive'", "displacement", 23, "YAML tag"),
    "missing_axis.yaml": ("joint 'pin'", "axis", 14, "is required"),
    "negative_mass.yaml": ("body 'rod'", "mass", 10, "must be >= 0"),
    "unknown_joint_type.yaml": ("joint 'pin'", "type", 15, "'revolut' is not known; types are: revolute"),
    "unknown_joint_reference.yaml": ("motion 'drive'", "joint", 21, "joint 'pinn' not found; joints are: pin"),
    "inertia_triangle.yaml": ("body 'rod'", "inertia", 11, "triangle inequality"),
    "boolean_mass.yaml": ("body 'rod'", "mass", 10, "boolean"),
    "zero_axis.yaml": ("joint 'pin'", "axis", 19, "non-zero"),
    "duplicate_name.yaml": ("body 'crank'", "name", 9, "already exists"),
    "bad_euler_sequence.yaml": ("body 'rod'", "orientation", 13, "ZZX"),
    "unknown_marker.yaml": ("spring 'k'", "at_i", 14, "marker 'crank.tipp' not found; markers of 'crank' are: crank.tip"),
    "hostile_unit.yaml": ("body 'rod'", "mass", 10, "cannot read"),
    "short_vector.yaml": ("joint 'pin'", "point", 18, "expected 3 values, got 2"),
    "unknown_frame.yaml": ("force 'push'", "frame", 14, "body 'rodd' not found"),
    "custom_tag.yaml": ("model", "forces", 13, "'!include' is not allowed"),
    "negative_stiffness.yaml": ("spring 'k'", "stiffness", 18, "must be >= 0"),
    "stop_without_stiffness.yaml": ("stop 'limit'", "stiffness", 21, "is required"),
    "syntax_error.yaml": ("file", "(syntax)", 15, "YAML syntax error"),
    "top_level_list.yaml": ("model", "(top level)", 1, "mapping"),
    "motion_on_spherical.yaml": ("motion 'drive'", "joint", 16, "cannot drive a spherical joint"),
    "missing_field.json": ("joint 'pin'", "point", 15, "is required"),
    "alias_bomb.yaml": ("file", "(size)", 2, "once aliases are expanded"),
}


def test_every_bad_file_has_a_case():
    assert {p.name for p in BAD.iterdir()} == set(CASES) and len(CASES) >= 20


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_model_gives_one_clear_error(name, tmp_path, monkeypatch):
    entity, field, line, words = CASES[name]
    monkeypatch.chdir(tmp_path)                       # a hostile file would write ./x here
    with pytest.raises(ModelFileError) as err:
        mb.load_model(BAD / name)
    e = err.value
    assert (e.entity, e.field, e.line, e.file) == (entity, field, line, name)
    assert words in str(e)
    assert str(e).startswith(f"{name}, line {line}: {entity}.{field}: ")
    assert isinstance(e, ModelError) and e.__cause__ is None
    assert not (tmp_path / "x").exists()


def test_errors_from_a_dict_name_the_source_and_no_line():
    with pytest.raises(ModelFileError) as err:
        model_from_dict({"bodies": [{"name": "a", "mass": "1 m"}]}, source="study.yaml#case3")
    assert err.value.file == "study.yaml#case3" and err.value.line is None
    assert str(err.value) == "study.yaml#case3: body 'a'.mass: '1 m' is not a mass [kg]: its dimension is [length]"


def test_unknown_extension_and_missing_file(tmp_path):
    with pytest.raises(ModelFileError, match="unknown model file extension '.txt'"):
        mb.load_model(tmp_path / "m.txt")
    with pytest.raises(ModelFileError, match="cannot read"):
        mb.load_model(tmp_path / "absent.yaml")


def test_json_syntax_error_has_a_line(tmp_path):
    p = tmp_path / "m.json"
    p.write_text('{\n  "name": "x",\n  "bodies": [\n}\n')
    with pytest.raises(ModelFileError) as err:
        mb.load_model(p)
    assert err.value.line == 4 and "JSON syntax error" in str(err.value)


def test_duplicate_yaml_keys_are_refused(tmp_path):
    p = tmp_path / "m.yaml"
    p.write_text("name: a\nbodies: []\nbodies: []\n")
    with pytest.raises(ModelFileError, match="duplicate key 'bodies'") as err:
        mb.load_model(p)
    assert err.value.line == 3


def test_nested_unknown_field_and_missing_type():
    with pytest.raises(ModelFileError, match=r"body 'a'.shape.sise: unknown field 'sise' \(did you mean 'size'\?\)"):
        model_from_dict({"bodies": [{"name": "a", "shape": {"type": "box", "sise": [1, 1, 1]}, "density": 1}]})
    with pytest.raises(ModelFileError, match=r"element #1 of forces.type: needs a 'type'"):
        model_from_dict({"forces": [{"body": "ground"}]})
