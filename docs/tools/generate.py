"""Pages of the documentation that come from the code and from recorded data.

Called by ``docs/conf.py`` before every build; writes into ``docs/_generated/``
(git-ignored):

* ``api/<package>.rst``: one ``automodule`` per module of each package, found by
  walking the package, so a new module appears in the API reference without editing
  the docs;
* ``validation.md``: the table of every reference case the tests check, from
  ``docs/data/validation.json`` (written by ``make validation``: the tests themselves
  record each check through ``tests/reference.py``);
* ``limits.md``: the table of the bounds every size a user types is checked against,
  from the constants of ``damper/limits.py`` and their ``#:`` comments;
* ``formats.md`` and ``extra/schemas/<name>.schema.json``: every input file format's
  keys (type, bounds, meaning) and its JSON Schema, from the typed models
  (``damper.formats``); the schema files are copied into the site's ``schemas/``;
* ``accuracy.md``, ``accuracy_upd.md``, ``accuracy_contact.md``: the truncation-error
  tables of the chains, of UPD-24 and of the 3D contact point, from
  ``docs/data/accuracy.json``, ``accuracy_upd.json`` and ``accuracy_contact.json``
  (``make docs-accuracy``), and ``accuracy_plots.md`` with its figures of error against
  time, one per model class (``accuracy_<class>.png``, drawn by ``docs/tools/plots.py``);
* ``performance.md`` and ``stress.md``: from ``docs/data/bench.json`` and
  ``docs/data/stress.json`` (written by ``make docs-bench`` and ``make docs-stress``:
  ``docs/tools/record.py`` around ``damper bench --json`` / ``damper stress --json``).

Every generated page names the command, revision, date and machine of its data.
"""
from __future__ import annotations

import json
import pkgutil
from pathlib import Path

import plots
import tables

#: The packages of the API reference, bottom layer first, with a one-line role each.
PACKAGES = {
    "contact_core": "FE contact of two bodies: bodies, condensation, normal and tangential solves, curve file.",
    "fmu_src": "The Masing/Iwan friction element: C core bindings, curve checks, FMI 2/3 FMU builder.",
    "harmonic_balance": "Forced response: force elements, AFT, Newton, continuation, stability, EPMC, bladed disk.",
    "damper": "The application: CLI, scenes, stage graph, cache, provenance, reports, sweeps, studies, bench, stress.",
}


def _write(path: Path, text: str) -> None:
    """Write only when the text changed (Sphinx then rebuilds only what changed)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def modules(package: str, root: Path) -> list[str]:
    """Dotted names of every module below ``package`` (the package itself first)."""
    names = [package]
    for info in pkgutil.walk_packages([str(root / package.replace(".", "/"))], prefix=package + "."):
        if info.name.rsplit(".", 1)[-1].startswith("_"):
            continue  # private modules (the ctypes layer) are documented through their users
        names.append(info.name)
    return names


def api_pages(docs: Path) -> None:
    root = docs.parent
    for pkg, role in PACKAGES.items():
        lines = [f"``{pkg}``", "=" * (len(pkg) + 4), "", role, ""]   # the theme lists the modules at the side
        for name in modules(pkg, root):
            lines += [name, "-" * len(name), "", f".. automodule:: {name}", ""]
        _write(docs / "_generated" / "api" / f"{pkg}.rst", "\n".join(lines))


def cli_page(docs: Path) -> None:
    """``damper COMMAND --help`` of every subcommand, as one reference page."""
    import argparse

    from damper.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    lines = ["# Command reference", "",
             "The `--help` text of every `damper` subcommand, as this version prints it. Every "
             "subcommand prints one JSON object with `--json`, uses SI units, and exits with 0 when done, 2 on "
             "bad input (a one-line message, nothing written), 3 when a solver fails and 130 when "
             "interrupted (Ctrl-C).", "",
             "```text", parser.format_help().rstrip(), "```", ""]
    for name, p in sub.choices.items():
        lines += [f"## damper {name}", "", "```text", p.format_help().rstrip(), "```", ""]
        nested = [a for a in p._actions if isinstance(a, argparse._SubParsersAction)]
        for act in nested:
            for sname, sp in act.choices.items():
                lines += [f"### damper {name} {sname}", "", "```text", sp.format_help().rstrip(), "```", ""]
    _write(docs / "_generated" / "cli.md", "\n".join(lines))


#: The two index pages whose toctrees place the pages of docs/ and docs/user/. Any other
#: page found there (added by a part of the project the indexes do not name yet) is
#: listed under "More" in the user guide, so the build neither warns nor hides it.
INDEXES = ("index.md", "user/index.md")


def toctree_pages(docs: Path) -> set[str]:
    """Pages the toctrees of :data:`INDEXES` name, as paths relative to docs/ without the
    suffix (``"getting_started"``, ``"user/mistuning"``), the indexes themselves included."""
    named = {Path(index).with_suffix("").as_posix() for index in INDEXES}
    for index in INDEXES:
        base = Path(index).parent
        inside = False
        for line in (docs / index).read_text().splitlines():
            line = line.strip()
            if line.startswith("```{toctree}"):
                inside = True
            elif line.startswith("```"):
                inside = False
            elif inside and line and not line.startswith(":"):
                named.add((base / line).as_posix())
    return named


def more_pages(docs: Path) -> None:
    """``_generated/more.md``: a toctree (relative to docs/user/) of the pages in docs/ and
    docs/user/ that no toctree of :data:`INDEXES` names."""
    named = toctree_pages(docs)
    extra = []
    for sub in ("", "user"):
        for p in sorted((docs / sub).glob("*.md")):
            if (Path(sub) / p.stem).as_posix() not in named:
                extra.append(p.stem if sub == "user" else f"../{p.stem}")
    text = ("```{toctree}\n:maxdepth: 1\n:caption: More\n\n" + "\n".join(extra) + "\n```\n") if extra else ""
    _write(docs / "_generated" / "more.md", text)


#: Modules whose upper-case constants with a ``#:`` reason are the bounds of limits.md:
#: the sizes a user types, and the input files' caps.
LIMIT_MODULES = ("damper/limits.py", "contact_core/fileio.py")


def limits_page(docs: Path) -> None:
    """``_generated/limits.md``: every constant of :data:`LIMIT_MODULES` with its ``#:`` reason."""
    rows = []
    for module in LIMIT_MODULES:
        rows += _limit_rows((docs.parent / module).read_text())
    text = "| constant | bound | what it bounds, and why |\n|---|---|---|\n" + "\n".join(rows) + "\n"
    _write(docs / "_generated" / "limits.md", text)


def _limit_rows(src: str) -> list[str]:
    """Table rows of the numeric upper-case constants of one module's source with their ``#:`` comments."""
    import ast

    lines = src.splitlines()
    rows = []
    for node in ast.parse(src).body:
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)
                and node.targets[0].id.isupper() and not node.targets[0].id.startswith("_")):
            continue
        k, why = node.lineno - 2, []
        while k >= 0 and lines[k].lstrip().startswith("#:"):
            why.insert(0, lines[k].lstrip()[2:].strip())
            k -= 1
        value = _number(node.value)
        if value is None:
            continue   # a message text (e.g. RING_BLADES_WHY) or an object, not a bound
        shown = f"{value:g}" if isinstance(value, float) else f"{value:,}".replace(",", " ")
        if node.targets[0].id.endswith("_BYTES") and value >= 2**20:
            shown += f" ({value / 2**30:g} GiB)" if value >= 2**30 else f" ({value / 2**20:g} MiB)"
        rows.append(f"| `{node.targets[0].id}` | {shown} | {' '.join(why)} |")
    return rows


def _number(node):
    """The int or float value of a constant expression of numbers (``16 * 2**20``), else None."""
    import ast

    allowed = (ast.Expression, ast.Constant, ast.BinOp, ast.UnaryOp, ast.operator, ast.unaryop)
    tree = ast.Expression(node)
    if not all(isinstance(n, allowed) for n in ast.walk(tree)):
        return None
    value = eval(compile(tree, "<limit>", "eval"), {"__builtins__": {}})  # numbers and operators only
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def formats_page(docs: Path) -> None:
    """``_generated/formats.md`` (a table of keys per format) and the schema files."""
    from damper.formats import FORMATS, json_schema, write_schemas

    write_schemas(docs / "_generated" / "extra" / "schemas")
    parts = []
    for name, (what, used, _) in FORMATS.items():
        schema = json_schema(name)
        parts += [f"## {what}", "", f"Read by {used}. Schema: `schemas/{name}.schema.json` in this site "
                  f"(`python -m damper.formats DIR` writes it).", "",
                  "| key | type | bounds | meaning |", "|---|---|---|---|"]
        parts += [_schema_row(k, v) for k, v in _schema_keys(schema, schema)]
        parts.append("")
    _write(docs / "_generated" / "formats.md", "\n".join(parts))


def _resolve(node: dict, root: dict) -> dict:
    ref = node.get("$ref")
    return root["$defs"][ref.rsplit("/", 1)[-1]] if ref else node


def _schema_keys(node: dict, root: dict, prefix: str = ""):
    """(dotted key, schema) of every leaf key, one level of tables deep (and a named table's items)."""
    for key, sub in _resolve(node, root).get("properties", {}).items():
        sub = _resolve(sub, root)
        inner = sub.get("additionalProperties") if isinstance(sub.get("additionalProperties"), dict) else None
        kinds = sub.get("items", {}).get("oneOf", []) if sub.get("type") == "array" else []
        if kinds and not prefix:   # an array of tagged tables ([[element]] of each type)
            for ref in kinds:
                table = _resolve(ref, root)
                tag = table["properties"].get("type", {})
                yield from _schema_keys(table, root, f"{key}[type={tag.get('const', tag.get('default'))}].")
        elif "properties" in sub and not prefix:
            yield from _schema_keys(sub, root, f"{key}.")
        elif inner and "properties" in inner and not prefix:
            yield from _schema_keys(inner, root, f"{key}.NAME.")
        else:
            yield prefix + key, sub


def _schema_type(node: dict) -> str:
    if "enum" in node or "const" in node:
        return " or ".join(json.dumps(v) for v in node.get("enum", [node.get("const")]))
    if "anyOf" in node or "oneOf" in node:
        kinds = [_schema_type(n) for n in node.get("anyOf", node.get("oneOf")) if n.get("type") != "null"]
        return " or ".join(k for k in kinds if k) + (" (optional)" if any(
            n.get("type") == "null" for n in node.get("anyOf", [])) else "")
    if node.get("type") == "array":
        n = [node.get("minItems"), node.get("maxItems")]
        size = f" of {n[0]}" if n[0] is not None and n[0] == n[1] else ""
        return f"list{size} of {_schema_type(node.get('items', {})) or 'values'}"
    return {"number": "number", "integer": "integer", "string": "string", "boolean": "boolean",
            "object": "table"}.get(node.get("type"), "")


def _schema_bounds(node: dict) -> str:
    if node.get("type") == "array":
        node = node.get("items", {})
    for alt in node.get("anyOf", []):
        if alt.get("type") != "null":
            node = alt.get("items", alt) if alt.get("type") == "array" else alt
            break
    marks = (("exclusiveMinimum", "> {}"), ("minimum", ">= {}"), ("exclusiveMaximum", "< {}"), ("maximum", "<= {}"))
    return ", ".join(f.format(f"{node[k]:g}" if isinstance(node[k], float) else node[k])
                     for k, f in marks if k in node)


def _schema_row(key: str, node: dict) -> str:
    doc = node.get("description", "").replace("|", "/").replace("\n", " ")
    return f"| `{key}` | {_schema_type(node).replace('|', '/')} | {_schema_bounds(node)} | {doc} |"


def data_page(docs: Path, name: str, render) -> None:
    """Render ``docs/data/<name>.json`` with ``render(data) -> markdown``, or say how to make it."""
    src = docs / "data" / f"{name}.json"
    if src.exists():
        text = render(json.loads(src.read_text()))
    else:
        text = tables.missing(name)
    _write(docs / "_generated" / f"{name}.md", text)


def all_pages(docs: Path) -> None:
    api_pages(docs)
    cli_page(docs)
    limits_page(docs)
    formats_page(docs)
    more_pages(docs)
    data_page(docs, "validation", tables.validation)
    data_page(docs, "bench", tables.bench)
    data_page(docs, "bench_peers", tables.bench)
    data_page(docs, "bench_surface", tables.bench)
    data_page(docs, "bench_peers_1pct", tables.peers_1pct)
    data_page(docs, "bench_peers_1pct_chain5", lambda d: tables.peers_1pct(d, "bench_peers_1pct_chain5"))
    data_page(docs, "stress", tables.stress)
    data_page(docs, "accuracy", tables.accuracy)
    data_page(docs, "accuracy_upd", tables.accuracy)
    data_page(docs, "accuracy_contact", tables.accuracy)
    plots.accuracy_plots(docs)
