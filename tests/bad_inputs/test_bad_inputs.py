"""Issue 10: a catalogue of bad inputs through the API and model files (bad_input_cases.py), one
parametrized test each: the error's class, entity and field, and nothing ran (no element added, no
analysis step taken, nothing executed from a hostile expression)."""
import copy
import re

import pytest
import yaml

import mbdsim as mb
from mbdsim.solvers import dynamic, kinematic

from bad_input_cases import API_CASES, BASE_FILE, DELETE, FILE_CASES, base_model


def test_catalogue_size():
    ids = [c[0] for c in API_CASES + FILE_CASES]
    assert len(ids) == len(set(ids)) and len(ids) >= 80


@pytest.fixture
def no_analysis(monkeypatch):
    """Any integration or kinematic solve fails the test: errors must come before work starts."""
    def ran(*args, **kwargs):
        raise AssertionError("an analysis step ran before the input was refused")
    monkeypatch.setattr(dynamic, "integrate_compiled", ran)
    monkeypatch.setattr(dynamic, "_run", ran)
    monkeypatch.setattr(kinematic, "solve_at", ran)


def _names(m):
    return {k: set(getattr(m, k)) for k in ("bodies", "joints", "motions", "forces")}


@pytest.mark.parametrize("case", API_CASES, ids=[c[0] for c in API_CASES])
def test_bad_api_input(case, no_analysis, tmp_path, monkeypatch):
    cid, action, cls, entity, field = case
    monkeypatch.chdir(tmp_path)
    m = base_model()
    before = _names(m)
    with pytest.raises(cls) as err:
        action(m)
    e = err.value
    assert type(e) is cls or isinstance(e, cls)
    assert (e.entity, e.field) == (entity, field), str(e)
    assert str(e).startswith(f"{entity}.{field}: ")
    name = re.search(r"'([^']*)'", entity)
    if name and not cid.startswith(("sim-", "kin-")):   # the refused element was not added
        after = _names(m)
        for k in after:
            if name.group(1) not in before[k]:
                assert name.group(1) not in after[k], f"{entity} was added to {k}"
    assert not list(tmp_path.iterdir())   # nothing executed by a hostile expression


def _mutate(data, path, value):
    keys = path.split(".")
    node = data
    for k in keys[:-1]:
        node = node[int(k)] if isinstance(node, list) else node[k]
    last = keys[-1]
    if value is DELETE:
        del node[last]
    else:
        node[int(last) if isinstance(node, list) else last] = value


@pytest.mark.parametrize("case", FILE_CASES, ids=[c[0] for c in FILE_CASES])
def test_bad_model_file(case, tmp_path, monkeypatch):
    _, (path, value), cls, entity, field = case
    data = copy.deepcopy(BASE_FILE)
    _mutate(data, path, value)
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump(data, sort_keys=False))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(cls) as err:
        mb.load_model(f)
    e = err.value
    assert (e.entity, e.field) == (entity, field), str(e)
    assert e.file == "m.yaml" and f"{entity}.{field}: " in str(e)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.yaml"]


def test_base_file_and_model_are_valid(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump(BASE_FILE, sort_keys=False))
    assert set(mb.load_model(f).bodies) >= {"rod", "block"}
    assert set(base_model().joints) == {"pin", "slide"}
