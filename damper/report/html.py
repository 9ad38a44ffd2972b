"""The one-page HTML report of a run: numbers, tables, plots, the plan with times.

Plain HTML and CSS (no script, no network): it opens from the output folder in any
browser. Plots are the PNG files of the stages, referenced relative to the report.
"""
from __future__ import annotations

import html
import json
import math
import os
from pathlib import Path

from damper.cli.common import atomic_write

CSS = """
body { font-family: sans-serif; max-width: 70em; margin: 1.5em auto; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.5em 0; } td, th { padding: 0.2em 0.7em; text-align: left; }
tr:nth-child(even) { background: #f4f4f4; } th { background: #e4e4e4; }
td.num { text-align: right; font-family: monospace; }
.compute { color: #a40; } .cached { color: #070; } .skip { color: #888; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; }
figure img { max-width: 44em; max-height: 22em; border: 1px solid #ddd; }
figcaption { font-size: 0.85em; color: #555; } .meta { color: #555; font-size: 0.9em; }
ul.warn { background: #fff4e0; border-left: 4px solid #c60; padding: 0.4em 0.4em 0.4em 2em; }
"""


def _fmt(v) -> str:
    if isinstance(v, float):
        return "-" if not math.isfinite(v) else f"{v:.6g}"
    return "-" if v is None else html.escape(str(v))


def _table(head: list, rows: list, num_cols=(1,), classes=None) -> str:
    out = ["<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in head) + "</tr>"]
    for i, row in enumerate(rows):
        cls = f' class="{classes[i]}"' if classes else ""
        cells = "".join(f'<td class="num">{_fmt(v)}</td>' if j in num_cols else f"<td>{_fmt(v)}</td>"
                        for j, v in enumerate(row))
        out.append(f"<tr{cls}>{cells}</tr>")
    return "\n".join(out + ["</table>"])


def render(rec, out_dir: Path) -> str:
    """The report's HTML text for the run record ``rec`` written into ``out_dir``."""
    scene, plan, prov = rec.scene, rec.plan, rec.provenance
    title = scene.data.get("title") or Path(scene.source).stem
    git = prov.get("git", {})
    rev = (git.get("commit") or "unknown")[:12] + (" (uncommitted changes)" if git.get("dirty") else "")
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
             f"<style>{CSS}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>",
             f"<p class='meta'>scene {html.escape(scene.source)} (hash {scene.hash()}), code {html.escape(rev)}, "
             f"{html.escape(prov.get('created', ''))}; wanted: {html.escape(', '.join(plan.want))}</p>"]
    warned = [s.name for s in plan.stages if s.name in rec.results and s.kind.warnings(s, rec.results[s.name])]
    if warned:   # at the top as well: a warning deep in the results is easily missed
        parts.append(f"<p class='meta'><b>warnings</b> in {html.escape(', '.join(warned))} (see Results)</p>")
    computed = [s for s in plan.stages if s.action == "compute"]
    cached = [s for s in plan.stages if s.action == "cached"]
    parts.append(f"<h2>Plan</h2><p>{len(computed)} stage(s) computed, {len(cached)} from the cache, "
                 f"{sum(s.action == 'skip' for s in plan.stages)} skipped; "
                 f"{sum(rec.times.values()):.2f} s in the stages.</p>")
    parts.append(_table(["stage", "action", "time [s]", "reason"],
                        [[s.name, s.action, rec.times.get(s.name), s.reason] for s in plan.stages],
                        num_cols=(2,), classes=[s.action for s in plan.stages]))
    parts.append("<h2>Results</h2>")
    for s in plan.stages:
        if s.name not in rec.results or s.kind.name == "condense":
            continue
        result = rec.results[s.name]
        scal = s.kind.scalars(s, result)
        warns = s.kind.warnings(s, result)
        if scal or warns:
            parts.append(f"<h3>{html.escape(s.name)}</h3>")
        if warns:   # the texts the stage printed as "warning: ..." (its result's *warning* fields)
            parts.append("<ul class='warn'>" + "".join(f"<li>warning: {html.escape(w)}</li>" for w in warns)
                         + "</ul>")
        if scal:
            parts.append(_table(["quantity", "value"], [[k, v] for k, v in scal.items()]))
        pngs = sorted(n for n in result.files if n.endswith(".png"))
        for name in pngs:
            src = f"{s.kind.folder(s)}/{name}"
            parts.append(f"<figure><img src='{html.escape(src)}' alt='{html.escape(s.name)}: "
                         f"{html.escape(name)}'><figcaption>{html.escape(s.name)}: {html.escape(name)}"
                         "</figcaption></figure>")
    if rec.outputs:
        parts.append("<h2>Files</h2>")
        rows = []
        for k, v in rec.outputs.items():
            for f in v if isinstance(v, list) else [v]:
                rel = os.path.relpath(Path(f).resolve(), out_dir.resolve())
                rows.append(f"<li>{html.escape(k)}: <a href='{html.escape(str(rel))}'>{html.escape(str(rel))}</a></li>")
        parts.append("<ul>" + "".join(rows) + "</ul>")
    parts.append("<h2>Scene</h2><details><summary>validated content (defaults filled in)</summary><pre>"
                 + html.escape(json.dumps(scene.data, indent=1, sort_keys=True)) + "</pre></details>")
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(rec, path: Path) -> Path:
    """Write the report of ``rec`` to ``path`` (atomically)."""
    return atomic_write(path, render(rec, Path(path).parent))
