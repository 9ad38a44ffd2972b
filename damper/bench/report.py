"""The benchmark report: one JSON object and one HTML page with a plot per stage.

Each plot puts the error against its reference on the x axis and the time on
the y axis (both logarithmic), one point per row labelled with its size; cold
runs are circles, cached runs squares, the tool's default setting a star. The hb
stage's accuracy rows (:mod:`.hb_accuracy`) also get a table of the truncation-error
estimate beside the true error, its rows of HB against time integration
(:mod:`.hb_steady`) a table of the two peaks and the steady-state flag.
"""
from __future__ import annotations

import base64
import html
import io
import json
import math
from pathlib import Path

from . import surface_cost

#: What each stage's size and error mean (axis labels and the report's captions).
LEGEND = {
    "contact": ("grid (nodes per side)", "max(|a/a_H - 1|, |p0/p0_H - 1|) against Hertz"),
    "tangential": ("grid (nodes per side)", "max |T - T_Mindlin| / mu N"),
    "element": ("sliders", "|loop energy / Masing energy of the exact Mindlin curve - 1|"),
    "fmu": ("communication steps per cycle", "|energy per cycle / exact Masing energy - 1|"),
    "hb": ("H or AFT samples; model rows: HB unknowns n (2 H + 1)",
           "|amplitude / time-integration amplitude - 1| at 1.1 rad/s; model rows: "
           "|first-harmonic peak / dense reference - 1|"),
    "solvers": ("contact nodes (grid^2)", "largest relative difference of k_n, k_t against the first solver"),
    "surface": ("nodes per side of each face", "none (cost rows: the plot is time against nodes per side)"),
}


def _plot(stage: str, rows: list[dict]) -> str:
    """PNG (base64) of error against time for one stage."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    if all(r["error"] is None for r in rows):
        _plot_cost(ax, stage, rows)
        return _png(fig, plt)
    floor = 1e-16  # an exact result (error 0) is drawn at round-off
    # model rows (a "tool" key) are one series per tool, marks only, labelled by model
    for case in dict.fromkeys(r.get("tool", r["case"]) for r in rows):
        for cached in (False, True):
            pts = [r for r in rows if r.get("tool", r["case"]) == case and r["cached"] == cached
                   and r["error"] is not None and r["time_s"]]
            if not pts:
                continue
            x = [max(r["error"], floor) for r in pts]
            y = [r["time_s"] for r in pts]
            style = ("s" if cached else "o") if "tool" in pts[0] else ("s--" if cached else "o-")
            ax.plot(x, y, style, label=f"{case}{' (cached)' if cached else ''}")
            for r, xi, yi in zip(pts, x, y):
                ax.annotate(r["model"] if "tool" in r else f"{r['size']:g}", (xi, yi), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
                if r.get("default"):
                    ax.plot(xi, yi, "*", ms=16, mfc="none", mec="k")
    ax.set_xscale("log")
    ax.set_yscale("log")
    size_label, err_label = LEGEND.get(stage, ("size", "error"))
    ax.set_xlabel(f"error: {err_label}", fontsize=8)
    ax.set_ylabel("time [s]")
    ax.set_title(f"{stage} (labels: {size_label}; star: default)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    return _png(fig, plt)


def _plot_cost(ax, stage: str, rows: list[dict]) -> None:
    """A stage of cost rows alone (no error): time against size, one line per case."""
    for case in dict.fromkeys(r["case"] for r in rows):
        pts = sorted((r["size"], r["time_s"]) for r in rows if r["case"] == case and r["time_s"])
        if pts:
            ax.plot(*zip(*pts), "o-", label=case)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(LEGEND.get(stage, ("size", ""))[0], fontsize=8)
    ax.set_ylabel("time [s]")
    ax.set_title(f"{stage}: cost", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def _png(fig, plt) -> str:
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.3g}"
    return html.escape(str(v))


def _split(rows: list[dict]) -> tuple[list[dict], list[dict], list[dict]]:
    """(the stage's own rows, the accuracy rows of damper.bench.hb_accuracy, the model-class
    rows of damper.bench.hb_classes)."""
    acc = [r for r in rows if "estimate" in r and "tool" not in r]
    return ([r for r in rows if "tool" not in r and "estimate" not in r], acc,
            [r for r in rows if "tool" in r])


#: Columns of the accuracy rows' HTML and Markdown tables: (heading, key, format).
ACCURACY_COLUMNS = (("model", "model", "s"), ("H or target", "setting", "s"), ("peak", "peak_amplitude", ".6g"),
                    ("estimate", "estimate", ".2e"), ("true error", "true_error", ".2e"),
                    ("ratio", "ratio", ".2f"), ("check [s]", "check_time_s", ".2f"), ("total [s]", "time_s", ".2f"),
                    ("flags", "flags", "s"))
ACCURACY_CAPTION = ("accuracy: the truncation-error estimate of the peak amplitude against the true error "
                    "(against the peak re-solved with many more harmonics); ratio = estimate / true error; "
                    "total: the curve and its check (of a target: every curve and check it took); "
                    "flags: R ratio outside [1/3, 3], T true error above the target (t: the engine said "
                    "not met, the harmonic limit), D! a default more than 1 % off without a warning, "
                    "D~ with one")


def _cells(r: dict) -> list[str]:
    return ["-" if r.get(k) is None else format(r[k], f) for _, k, f in ACCURACY_COLUMNS]


def table_text(stage: str, rows: list[dict]) -> str:
    """Plain-text table of one stage (case, size, error, time, memory, cached), then its
    model-class rows (hb_classes.table)."""
    own, acc, models = _split(rows)
    lines = [f"== {stage}", f"{'case':26s} {'size':>8s} {'error':>10s} {'time_s':>8s} {'memory_mb':>9s} cached"]
    for r in own:
        err = "-" if r["error"] is None else f"{r['error']:.2e}"
        lines.append(f"{r['case']:26s} {r['size']:8g} {err:>10s} {r['time_s']:8.2f} {r['memory_mb']:9.0f} "
                     f"{'yes' if r['cached'] else 'no'}{'  (default)' if r.get('default') else ''}")
    if acc:
        from .hb_accuracy import table_lines

        lines += [ACCURACY_CAPTION + ":", *table_lines(acc)]
    steady = [r for r in own if "states_differ" in r]
    if steady:
        from .hb_steady import table_lines as steady_lines

        lines += ["harmonic balance against time integration (which steady state):", *steady_lines(steady)]
    if models:
        from .hb_classes import table

        lines += ["model classes (peak error against dense references):", table(models)]
    return "\n".join(lines)


def _html_table(caption: str, columns, cell_rows) -> list[str]:
    """HTML lines of a captioned table: headings from ``columns`` ((heading, key, format)
    triples), one row of formatted cells per item of ``cell_rows``."""
    return ([f"<p>{html.escape(caption)}.</p><table><tr>"
             + "".join(f"<th>{html.escape(h)}</th>" for h, _, _ in columns) + "</tr>"]
            + ["<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>" for cells in cell_rows]
            + ["</table>"])


def write(out: Path, result: dict) -> tuple[Path, Path]:
    """Write bench.json and bench.html into ``out``; return their paths."""
    from contact_core.fileio import atomic_write

    parts = ["<!doctype html><html><head><meta charset='utf-8'><title>damper bench</title>"
             "<style>body{font-family:sans-serif;max-width:60em;margin:auto}table{border-collapse:collapse;"
             "font-size:85%}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}</style></head><body>",
             "<h1>damper bench</h1>", "<h2>Run</h2><table>"]
    for k, v in result["stamp"].items():
        parts.append(f"<tr><th>{html.escape(k)}</th><td style='text-align:left'>{_fmt(json.dumps(v))}</td></tr>")
    parts.append("</table>")
    for stage, rows in result["stages"].items():
        size_label, err_label = LEGEND.get(stage, ("size", "error"))
        parts.append(f"<h2>{html.escape(stage)}</h2><p>size: {html.escape(size_label)}; error: "
                     f"{html.escape(err_label)}.</p>")
        if rows:
            parts.append(f"<img alt='{html.escape(stage)}' src='data:image/png;base64,{_plot(stage, rows)}'>")
        parts.append("<table><tr><th>case</th><th>size</th><th>error</th><th>time [s]</th><th>memory [MB]</th>"
                     "<th>cached</th><th>default</th></tr>")
        for r in rows:
            parts.append(f"<tr><td style='text-align:left'>{_fmt(r['case'])}</td><td>{_fmt(r['size'])}</td>"
                         f"<td>{_fmt(r['error'])}</td><td>{_fmt(r['time_s'])}</td><td>{_fmt(r['memory_mb'])}</td>"
                         f"<td>{'yes' if r['cached'] else 'no'}</td><td>{'*' if r.get('default') else ''}</td></tr>")
        parts.append("</table>")
        surf = [r for r in rows if surface_cost.is_row(r)]
        if surf:
            parts += _html_table(surface_cost.CAPTION, surface_cost.COLUMNS, map(surface_cost.cells, surf))
        acc = _split(rows)[1]
        if acc:
            parts += _html_table(ACCURACY_CAPTION, ACCURACY_COLUMNS, map(_cells, acc))
    parts.append("</body></html>")
    j = atomic_write(out / "bench.json", json.dumps(result, indent=1) + "\n")
    h = atomic_write(out / "bench.html", "\n".join(parts))
    atomic_write(out / "bench.md", markdown(result))
    return j, h


def markdown(result: dict) -> str:
    """Markdown tables of every stage (DIR/bench.md), with the run's stamp."""
    s = result["stamp"]
    out = [f"Run {s['date_utc']}, revision {s['revision']}, {s['cores']} cores, {s['machine']}, "
           f"load average {s['load_average'][0]:.1f}, sparse back ends {', '.join(s['sparse_solvers'])}.", ""]
    for stage, rows in result["stages"].items():
        size_label, err_label = LEGEND.get(stage, ("size", "error"))
        out += [f"**{stage}** (size: {size_label}; error: {err_label})", "",
                "| case | size | error | time [s] | memory [MB] | cached |", "|---|---|---|---|---|---|"]
        own, acc, models = _split(rows)
        for r in own:
            err = "-" if r["error"] is None else f"{r['error']:.2e}"
            star = " (default)" if r.get("default") else ""
            out.append(f"| {r['case']}{star} | {r['size']:g} | {err} | {r['time_s']:.2f} | {r['memory_mb']:.0f} | "
                       f"{'yes' if r['cached'] else 'no'} |")
        out.append("")
        surf = [r for r in own if surface_cost.is_row(r)]
        if surf:
            out += [f"**{stage}: {surface_cost.CAPTION}**", "", *surface_cost.markdown(surf), ""]
        if acc:
            out += [f"**{stage}: {ACCURACY_CAPTION}**", "",
                    "| " + " | ".join(h for h, _, _ in ACCURACY_COLUMNS) + " |", "|" + "---|" * len(ACCURACY_COLUMNS),
                    *("| " + " | ".join(_cells(r)) + " |" for r in acc), ""]
        steady = [r for r in own if "states_differ" in r]
        if steady:
            from .hb_steady import markdown as steady_markdown

            out += [f"**{stage}: harmonic balance against time integration (which steady state)**", "",
                    *steady_markdown(steady), ""]
        if models:
            from .hb_classes import markdown as model_markdown

            out += [f"**{stage}: model classes** (error: |first-harmonic peak / dense reference - 1|)", "",
                    *model_markdown(models), ""]
    return "\n".join(out)
