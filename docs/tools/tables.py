"""Markdown of the data pages: validation, performance (``damper bench``), stability (``damper stress``).

Each renderer takes the JSON of one data file and returns the page's Markdown,
starting with where the figures come from (command, revision, date, machine).
"""
from __future__ import annotations

#: How each data file is made (shown on a page whose data file is missing, and in the stamp).
MAKE = {
    "validation": "make validation",
    "bench": "make docs-bench",
    "bench_peers": "make docs-bench-peers PYHARM=... NLVIB=...",
    "bench_peers_1pct": "make docs-bench-peers-1pct PYHARM=...",
    "bench_peers_1pct_chain5": "python docs/tools/record.py docs/data/bench_peers_1pct_chain5.json -- "
                               ".venv/bin/python -m damper.bench.peers_1pct --pyharm PYHARM "
                               "--case 'chain5 down' --json",
    "stress": "make docs-stress",
    "bench_surface": "make docs-bench-surface",
    "accuracy": "make docs-accuracy",
    "accuracy_upd": "make docs-accuracy",
}


def missing(name: str) -> str:
    return (f"```{{note}}\nNo recorded data yet (`docs/data/{name}.json`): run `{MAKE[name]}` and build "
            f"the documentation again.\n```\n")


def _g(x, digits: int = 3) -> str:
    """A number in short form ('-' for none)."""
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        if x == 0.0:
            return "0"
        return f"{x:.{digits}g}" if 1e-3 <= abs(x) < 1e5 else f"{x:.{max(digits - 1, 1)}e}"
    return str(x)


def _cell(x) -> str:
    return _g(x).replace("|", "/").replace("\n", " ")


def stamp_text(data: dict, name: str) -> str:
    """Where the figures come from: one paragraph."""
    s = data.get("stamp", {})
    load = s.get("load_average")
    load_txt = f", load average {load[0]:.1f}" if load else ""
    versions = ", ".join(f"{k} {v}" for k, v in (s.get("versions") or {}).items() if v)
    return (f"Recorded {s.get('date_utc', '?')} at revision `{s.get('revision', '?')}` on "
            f"{s.get('cores', '?')} cores ({s.get('machine', '?')}, {s.get('system', '?')}, Python "
            f"{s.get('python', '?')}{load_txt}) by\n\n```\n{data.get('command', '?')}\n```\n\n"
            f"(exit code {data.get('exit_code', '?')}, {data.get('wall_s', '?')} s wall). Libraries: "
            f"{versions or '-'}. Regenerate with `{MAKE[name]}`; the machine is shared, so wall times "
            f"are upper bounds and only ratios within one run compare.\n")


#: The two kinds of reference check (tests/refcheck.py), in page order: heading, what it means.
KINDS = {
    "independent": ("Independent references",
                    "The reference owes nothing to this code: a closed form, a published value."),
    "self-consistency": ("Self-consistency",
                         "The reference is another part of the same code (a time integration through the "
                         "same friction element, the linear limit from the same sector matrices, the EPMC "
                         "backbone of the same model): it catches a part that drifts from the others, not "
                         "an error they share."),
}


def _validation_rows(recs: list[dict]) -> list[str]:
    """One table per test folder."""
    out: list[str] = []
    groups: dict[str, list[dict]] = {}
    for r in recs:
        groups.setdefault(r["test"].split("/")[1] if r["test"].count("/") > 1 else "tests", []).append(r)
    for group in sorted(groups):
        out += [f"### {group}", "",
                "| quantity | reference | our value | reference value | tolerance | test |",
                "|---|---|---|---|---|---|"]
        for r in sorted(groups[group], key=lambda r: (r["test"], r["quantity"])):
            mark = "" if r["passed"] else " **(failed)**"
            out.append(f"| {_cell(r['quantity'])} | {_cell(r['source'])} | {_g(r['value'], 6)} | "
                       f"{_g(r['reference'], 6)} | {_cell(r['tolerance'])}{mark} | `{r['test']}` |")
        out.append("")
    return out


def validation(data: dict) -> str:
    recs = data.get("records", [])
    kind = {k: [r for r in recs if r.get("kind", "independent") == k] for k in KINDS}
    out = [stamp_text(data, "validation"), "",
           f"{len(recs)} reference checks in {len({r['test'] for r in recs})} tests "
           f"({len(kind['independent'])} against independent references, "
           f"{len(kind['self-consistency'])} of self-consistency); "
           f"{sum(r['passed'] for r in recs)} passed, {sum(not r['passed'] for r in recs)} failed.", ""]
    for k, (title, text) in KINDS.items():
        if kind[k]:
            out += [f"## {title}", "", text, "", *_validation_rows(kind[k])]
    return "\n".join(out) + "\n"


def bench(data: dict) -> str:
    from damper.bench import surface_cost
    from damper.bench.report import ACCURACY_CAPTION, ACCURACY_COLUMNS, LEGEND

    res = data.get("result", {})
    out = [stamp_text(data, "bench"), ""]
    if res.get("quick"):
        out += ["```{warning}\nThese are the `--quick` sizes (a smoke run), not the full benchmark.\n```", ""]
    for stage, rows in res.get("stages", {}).items():
        size, err = LEGEND.get(stage, ("size", "error"))
        out += [f"## {stage}", "", f"Size: {size}. Error: {err}.", "",
                "| case | size | error | time [s] | memory [MB] | cached |", "|---|---|---|---|---|---|"]
        for r in (r for r in rows if "tool" not in r and "estimate" not in r):
            case = r["case"] + (" (default)" if r.get("default") else "")
            out.append(f"| {_cell(case)} | {_g(r['size'])} | {_g(r['error'])} | {_g(r['time_s'])} | "
                       f"{_g(r['memory_mb'], 4)} | {_g(bool(r.get('cached')))} |")
        out.append("")
        surf = [r for r in rows if surface_cost.is_row(r)]
        if surf:
            out += [surface_cost.CAPTION[0].upper() + surface_cost.CAPTION[1:] + ".", "",
                    *surface_cost.markdown(surf), ""]
        acc = [r for r in rows if "estimate" in r and "tool" not in r]   # damper.bench.hb_accuracy
        if acc:
            out += [ACCURACY_CAPTION[0].upper() + ACCURACY_CAPTION[1:] + ".", "",
                    "| " + " | ".join(h for h, _, _ in ACCURACY_COLUMNS) + " |", "|" + "---|" * len(ACCURACY_COLUMNS)]
            out += ["| " + " | ".join(_cell(r.get(k)) for _, k, _ in ACCURACY_COLUMNS) + " |" for r in acc]
            out.append("")
        models = [r for r in rows if "tool" in r]   # whole curves of the model classes, with peers
        if models:
            from damper.bench.hb_classes import markdown

            out += ["Model classes (error: |first-harmonic peak / dense reference - 1|):", "",
                    *markdown(models), ""]
    return "\n".join(out) + "\n"


def peers_1pct(data: dict, name: str = "bench_peers_1pct") -> str:
    """The peer rows at each tool's own H for 1 % (``python -m damper.bench.peers_1pct --json``)."""
    from damper.bench.peer_accuracy import markdown

    return "\n".join([stamp_text(data, name), "", *markdown(data.get("result", {}).get("rows", []))]) + "\n"


def accuracy(data: dict) -> str:
    """The truncation-error table of ``python -m damper.bench.hb_accuracy --json``."""
    res = data.get("result", {})
    out = [stamp_text(data, "accuracy"), "",
           f"True error: against the first curve's peak raised level by level to 0..{res.get('reference_H', '?')} "
           "harmonics, or to twice the richest peak level of the model's targets when higher "
           f"(UPD-24: 0..{res.get('reference_H_upd', '?')}). A target's setting reads \"tol -> H "
           "curve/peak\": the curve traced once at the first H, its peak raised to the second. "
           "Ratio: estimate / true error (the goal: between 1/3 and 3). Check: the wall time of the "
           "estimate (of a target: its peak levels); total: CPU time of the curve and its check "
           "(of a target: the curve and every level at its peak). Flags: R the "
           "ratio outside [1/3, 3]; u the ratio not judged: the true error is within three times the "
           "reference's own estimated error (or below 1e-6); T a target's true error above it "
           "(t: the engine said not met, "
           "at its harmonic limit); D~ the default setting more than 1 % off, with its warning; "
           "D! without one.", "",
           "| model | H or target | peak | estimate | true error | ratio | check [s] | total [s] | flags |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in res.get("rows", []):
        out.append(f"| {_cell(r['model'])} | {_cell(r['setting'])} | {_g(r['peak_amplitude'], 6)} | "
                   f"{_pct(r['estimate'])} | {_pct(r['true_error'])} | {_g(r['ratio'])} | "
                   f"{_g(r['check_time_s'])} | {_g(r['time_s'])} | {r.get('flags') or ''} |")
    goals = res.get("goals")
    if goals:
        out += ["", "Goals over these rows: " + "; ".join(
            f"{what} {len(goals[key]['failing'])} of {goals[key]['rows']} rows"
            + (f" ({', '.join(goals[key]['failing'])})" if goals[key]["failing"] else "")
            for key, what in (("ratio_ok", "estimate outside a factor 3 of the true error:"),
                              ("target_met", "target missed in truth:"),
                              ("default", "default more than 1 % off without a warning:"))) + "."]
    return "\n".join(out) + "\n"


def _pct(x) -> str:
    return "-" if x is None else f"{100 * x:.2g} %"


def stress(data: dict) -> str:
    res = data.get("result", {})
    summ = res.get("summary", {})
    counts = ", ".join(f"{n} {k}" for k, n in sorted(summ.get("counts", {}).items()))
    out = [stamp_text(data, "stress"), "",
           f"{len(res.get('cases', []))} cases: {counts}; not as expected: {summ.get('unexpected', '?')}; "
           f"unexplained: {len(summ.get('unexplained', []))}.", ""]
    if res.get("quick"):
        out += ["```{warning}\nThese are the `--quick` cases (a smoke run), not the full grid.\n```", ""]
    stages: dict[str, list[dict]] = {}
    for r in res.get("cases", []):
        stages.setdefault(r["stage"], []).append(r)
    for stage, rows in stages.items():
        out += [f"## {stage}", "", "| case | outcome | expected | worst residual | time [s] | note |",
                "|---|---|---|---|---|---|"]
        for r in rows:
            note = r.get("known") or ("" if r.get("ok") else "UNEXPECTED: " + r.get("message", ""))
            if r.get("ok") and r["outcome"] == "clear_error":
                note = r.get("message", "")
            out.append(f"| {_cell(r['case'])} | {r['outcome']} | {r['expected']} | {_g(r.get('worst_residual'), 2)} "
                       f"| {_g(r['time_s'])} | {_cell(note[:160])} |")
        out.append("")
    return "\n".join(out) + "\n"
