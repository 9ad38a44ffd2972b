"""Run the stress grid: every case in a child process with a time limit, classified.

Outcomes: "converged" (exit 0, every invariant of ``checks`` holds), "clear_error"
(exit 2 or 3 with a one-line message and no traceback), "crash" (a traceback, a
signal or another exit code), "nan" (a non-finite number in the result), "hang"
(the time limit passed), "wrong" (a result that breaks an invariant, or a legal
case refused / an illegal one accepted). ``ok`` says whether the outcome is the
expected one; ``known`` names the entry of the stress findings when a failure is
a known bug of another stage, so that a failure is never unexplained.
"""
from __future__ import annotations

import json
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from damper.bench.common import run_child

from . import checks, inputs
from .cases import MU, N0, Case, all_cases

#: Known failures: (stage, case name) -> the entry of /work/wt/notes/stress-findings.md
#: (the stage's owner fixes it; the stress table shows it as known, not unexplained).
KNOWN: dict[tuple[str, str], str] = {}
#: Words of a message that tells the user what to change (a "clear" error).
ADVICE = re.compile(r"\b(use|refine|lower|raise|increase|reduce|decrease|must|should|give|set|try|at least|"
                    r"at most|between|choose|limit|remove|check|pass)\b", re.I)
_FMU_CHILD = "from damper.stress.fmu_child import main; import sys; sys.exit(main())"


def _mindlin_curve(n: int) -> dict:
    """Cattaneo-Mindlin virgin curve of n points ending at gross slip mu N (schema-1 curve file)."""
    u_slip = 2.5e-6
    u = u_slip * np.linspace(0.0, 1.0, n) if n > 2 else np.array([0.0, u_slip])
    T = MU * N0 * (1.0 - (1.0 - u / u_slip) ** 1.5)
    T[-1] = MU * N0
    return {"schema": "damper-virgin-curve/1", "u": u.tolist(), "T": T.tolist(), "N": N0, "mu": MU,
            "k_t": 1.5 * MU * N0 / u_slip, "load_case": "CNF"}


def make_curves(work: Path) -> dict[str, Path]:
    """The curve files the cases name: Mindlin curves of 2 to 10,000 points and a convex one."""
    curves = {}
    for n in (2, 10, 1000, 10000):
        curves[f"mindlin{n}"] = _mindlin_curve(n)
    convex = _mindlin_curve(10)
    convex["T"] = (MU * N0 * np.linspace(0, 1, 10) ** 2).tolist()
    curves["convex"] = convex
    paths = {}
    for name, data in curves.items():
        paths[name] = work / f"{name}.json"
        paths[name].write_text(json.dumps(data))
    return paths


def _fill(argv: list[str], curves: dict[str, Path], work: Path) -> list[str]:
    out = []
    for a in argv:
        m = re.fullmatch(r"\{curve:(\w+)\}", a)
        out.append(str(curves[m.group(1)]) if m else a.replace("{work}", str(work)))
    return out


def _message(stderr: str) -> str:
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    return lines[-1].strip() if lines else ""


def classify(case: Case, code: int | None, stdout: str, stderr: str) -> tuple[str, str, float]:
    """Outcome, message and worst residual of a finished child."""
    if code is None:
        return "hang", f"no answer within {case.timeout:g} s", float("nan")
    if "Traceback (most recent call last)" in stderr or code not in (0, 2, 3):
        return "crash", f"exit {code}: {_message(stderr)[:300]}", float("nan")
    if code != 0:
        return "clear_error", _message(stderr)[:300], float("nan")
    try:
        out = json.loads(stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return "crash", f"exit 0 without a JSON result: {stdout[-200:]!r}", float("nan")
    if case.stage == "fmu" and "F" in out and len(out) == 1:
        return "nan", "the FMU returned a non-finite output", float("nan")
    outcome, worst, msg = checks.check(case.stage, out, case.request)
    warn = _message(stderr)
    return outcome, msg or (warn[:300] if warn else ""), worst


def run_case(case: Case, curves: dict[str, Path], work: Path) -> dict:
    """Run one case in a child process; its table row."""
    argv = _fill(case.argv, curves, work)
    t0 = time.perf_counter()
    if case.stage == "fmu":
        r = run_child([*argv, str(work / f"fmu{argv[1]}")], case.timeout, python_code=_FMU_CHILD)
    else:
        r = run_child(argv, case.timeout)
    outcome, message, worst = classify(case, r.code, r.stdout, r.stderr)
    return judge({"stage": case.stage, "case": case.name, "outcome": outcome, "expected": case.expect,
            "message": message, "worst_residual": None if np.isnan(worst) else worst,
            "time_s": round(time.perf_counter() - t0, 3),
            "command": "damper " + " ".join(argv) if case.stage != "fmu" else "fmu_child " + " ".join(argv)})


def judge(row: dict) -> dict:
    """Set ``ok``, ``advice`` and ``known`` of a row from its outcome, expectation and message.

    A legal input may be refused when the message says what to change;
    an input that must be refused needs only a message.
    """
    message = row["message"].removeprefix("error without advice: ")
    refused = row["outcome"] == "clear_error"
    advice = not refused or row["expected"] == "clear_error" or bool(ADVICE.search(message))
    ok = advice and (row["outcome"] == row["expected"] or (refused and row["expected"] == "converged"))
    if refused and not advice:
        message = f"error without advice: {message}"
    known = None if ok else KNOWN.get((row["stage"], row["case"]))
    return dict(row, ok=ok, advice=advice, known=known, message=message)


def run(quick: bool = False, stages=None, log=print, match=None) -> list[dict]:
    """Run the grid (``quick``: the marked subset; ``match``: cases whose name contains one of these texts).

    The input stage (:mod:`.inputs`, every case in the quick run too) runs first.
    """
    rows = inputs.run(log, match) if stages is None or "inputs" in stages else []
    cases = [c for c in all_cases() if (c.quick or not quick) and (stages is None or c.stage in stages)
             and (not match or any(m in c.name for m in match))]
    if not cases:
        return rows
    work = Path(tempfile.mkdtemp(prefix="damper_stress_"))
    try:
        curves = make_curves(work)
        for i, case in enumerate(cases, 1):
            row = run_case(case, curves, work)
            rows.append(row)
            log(f"[{i:3d}/{len(cases)}] {row['stage']:10s} {row['case']:44s} {row['outcome']:11s} "
                f"{row['time_s']:7.1f} s  {'' if row['ok'] else 'UNEXPECTED '}{row['message'][:90]}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return rows


def table(rows: list[dict]) -> str:
    """Markdown table of the rows (DIR/stress.md)."""
    head = "| stage | case | outcome | expected | worst residual | time [s] | note |\n|---|---|---|---|---|---|---|\n"
    lines = []
    for r in rows:
        res = "-" if r["worst_residual"] is None else f"{r['worst_residual']:.1e}"
        note = r["known"] or ("" if r["ok"] else "UNEXPECTED: " + r["message"][:120])
        if r["ok"] and r["outcome"] == "clear_error":
            note = r["message"][:120]
        lines.append(f"| {r['stage']} | {r['case']} | {r['outcome']} | {r['expected']} | {res} | "
                     f"{r['time_s']:.1f} | {note.replace('|', '/')} |")
    return head + "\n".join(lines) + "\n"


def summary(rows: list[dict]) -> dict:
    """Counts per outcome and the failures that are neither expected nor known."""
    counts: dict[str, int] = {}
    for r in rows:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    unexplained = [f"{r['stage']}: {r['case']}" for r in rows if not r["ok"] and not r["known"]]
    return {"counts": counts, "unexpected": sum(not r["ok"] for r in rows), "unexplained": unexplained}
