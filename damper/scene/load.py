"""Read and validate a scene once, before anything is computed.

Every error names the key (dotted path), the file and its line, and what to change;
all problems of a file are reported together (:class:`SceneError`, a ValueError: the
CLI exits with code 2).
"""
from __future__ import annotations

import copy
import hashlib
import json
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from contact_core.fileio import MAX_ARRAY_FILE_BYTES, MAX_TEXT_FILE_BYTES, read_bounded, read_text_bounded

from . import checks, schema
from .lines import key_lines, line_of


class SceneError(ValueError):
    """A scene that cannot run; ``problems`` lists (key path, message) pairs."""

    def __init__(self, source: str, problems: list[tuple[str, int | None, str]]):
        self.source = source
        self.problems = problems
        # a key without a line (e.g. a --param of a sweep) is named without one
        text = "; ".join(f"{source}{f':{line}' if line else ''}: {key}: {msg}" if key
                         else f"{source}: {msg}" for key, line, msg in problems)
        super().__init__(text)


@dataclass(frozen=True)
class Scene:
    """A validated scene.

    Attributes
    ----------
    source : str
        The file (or a label) it came from.
    raw : dict
        The TOML as written (after overrides), for sweeps and provenance.
    data : dict
        Validated, with defaults filled in and derived values (a contact's ``radius``
        from ``diameter``, ``E2``/``nu2`` from ``E``/``nu``, each contact's ``want``).
    """

    source: str
    raw: dict
    data: dict

    @property
    def want(self) -> list[str]:
        return list(self.data["want"])

    def files(self) -> list[tuple[str, Path]]:
        """(key, absolute path) of every file the scene reads besides itself (``structure.matrices``,
        ``upd.config``): inputs of the run as much as the scene file."""
        refs = (("structure", "matrices"), ("upd", "config"))
        return [(f"{t}.{k}", Path(self.data[t][k])) for t, k in refs
                if isinstance(self.data.get(t), dict) and self.data[t].get(k)]

    def hash(self) -> str:
        """SHA-256 (16 hex digits) of the validated content (comments and layout do not count)."""
        text = json.dumps(self.data, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]


#: A named table's name ([contact.NAME]): it becomes a folder of the results (``normal_NAME``)
#: and a part of a sweep's parameter path (``contact.NAME.mu``): a name holding ``/``, ``..``
#: or ``.`` wrote a stage's files outside the output folder.
ITEM_NAME = re.compile(r"[A-Za-z0-9_-]{1,64}")


def load_scene(path: str | Path, overrides: dict | None = None) -> Scene:
    """Read, override (``{"contact.damper.mu": 0.3}``) and validate the scene file ``path``."""
    path = Path(path)
    return parse_scene(read_scene_text(path), str(path), overrides, base=path.parent)


def read_scene_text(path: str | Path) -> str:
    """The text of a scene file; SceneError naming the file if it cannot be read as text."""
    path = Path(path)
    try:
        return read_text_bounded(path, what="scene")
    except (OSError, ValueError) as err:
        text = getattr(err, "strerror", None) or str(err).replace(f"scene {path} ", "")
        raise SceneError(str(path), [("", None, f"cannot read the scene: {text}")]) from None
    except UnicodeDecodeError:
        raise SceneError(str(path), [("", None, "not a text file (a scene is TOML)")]) from None


def parse_scene(text: str, source: str = "<scene>", overrides: dict | None = None,
                base: str | Path | None = None) -> Scene:
    """Validate the scene TOML ``text`` (``source`` names it in messages; files it names are
    relative to ``base``, default the working directory)."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(source, [("", None, f"not valid TOML: {err}")]) from None
    lines = key_lines(text)
    raw = copy.deepcopy(raw)
    for key, value in (overrides or {}).items():
        set_path(raw, key, value, source)
    problems: list[tuple[tuple, str]] = []
    data = _validate(raw, problems, Path(base) if base is not None else Path.cwd())
    if problems:
        raise SceneError(source, [(".".join(map(str, p)), line_of(lines, p), m) for p, m in problems])
    return Scene(source, raw, data)


def set_path(raw: dict, dotted: str, value, source: str = "<scene>") -> None:
    """Set ``raw[a][b][c] = value`` for ``dotted = "a.b.c"``; the key must be a schema key."""
    parts = dotted.split(".")
    fields = _fields_of(parts)
    if fields is None:
        raise SceneError(source, [(dotted, None, "not a scene parameter (see damper.scene.schema)")])
    node = raw
    for p in parts[:-1]:
        node = node.setdefault(p, {})
        if not isinstance(node, dict):
            raise SceneError(source, [(dotted, None, f"{p!r} is not a table")])
    node[parts[-1]] = value


def _fields_of(parts: list[str]):
    if len(parts) == 1:
        return schema.TOP.get(parts[0])
    table = schema.TABLES.get(parts[0])
    if table is None:
        return None
    fields, named = table
    if named:
        return fields.get(parts[2]) if len(parts) == 3 else None
    return fields.get(parts[1]) if len(parts) == 2 else None


def _validate(raw: dict, problems: list, base: Path) -> dict:
    data = _check_fields(raw, schema.TOP, (), problems, skip=set(schema.TABLES))
    for name, (fields, named) in schema.TABLES.items():
        if name not in raw:
            continue
        table = raw[name]
        if not isinstance(table, dict):
            problems.append(((name,), "must be a table"))
            continue
        if named:
            data[name] = {}
            for item, sub in table.items():
                if not ITEM_NAME.fullmatch(item):
                    problems.append(((name, item), f"name {item!r}: use 1 to 64 letters, digits, '_' or '-' "
                                     "(it names the result's folder and the sweep's parameter path)"))
                    continue
                if not isinstance(sub, dict):
                    problems.append(((name, item), f"must be a table [{name}.{item}] of contact options"))
                    continue
                data[name][item] = _check_fields(sub, fields, (name, item), problems)
        else:
            data[name] = _check_fields(table, fields, (name,), problems)
    if not problems:
        _check_contacts(data, problems)
        _check_structure(data, problems, base)
        _check_upd(data, problems, base)
        _check_wants(data, problems, raw)
    if not problems:   # what the stages would refuse only when they run
        checks.check_contacts(data, problems)
        checks.check_element(data, problems)
        checks.check_response(data, problems)
        checks.check_upd(data, problems)
        checks.check_upd_contacts(data, problems)
    return data


def _check_structure(data: dict, problems: list, base: Path) -> None:
    s = data.get("structure")
    if s is None:
        return
    for key in schema.STRUCTURE_NEEDS[s["model"]]:
        if key not in s:
            problems.append((("structure", key), f"missing: structure model {s['model']!r} needs it"))
    unused = [k for k in s if k != "model" and k not in schema.STRUCTURE_NEEDS[s["model"]]]
    for key in unused:
        problems.append((("structure", key), f"not used by structure model {s['model']!r}"))
    if s["model"] == "matrices" and "matrices" in s:
        path = (base / s["matrices"]).resolve()
        try:
            s["matrices_sha256"] = hashlib.sha256(read_bounded(path, MAX_ARRAY_FILE_BYTES, "file")).hexdigest()
        except (OSError, ValueError) as err:
            problems.append((("structure", "matrices"), f"cannot read {path}: {getattr(err, 'strerror', None) or err}"))
        s["matrices"] = str(path)
        if "element_dofs" in s and len(s["element_dofs"]) not in (1, 2):
            problems.append((("structure", "element_dofs"), "must be [a] (to the ground) or [a, b]"))


def _check_fields(table: dict, fields: dict, path: tuple, problems: list, skip=()) -> dict:
    out = {}
    for key, value in table.items():
        if key in skip:
            continue
        f = fields.get(key)
        if f is None:
            known = ", ".join(sorted(fields) + sorted(skip))
            problems.append((path + (key,), f"unknown key (known here: {known})"))
            continue
        msg = schema.check_value(f, value)
        if msg:
            problems.append((path + (key,), msg))
        out[key] = value
    for key, f in fields.items():
        if key in out:
            continue
        if f.required:
            problems.append((path + (key,), f"missing (required: {f.doc})"))
        elif f.default is not None:
            out[key] = copy.deepcopy(f.default)
    return out


def _check_contacts(data: dict, problems: list) -> None:
    for name, c in data.get("contact", {}).items():
        path = ("contact", name)
        for options in schema.BODY_SIZES[c["body"]]:
            given = [o for o in options if o in c]
            if not given:
                problems.append((path + (options[0],), f"missing: body {c['body']!r} needs "
                                 + " or ".join(repr(o) for o in options)))
            elif len(given) > 1:
                problems.append((path + (given[1],), f"give {' or '.join(map(repr, given))}, not both"))
        if "height" in c and c["body"] != "flat":
            problems.append((path + ("height",), f"applies to the flat face only, not to {c['body']!r}"))
        if "diameter" in c and "radius" not in c:
            c["radius"] = 0.5 * c["diameter"]
        c.setdefault("zone_load", c["force"])
        c.setdefault("E2", c["E"])
        c.setdefault("nu2", c["nu"])


def _check_wants(data: dict, problems: list, raw: dict) -> None:
    """The wanted results against the tables they need (``raw``: the scene as written)."""
    wants = data["want"]
    contacts = data.get("contact", {})
    for i, w in enumerate(wants):
        if w in schema.PLANNED:
            problems.append((("want",), f"item {i}: {w!r}: {schema.PLANNED[w]}"))
        elif w not in schema.RESULTS:
            problems.append((("want",), f"item {i}: unknown result {w!r} (known: {', '.join(schema.RESULTS)})"))
    if problems:
        return
    contact_wants = [w for w in wants if schema.RESULTS[w][1]]
    for name, c in contacts.items():
        own = c.get("want")
        if own is not None:
            bad = [w for w in own if w not in schema.RESULTS or not schema.RESULTS[w][1]]
            if bad:
                problems.append((("contact", name, "want"), f"not a contact result: {bad[0]!r} (contact "
                                 f"results: {', '.join(k for k, v in schema.RESULTS.items() if v[1])})"))
                continue   # its stages cannot be named
        c["want"] = list(own) if own is not None else list(contact_wants)
        if any(schema.RESULTS[w][0] == "tangential" for w in c["want"]) and "mu" not in c:
            problems.append((("contact", name, "mu"), "missing: needed for "
                             + ", ".join(w for w in c["want"] if schema.RESULTS[w][0] == "tangential")))
    if any(schema.RESULTS[w][1] for w in wants) and not contacts:
        problems.append((("contact",), f"missing: {', '.join(contact_wants)} need at least one [contact.NAME]"))
    bb = data.get("backbone")
    element_wants = [w for w in wants if w in ("loop", "fmu", "frf")
                     or (w == "backbone" and bb is not None and bb["element"] == "contact")]
    if element_wants:
        el = data.get("element")
        if el is None:
            problems.append((("element",), f"missing: {', '.join(element_wants)} need an [element] table"))
        elif el["contact"] not in contacts:
            problems.append((("element", "contact"), f"no contact named {el['contact']!r} (contacts: "
                             f"{', '.join(contacts) or 'none'})"))
        elif "mu" not in contacts[el["contact"]] and not any(p == ("contact", el["contact"], "mu")
                                                              for p, _ in problems):
            problems.append((("contact", el["contact"], "mu"), f"missing: needed for {', '.join(element_wants)}"))
        if el is not None and "loop" in wants and "loop_force_amplitude" not in el:
            problems.append((("element", "loop_force_amplitude"), "missing: needed for loop"))
    if "backbone" in wants:
        _check_backbone(data, problems)
    if "mistuning" in wants:
        _check_mistuning(data, problems)
    for w in ("optimal_load", "upd_frf"):
        if w in wants and "upd" not in data:
            problems.append((("upd",), f"missing: needed for {w} (an empty [upd] table takes the "
                             "bundled UPD-24 model and its defaults)"))
    if "upd" in data:
        _check_upd_contacts(data, problems, set(raw["upd"]))
    if "frf" in wants:
        for table in ("structure", "excitation", "sweep"):
            if table not in data:
                problems.append(((table,), "missing: needed for frf"))
        sweep = data.get("sweep")
        if sweep and not sweep["f_max"] > sweep["f_min"]:
            problems.append((("sweep", "f_max"), f"must be > f_min = {sweep['f_min']:g} Hz"))


def _check_backbone(data: dict, problems: list) -> None:
    """The [backbone] table and the [structure] it needs; keys of the other element refused."""
    bb = data.get("backbone")
    for table in ("structure", "backbone"):
        if table not in data:
            problems.append(((table,), "missing: needed for backbone"))
    if bb is None:
        return
    for key in schema.BACKBONE_NEEDS[bb["element"]]:
        if key not in bb:
            problems.append((("backbone", key), f"missing: backbone element {bb['element']!r} needs it"))
    for key in set().union(*schema.BACKBONE_NEEDS.values()) - set(schema.BACKBONE_NEEDS[bb["element"]]):
        if key in bb:
            problems.append((("backbone", key), f"not used by backbone element {bb['element']!r}"))
    a = bb["amplitude"]
    if len(a) != 2 or not a[1] > a[0]:
        problems.append((("backbone", "amplitude"), "must be [start, end] with end > start"))


def _check_upd(data: dict, problems: list, base: Path) -> None:
    """The [upd] table: its model file read and hashed (the stage key holds the content)."""
    u = data.get("upd")
    if u is None:
        return
    lo_hi = u["cf_range"]
    if len(lo_hi) != 2 or not lo_hi[1] > lo_hi[0]:
        problems.append((("upd", "cf_range"), "must be [low, high] with high > low"))
    band = u.get("band")
    if band is not None and not (len(band) == 2 and band[1] > band[0]):
        problems.append((("upd", "band"), "must be [low, high] with high > low [Hz]"))
    if "config" in u:
        path = (base / u["config"]).resolve()
        try:
            u["config_sha256"] = hashlib.sha256(read_bounded(path, MAX_TEXT_FILE_BYTES, "file")).hexdigest()
        except (OSError, ValueError) as err:
            problems.append((("upd", "config"), f"cannot read {path}: {getattr(err, 'strerror', None) or err}"))
        u["config"] = str(path)
    if len(lo_hi) == 2 and not any(p[0] == ("upd", "config") for p in problems):
        from damper import limits
        from harmonic_balance.bladed_disk.config import load_config

        try:
            f0 = load_config(u.get("config")).f0
        except (OSError, ValueError):   # the model file's own check reports it
            return
        try:
            limits.check_cf_floor("cf_range low", lo_hi[0], f0, None, "or start the range there")
        except ValueError as err:
            problems.append((("upd", "cf_range"), str(err)))


def _check_upd_contacts(data: dict, problems: list, given: set) -> None:
    """[upd] contacts against the wanted results, as ``damper upd frf|optimize`` refuse them:
    the surface options only with surface contacts (their defaults filled in there, so the
    stage key holds them), surfaces at a fixed H, optimal_load's with the condensed model and
    no grid of its own (``given``: the keys the scene writes); the CF above its floor."""
    from damper import limits
    from damper.upd_frf import SURFACE_MODEL, SURFACE_NODES

    u, wants = data["upd"], data["want"]
    if u["contacts"] != "surface":
        for key in ("surface_nodes", "surface_model"):
            if key in u:
                problems.append((("upd", key), f"goes with contacts = \"surface\" (got contacts = "
                                 f"{u['contacts']!r}): set contacts = \"surface\" or drop {key}"))
    else:
        u.setdefault("surface_nodes", SURFACE_NODES)
        u.setdefault("surface_model", SURFACE_MODEL)
        if "optimal_load" in wants and u["surface_model"] != "condensed":
            problems.append((("upd", "surface_model"), "optimal_load with contacts = \"surface\" walks the "
                             "loads with surface_model = \"condensed\" (its unknowns are the same at every "
                             "load): drop surface_model"))
        if "accuracy" in u:
            problems.append((("upd", "accuracy"), "contacts = \"surface\" runs at the fixed harmonics: "
                             "drop accuracy"))
        if "grid" in given and "optimal_load" in wants and "upd_frf" not in wants:   # upd_frf's curve uses it
            problems.append((("upd", "grid"), "optimal_load with contacts = \"surface\" searches each peak by "
                             "Brent's method, not on a grid: drop grid"))
        from damper.upd_surface import MAX_OPTIMIZE_POINTS

        if "optimal_load" in wants and u["points"] > MAX_OPTIMIZE_POINTS:
            problems.append((("upd", "points"), f"at most {MAX_OPTIMIZE_POINTS} with contacts = \"surface\" "
                             "(each load a peak search of minutes): lower points"))
    if "upd_frf" in wants and "cf" in u and not any(p[0] == ("upd", "config") for p in problems):
        from harmonic_balance.bladed_disk.config import load_config

        try:
            f0 = u.get("f0") or load_config(u.get("config")).f0
        except (OSError, ValueError):   # the model file's own check reports it
            return
        try:
            limits.check_cf_floor("cf", u["cf"], f0, None, "or drop cf (the model's own)")
        except ValueError as err:
            problems.append((("upd", "cf"), str(err)))


def _check_mistuning(data: dict, problems: list) -> None:
    """The [mistuning] table: every pattern drawn and checked now (a scatter so large that
    a blade's stiffness is not positive is refused before any stage runs)."""
    from damper.mistuning import study_from_scene

    m = data.get("mistuning")
    if m is None:
        problems.append((("mistuning",), "missing: needed for mistuning (an empty [mistuning] table "
                         "takes 20 samples of std 0.02 on the bundled UPD-24)"))
        return
    if "factors" in m and any(k in m for k in ("std", "samples", "seed")):
        problems.append((("mistuning", "factors"), "give factors or std/samples/seed, not both"))
        return
    if "band" in m and not (len(m["band"]) == 2 and m["band"][1] > m["band"][0]):
        problems.append((("mistuning", "band"), "must be [low, high] with high > low"))
        return
    try:
        study = study_from_scene(data)
        study.check()
        study.patterns(study.load().blades)
    except ValueError as err:
        problems.append((("mistuning",), str(err)))
