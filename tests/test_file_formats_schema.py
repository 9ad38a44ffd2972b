"""The published JSON Schemas (damper.formats) agree with the readers: each schema is a
valid draft 2020-12 schema, the files the toolkit ships or writes pass it, and files the
readers refuse for a type, a range, a length or an unknown key fail it too."""
import json
import tomllib
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator

from damper.formats import FORMATS, json_schema
from damper.stress import input_fixtures as fx

ROOT = Path(__file__).resolve().parents[1]


def _valid(name: str, doc) -> bool:
    return Draft202012Validator(json_schema(name)).is_valid(doc)


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_schema_is_a_valid_json_schema(name):
    Draft202012Validator.check_schema(json_schema(name))


def test_shipped_and_written_files_pass_their_schema():
    for scene in sorted((ROOT / "examples" / "scenes").glob("*.toml")):
        assert _valid("scene", tomllib.loads(scene.read_text())), scene.name
    assert _valid("upd", tomllib.loads((ROOT / "harmonic_balance" / "bladed_disk" / "upd24.toml").read_text()))
    assert _valid("elements", tomllib.loads(fx.elements()["el_good.toml"]))
    assert _valid("curve", json.loads(fx.curves()["curve.json"]))
    assert _valid("normal-curve", json.loads(fx.typed_files()["normal_good.json"]))
    assert _valid("ring-system", fx._ring_info())


@pytest.mark.parametrize("name, fixture", [
    ("curve", "curve_mutrue.json"), ("curve", "curve_Tstr.json"), ("curve", "curve_wobble.json"),
    ("curve", "curve_huge.json"), ("normal-curve", "normal_wobble.json"), ("normal-curve", "normal_Nstr.json"),
])
def test_json_files_the_readers_refuse_fail_their_schema(name, fixture):
    assert not _valid(name, json.loads(fx.typed_files()[fixture]))


@pytest.mark.parametrize("fixture", ["upd_mutrue.toml", "upd_mdstr.toml", "upd_band3.toml", "upd_blades.toml"])
def test_upd_files_the_reader_refuses_fail_the_schema(fixture):
    assert not _valid("upd", tomllib.loads(fx.typed_files()[fixture]))


@pytest.mark.parametrize("edit", [("mu = 0.5", "mu = true"), ("grid = 7", "grid = 100000"),
                                  ("force = 120.0", 'force = "heavy"'), ("grid = 7", "grid = 7\nscael = 2.0")])
def test_scenes_the_loader_refuses_fail_the_schema(edit):
    assert not _valid("scene", tomllib.loads(fx.SMALL.replace(*edit)))


def test_forged_ring_descriptions_fail_the_schema():
    for name, info in fx.forged_ring_infos().items():
        assert not _valid("ring-system", info), name
