"""Property-based fuzz of every input file format (Hypothesis): a good file, mutated at
random (a value replaced by one of any type, a key removed, an unknown key added) or
replaced by a random document, either loads or is refused with a one-line ValueError
that names the file -- never another exception.

Derandomized (the same examples on every machine: CI is reproducible) and small
(``MAX_EXAMPLES`` a format), so the whole module runs in seconds.
"""
import json
import math
import re
import tempfile
import tomllib
import zipfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[1]
#: Examples per format: enough to reach every key of the small good files a few times.
MAX_EXAMPLES = 60
FUZZ = settings(max_examples=MAX_EXAMPLES, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])

#: Any JSON value (the floats include NaN and infinities, which Python's json reads).
JSON = st.recursive(st.none() | st.booleans() | st.integers(-10**20, 10**20) | st.floats() | st.text(max_size=8),
                    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner,
                                                                                 max_size=4),
                    max_leaves=8)
#: TOML literals of every kind, for a value in a TOML file.
TOML_VALUES = st.sampled_from(["true", "false", '"0.005"', '""', "nan", "inf", "-inf", "-1", "0", "1e308",
                               "100000000", "1.5", "[]", "[1, 2, 3]", "[nan, 500.0]", '["a"]', "{ a = 1 }",
                               "[[1.0, 2.0], [3.0]]", "1979-05-27"])


def _refused_cleanly(err: Exception, source: str) -> None:
    assert isinstance(err, ValueError), f"{type(err).__name__}: {err}"
    text = str(err)
    assert source in text and "\n" not in text.strip(), text


def _mutations(doc):
    """Strategy: ``doc`` (a dict) with one value replaced, a key removed or an unknown key added,
    at any depth."""
    paths = []

    def walk(node, path):
        if isinstance(node, dict):
            for k, v in node.items():
                paths.append(path + (k,))
                walk(v, path + (k,))
        elif isinstance(node, list):
            for i, v in enumerate(node[:3]):
                paths.append(path + (i,))
                walk(v, path + (i,))
    walk(doc, ())

    def apply(args):
        path, how, value = args
        out = json.loads(json.dumps(doc))
        node = out
        for p in path[:-1]:
            node = node[p]
        if how == "replace":
            node[path[-1]] = value
        elif how == "remove" and isinstance(node, dict):
            del node[path[-1]]
        elif isinstance(node, dict):
            node["wobble"] = value
        return out
    return st.tuples(st.sampled_from(paths), st.sampled_from(["replace", "remove", "add"]), JSON).map(apply)


# ---------------------------------------------------------------- JSON formats
def _curve_doc() -> dict:
    u = [2.5e-6 * i / 9 for i in range(10)]
    T = [100.0 * (1.0 - (1.0 - x / u[-1]) ** 1.5) for x in u]
    return {"schema": "damper-virgin-curve/2", "u": u, "T": T, "tail": "flat", "N": 200.0, "mu": 0.5,
            "k_t": 6e7, "load_case": "CNF", "provenance": {"command": "test"}}


def _normal_doc() -> dict:
    return {"schema": "damper-normal-curve/1", "approach": [0.0, 1e-6, 2e-6], "N": [0.0, 50.0, 140.0],
            "load": 140.0, "k_n": [5e7, 5e7, 9e7]}


def _load_curve(doc):
    from contact_core.curve import VirginCurve

    return VirginCurve.from_dict(doc, "c.json")


def _load_normal(doc):
    from contact_core.normal_curve import NormalCurve

    return NormalCurve.from_dict(doc, "n.json")


def _check(load, doc, source):
    try:
        load(doc)
    except Exception as err:  # noqa: BLE001  (the property: only ValueError)
        _refused_cleanly(err, source)


def test_good_curve_and_normal_curve_load():
    assert _load_curve(_curve_doc()).tail == "flat"
    assert _load_normal(_normal_doc()).load == 140.0


@FUZZ
@given(_mutations(_curve_doc()) | JSON)
def test_mutated_curve_file_loads_or_is_refused_with_its_name(doc):
    _check(_load_curve, doc, "c.json")


@FUZZ
@given(_mutations(_normal_doc()) | JSON)
def test_mutated_normal_curve_file_loads_or_is_refused_with_its_name(doc):
    _check(_load_normal, doc, "n.json")


def _ring_doc() -> dict:
    from damper.stress.input_fixtures import _ring_info

    return _ring_info()


_TMP = Path(tempfile.mkdtemp(prefix="damper_fuzz_"))


def _load_ring(doc):
    from damper.cosim import read_info

    path = _TMP / "ring.ssp"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("resources/system.json", json.dumps(doc))
    return read_info(path)


def test_good_ring_description_loads():
    assert _load_ring(_ring_doc())["ring_blades"] == 4


@FUZZ
@given(_mutations(_ring_doc()) | JSON)
def test_mutated_ring_description_loads_or_is_refused_with_its_name(doc):
    _check(_load_ring, doc, "ring.ssp")


# ---------------------------------------------------------------- TOML formats
_ASSIGN = re.compile(r"^(\s*[A-Za-z0-9_]+\s*=\s*)(.*)$")


def _toml_mutations(text: str):
    """Strategy: ``text`` with one ``key = value`` line's value replaced by a TOML literal of
    any kind, the line removed, or an unknown key added after it."""
    lines = text.splitlines()
    assigns = [i for i, line in enumerate(lines) if _ASSIGN.match(line) and not line.rstrip().endswith("[")]

    def apply(args):
        i, how, value = args
        out = list(lines)
        m = _ASSIGN.match(out[i])
        if how == "replace":
            out[i] = m.group(1) + value
        elif how == "remove":
            out[i] = ""
        else:
            out.insert(i + 1, f"wobble = {value}")
        return "\n".join(out) + "\n"
    return st.tuples(st.sampled_from(assigns), st.sampled_from(["replace", "remove", "add"]), TOML_VALUES).map(apply)


def _load_scene(text):
    from damper.scene import parse_scene

    return parse_scene(text, "s.toml", base=ROOT / "examples" / "scenes")


def _load_upd(text):
    from harmonic_balance.bladed_disk.config import load_config

    path = _TMP / "u.toml"
    path.write_text(text)
    return load_config(path)


def _load_elements(text):
    from harmonic_balance.model import load_elements

    path = _TMP / "el.toml"
    path.write_text(text)
    return load_elements(path)


_SCENE = (ROOT / "examples" / "scenes" / "default.toml").read_text()
_UPD = "[disk]\nblades = 24\nengine_order = 6\n[damper]\nm_d = 0.005\nmu = 0.5\nleft_point = [-4.0e-3, 2.0e-3]\n" \
       "[load]\nf0 = 30.0\ncf = 120.0\nband_hz = [400.0, 500.0]\n[geometry]\ngrid = 15\n"
_ELEMENTS = ('[[element]]\ndofs = [1]\ntype = "jenkins"\nk = 3.85e7\nfs = 60.0\n'
             '[[element]]\ndofs = [0, 1]\ntype = "sliders"\nk = [1e5, 5e4]\nfs = [1.0, 2.0]\nk_res = 0.0\n'
             '[[element]]\ntype = "contact"\ndofs = [0, 1]\nnormal = [0.0, 1.0]\ntangent = [1.0, 0.0]\n'
             "k_n = 1e8\nk_t = 8e7\nmu = 0.5\npreload = 0.0\nslip_ref = 0.0\nbeta_c = 0.0\n")


def test_good_toml_files_load():
    assert _load_scene(_SCENE).data["want"]
    assert _load_upd(_UPD).blades == 24
    assert len(_load_elements(_ELEMENTS)) == 3


@FUZZ
@given(_toml_mutations(_SCENE))
def test_mutated_scene_loads_or_is_refused_with_its_name(text):
    _check(_load_scene, text, "s.toml")


@FUZZ
@given(_toml_mutations(_UPD))
def test_mutated_upd_model_loads_or_is_refused_with_its_name(text):
    _check(_load_upd, text, "u.toml")


@FUZZ
@given(_toml_mutations(_ELEMENTS))
def test_mutated_elements_file_loads_or_is_refused_with_its_name(text):
    _check(_load_elements, text, "el.toml")


def _upd_data() -> dict:
    return tomllib.loads((ROOT / "harmonic_balance" / "bladed_disk" / "upd24.toml").read_text())


def _load_upd_data(data):
    from harmonic_balance.bladed_disk.config import UPDConfig

    cfg = UPDConfig(data, source="u.toml")
    cfg.validate()
    return cfg


@FUZZ
@given(_mutations(_upd_data()))
def test_upd_model_with_any_value_anywhere_loads_or_is_refused_with_its_name(data):
    """Deeper than TOML text edits: any JSON value (tables, nested lists) at any key."""
    _check(_load_upd_data, data, "u.toml")


def test_refusals_name_the_key():
    """The typed messages carry the key's path (examples of each format)."""
    doc = _curve_doc() | {"mu": True}
    try:
        _load_curve(doc)
    except ValueError as err:
        assert "c.json: mu: must be a valid number, got a boolean True" in str(err)
    else:
        raise AssertionError("mu = true was accepted")
    for text, key in ((_UPD.replace("blades = 24", "blades = 100000000"), "u.toml: disk.blades:"),
                      (_UPD.replace("[400.0, 500.0]", "[400.0, 450.0, 500.0]"), "u.toml: load.band_hz:"),
                      (_UPD.replace("m_d = 0.005", 'm_d = "0.005"'), "u.toml: damper.m_d:")):
        try:
            _load_upd(text)
        except ValueError as err:
            assert key in str(err), str(err)
        else:
            raise AssertionError(f"accepted: {key}")
    assert math.isfinite(_load_upd(_UPD).cf)
