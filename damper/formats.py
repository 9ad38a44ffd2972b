"""Every file format a user writes, with its JSON Schema: the scene, the UPD model, the
elements file, the curve and normal-curve files, a ring archive's ``system.json``.

Each format is described once by a typed model (:mod:`contact_core.fileformat`; the
scene by the tables of :mod:`damper.scene.schema`), which checks the file when it is
read and gives the JSON Schema here, for editors that check and complete files as they
are typed (see the user guide's scene page). ``python -m damper.formats DIR`` writes
``DIR/<name>.schema.json`` for each format.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def _scene() -> dict:
    from damper.scene.schema import json_schema

    return json_schema()


def _model(module: str, name: str, partial: bool = False):
    def schema() -> dict:
        import importlib

        model = getattr(importlib.import_module(module), name)
        out = model.model_json_schema()
        if partial:
            _drop_required(out)
        return {"$schema": "https://json-schema.org/draft/2020-12/schema", **out}
    return schema


def _drop_required(node) -> None:
    """A file that may give any subset of the keys (the UPD model: the rest keep UPD-24's)."""
    if isinstance(node, dict):
        node.pop("required", None)
        for v in node.values():
            _drop_required(v)
    elif isinstance(node, list):
        for v in node:
            _drop_required(v)


#: name -> (what the file is, where it is used, its JSON Schema).
FORMATS = {
    "scene": ("scene (TOML)", "damper run / sweep / study", _scene),
    "upd": ("UPD bladed-disk model (TOML; any subset of the keys of the bundled upd24.toml)",
            "damper upd ... --config, damper system --config, a scene's [upd] config",
            _model("harmonic_balance.bladed_disk.config_model", "UPDFile", partial=True)),
    "elements": ("friction elements (TOML, [[element]] tables)", "damper frf / backbone --elements",
                 _model("harmonic_balance.elements_model", "ElementsFile")),
    "curve": ("virgin curve (JSON)", "damper loop / fmu --curve, an elements file's curve path",
              _model("contact_core.curve", "CurveFile")),
    "normal-curve": ("normal approach curve (JSON)", "damper fmu --normal",
                     _model("contact_core.normal_curve", "NormalCurveFile")),
    "ring-system": ("a ring archive's resources/system.json (JSON)", "damper cosim (written by damper system)",
                    _model("damper.ring_info", "RingInfo")),
}


def json_schema(name: str) -> dict:
    """The JSON Schema of format ``name`` (a key of :data:`FORMATS`)."""
    return FORMATS[name][2]()


def write_schemas(folder) -> list[Path]:
    """Write ``<name>.schema.json`` of every format into ``folder``; return the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name in FORMATS:
        path = folder / f"{name}.schema.json"
        text = json.dumps(json_schema(name), indent=1) + "\n"
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        out.append(path)
    return out


if __name__ == "__main__":   # python -m damper.formats DIR
    for p in write_schemas(sys.argv[1] if len(sys.argv) > 1 else "."):
        print(p)
