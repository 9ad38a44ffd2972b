"""Figures of the documentation drawn from recorded data at build time (matplotlib, Agg).

:func:`accuracy_plots` draws the truncation error of the harmonic balance against the
time of a curve, one figure per model class (single-DOF, chains, UPD-24), from
``docs/data/accuracy.json`` and ``accuracy_upd.json`` (``make docs-accuracy``), into
``docs/_generated/accuracy_<class>.png``, and writes ``_generated/accuracy_plots.md``
that shows them (included by the accuracy and performance pages).
"""
from __future__ import annotations

import io
import json
from pathlib import Path

#: Model classes of the figures: file stem, title, prefix of the rows' model names.
CLASSES = (("sdof", "single-DOF Jenkins oscillator", "sdof"),
           ("chains", "friction chains (3 and 5 masses)", "chain"),
           ("upd24", "UPD-24 sector, F0 = 30 N", "UPD-24"),
           ("contact", "mass on a 3D contact point with lift-off", "contact3d"))
#: The recorded data files the figures are drawn from.
SOURCES = ("accuracy", "accuracy_upd", "accuracy_contact")
#: Where a zero error would sit on the logarithmic axis (never reached by recorded rows).
FLOOR = 1e-12


def _rows(docs: Path) -> list[dict]:
    rows = []
    for name in SOURCES:
        src = docs / "data" / f"{name}.json"
        if src.exists():
            rows += json.loads(src.read_text()).get("result", {}).get("rows", [])
    return rows


def _figure(rows: list[dict], title: str) -> bytes:
    """PNG of one model class: per model, true error (solid) and estimate (dashed) against
    the time of the curve and its check, labelled with H; accuracy targets as stars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for model in dict.fromkeys(r["model"] for r in rows):
        fixed = sorted((r for r in rows if r["model"] == model and r["setting"].startswith("H ")),
                       key=lambda r: r["time_s"])
        targets = [r for r in rows if r["model"] == model and not r["setting"].startswith("H ")]
        t = [r["time_s"] for r in fixed]
        line, = ax.plot(t, [max(r["true_error"], FLOOR) for r in fixed], "o-", label=f"{model}: true error")
        est = [(r["time_s"], r["estimate"]) for r in fixed if r["estimate"] is not None]
        if est:
            ax.plot(*zip(*est), "x--", color=line.get_color(), alpha=0.7, label=f"{model}: estimate")
        for r in fixed:
            ax.annotate(r["setting"], (r["time_s"], max(r["true_error"], FLOOR)), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
        for i, r in enumerate(targets):   # targets that chose the same H share a point: labels stacked
            ax.plot(r["time_s"], max(r["true_error"], FLOOR), "*", ms=11, color=line.get_color(), mec="k")
            ax.annotate(r["setting"], (r["time_s"], max(r["true_error"], FLOOR)), fontsize=7,
                        xytext=(3, -9 - 8 * i), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time of the curve and its check [s] (wall)")
    ax.set_ylabel("relative error of the peak amplitude")
    ax.set_title(f"{title} (star: an accuracy target)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def _write_bytes(path: Path, data: bytes) -> None:
    """Write only when the bytes changed (Sphinx then rebuilds only what changed)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_bytes() != data:
        path.write_bytes(data)


def accuracy_plots(docs: Path) -> None:
    """The figures of the module docstring and the Markdown that shows them."""
    rows = _rows(docs)
    parts = []
    for stem, title, prefix in CLASSES:
        mine = [r for r in rows if r["model"].startswith(prefix)]
        if not mine:
            continue
        _write_bytes(docs / "_generated" / f"accuracy_{stem}.png", _figure(mine, title))
        parts += [f"```{{figure}} /_generated/accuracy_{stem}.png", f":alt: error against time, {title}", "",
                  f"{title[0].upper() + title[1:]}: the error of the peak amplitude against the time of "
                  "the curve and its estimate; solid: the true error (against the re-solved reference "
                  "peak), dashed: the estimate.", "```", ""]
    text = "\n".join(parts) if parts else ("```{note}\nNo recorded data yet (`docs/data/accuracy.json`): "
                                           "run `make docs-accuracy` and build the documentation again.\n```\n")
    md = docs / "_generated" / "accuracy_plots.md"
    md.parent.mkdir(parents=True, exist_ok=True)
    if not md.exists() or md.read_text() != text:
        md.write_text(text)
