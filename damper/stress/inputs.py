"""The input stage of ``damper stress``: every bad input refused cleanly, nothing lost.

Each case of :mod:`.input_cases` and :mod:`.file_cases` runs in a forked child (:mod:`.forkrun`) in a folder
of its own, with a time limit, and is classified:

* ``clear_error``: exit code 2 or 3, no traceback, the last line of standard error is
  the command's message (``damper <command>: ...``), no warning line repeated;
* ``converged`` / ``interrupted``: the duties of the cache and the runner held (the
  case's check; Ctrl-C: exit code 130, one line, no output folder);
* ``crash`` (a traceback, a signal, another exit code), ``hang`` (the time limit
  passed), ``wrong`` (a file was created, changed or removed by a refused input, a
  user's file touched, a message over several lines, a warning repeated, or the case's
  check failed).

A row's ``ok`` says whether the outcome is the expected one.
"""
from __future__ import annotations

import os
import shutil
import tempfile
import time
from pathlib import Path

from . import forkrun, input_fixtures
from .file_cases import cases as file_cases
from .input_cases import InputCase, all_cases

#: Lines of standard error that are not the message: argparse's usage, progress, plan.
_CONTEXT = ("usage:", " ", "[", "plan:", "damper: warning:")


def snapshot(folder: Path) -> dict:
    """Every file below ``folder``: relative path -> (size, mtime_ns); folders -> None."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for d in dirs:
            out[os.path.relpath(os.path.join(root, d), folder)] = None
        for f in files:
            p = os.path.join(root, f)
            try:
                st = os.stat(p)
            except OSError:
                continue
            out[os.path.relpath(p, folder)] = (st.st_size, st.st_mtime_ns)
    return out


def _changes(before: dict, after: dict) -> list[str]:
    made = [f"created {k}" for k in after if k not in before]
    gone = [f"removed {k}" for k in before if k not in after]
    changed = [f"changed {k}" for k in before if k in after and before[k] != after[k]]
    return made + gone + changed


def _message_lines(stderr: str) -> list[str]:
    """Lines of standard error that carry a message (not usage, progress or the plan)."""
    return [ln for ln in stderr.splitlines() if ln.strip() and not ln.startswith(_CONTEXT)
            and ": warning:" not in ln and not ln.startswith("note:")]


def _repeated_warning(stderr: str) -> str:
    warnings = [ln for ln in stderr.splitlines() if ": warning:" in ln]
    dup = {w for w in warnings if warnings.count(w) > 1}
    return f"warning printed {warnings.count(min(dup))} times: {min(dup)[:120]}" if dup else ""


# -- what a case may do to its folder (mutate) and what it must show (check) ------------
def _entries(case_dir: Path) -> list[Path]:
    return sorted((case_dir / ".damper_cache").glob("entry-*.damper-cache"))


def add_user_file(case_dir: Path) -> None:
    (case_dir / ".damper_cache" / "notes.txt").write_text("a user's notes: keep me\n")


def truncate_entries(case_dir: Path) -> None:
    for p in _entries(case_dir):
        p.write_bytes(b"")


def swap_entries(case_dir: Path) -> None:
    """Copy the older entry (grid 5) over the newer one (grid 7): a key that now holds another result."""
    ent = sorted(_entries(case_dir), key=lambda p: p.stat().st_mtime_ns)
    if len(ent) >= 2:
        ent[-1].write_bytes(ent[0].read_bytes())


def fifo_entries(case_dir: Path) -> None:
    """Replace every cache entry by a FIFO of the same name (a read would block forever)."""
    for p in _entries(case_dir):
        p.unlink()
        os.mkfifo(p)


def fifo(case_dir: Path, name: str) -> None:
    os.mkfifo(case_dir / name)


def symlink(case_dir: Path, target: str, name: str) -> None:
    (case_dir / name).symlink_to(target)


def hardlink(case_dir: Path, target: str, name: str) -> None:
    os.link(case_dir / target, case_dir / name)


def sparse(case_dir: Path, name: str, size: str) -> None:
    """A file of ``size`` bytes that takes no disk (a hole)."""
    with open(case_dir / name, "wb") as fh:
        fh.truncate(int(size))


MUTATE = {"add_user_file": add_user_file, "truncate_entries": truncate_entries, "swap_entries": swap_entries,
          "fifo_entries": fifo_entries, "fifo": fifo, "symlink": symlink, "hardlink": hardlink, "sparse": sparse}


def check(name: str, case_dir: Path, r: forkrun.Finished) -> str:
    """What is wrong with a converged case (empty when its check holds)."""
    what, _, arg = name.partition(":")
    if what == "version":
        return "" if r.stdout.startswith("damper ") else f"no version printed: {r.stdout[:80]!r}"
    if what == "no_entries":
        return "" if not _entries(case_dir) else f"{len(_entries(case_dir))} entries left"
    if what == "one_warning":
        n = sum(arg in ln for ln in r.stderr.splitlines())
        return "" if n == 1 else f"{n} lines with {arg!r} (expected one warning)"
    if what == "no_cache_folder":
        return "" if not (case_dir / ".damper_cache").exists() else "a cache folder was written"
    raise ValueError(f"unknown check {name!r}")


# -- classification ------------------------------------------------------------------
def classify(case: InputCase, r: forkrun.Finished, changes: list[str], kept: list[str], extra: str) -> tuple:
    """(outcome, message) of a finished case."""
    lines = _message_lines(r.stderr)
    last = lines[-1].strip() if lines else ""
    if r.code is None:
        return "hang", f"no answer within {case.timeout:g} s"
    if "Traceback (most recent call last)" in r.stderr:
        return "crash", f"exit {r.code}: traceback: {last[:240]}"
    if kept:
        return "wrong", f"a user's file was touched: {', '.join(kept)}"
    if case.expect == "interrupted":
        if r.code != 130:
            return ("crash" if r.code not in (0, 2, 3) else "wrong"), f"exit {r.code} after SIGINT: {last[:200]}"
        if len(lines) != 1 or "interrupted" not in last:
            return "wrong", f"{len(lines)} message lines after SIGINT: {' | '.join(lines)[:240]}"
        if any(c.startswith("created ok") for c in changes):
            return "wrong", "the interrupted run wrote its output folder: " + ", ".join(changes)[:200]
        return "interrupted", last
    if r.code not in (0, 2, 3):
        return "crash", f"exit {r.code}: {last[:240]}"
    if r.code == 0:
        if case.expect != "converged":
            return "wrong", "accepted (exit 0) an input that must be refused"
        return ("wrong", extra) if extra else ("converged", last[:240])
    if case.expect == "converged":
        return "wrong", f"refused (exit {r.code}): {last[:240]}"
    if changes:
        return "wrong", f"refused but wrote: {', '.join(changes)[:200]} ({last[:120]})"
    if len(lines) > 1:
        return "wrong", f"{len(lines)} message lines: {' | '.join(lines)[:240]}"
    if not last.startswith("damper"):
        return "wrong", f"no message of the command: {last[:200]!r}"
    dup = _repeated_warning(r.stderr)
    return ("wrong", dup) if dup else ("clear_error", last)


def run_case(case: InputCase, fx: Path, work: Path, index: int) -> dict:
    """Run one case in a folder of its own; its table row."""
    case_dir = work / f"case{index:03d}"
    case_dir.mkdir()
    for rel, content in case.files.items():
        path = case_dir / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content) if isinstance(content, bytes) else path.write_text(content)
    env = {"DAMPER_CACHE_DIR": str(case_dir / ".damper_cache"), "DAMPER_CACHE_MAX_MB": "4096"}
    fill = lambda argv: [a.replace("{fx}", str(fx)) for a in argv]  # noqa: E731
    t0 = time.perf_counter()
    for pre in case.pre:
        p = forkrun.run(fill(pre), case_dir, case.timeout, env)
        if p.code != 0:
            return _row(case, "crash", f"the set-up command failed (exit {p.code}): {p.stderr[-200:]}", t0, fill)
    if case.mutate:
        what, *mutate_args = case.mutate.split(":")
        MUTATE[what](case_dir, *mutate_args)
    keep = {k: (case_dir / k).read_bytes() for k in case.keep if (case_dir / k).is_file()}
    before, fx_before = snapshot(case_dir), snapshot(fx)
    r = forkrun.run(fill(case.argv), case_dir, case.timeout, env, interrupt_on=case.interrupt_on)
    changes = _changes(before, snapshot(case_dir)) + _changes(fx_before, snapshot(fx))
    kept = [k for k, blob in keep.items() if not (case_dir / k).is_file() or (case_dir / k).read_bytes() != blob]
    kept += [c.split(" ", 1)[1] for c in changes if c.split(" ", 1)[1] in case.files]
    extra = check(case.check, case_dir, r) if case.check and r.code == 0 else ""
    outcome, message = classify(case, r, changes, kept, extra)
    return _row(case, outcome, message.replace(str(fx), "{fx}"), t0, fill)


def _row(case: InputCase, outcome: str, message: str, t0: float, fill=None) -> dict:
    return {"stage": "inputs", "case": f"{case.group}: {case.name}", "outcome": outcome, "expected": case.expect,
            "message": message, "worst_residual": None, "time_s": round(time.perf_counter() - t0, 3),
            "command": "damper " + " ".join(case.argv), "ok": outcome == case.expect, "advice": True,
            "known": None}


def run(log=print, match=None) -> list[dict]:
    """Run every input case (``match``: only those whose name contains one of these texts)."""
    cases = [c for c in all_cases() + file_cases() if not match or any(m in f"{c.group}: {c.name}" for m in match)]
    if not cases:
        return []
    forkrun.preload()
    work = Path(tempfile.mkdtemp(prefix="damper_inputs_"))
    rows = []
    try:
        fx = input_fixtures.make(work / "fixtures")
        for i, case in enumerate(cases, 1):
            row = run_case(case, fx, work, i)
            rows.append(row)
            log(f"[{i:3d}/{len(cases)}] inputs     {row['case'][:44]:44s} {row['outcome']:11s} "
                f"{row['time_s']:7.1f} s  {'' if row['ok'] else 'UNEXPECTED '}{row['message'][:90]}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return rows


def group_table(rows: list[dict]) -> str:
    """Markdown summary of the input rows by command: cases, outcomes, failures, one message each."""
    groups: dict[str, list[dict]] = {}
    for r in rows:
        if r["stage"] == "inputs":
            groups.setdefault(r["case"].split(":", 1)[0], []).append(r)
    if not groups:
        return ""
    head = "| command | cases | outcomes | not as expected | a message |\n|---|---|---|---|---|\n"
    lines = []
    for g, rs in groups.items():
        counts: dict[str, int] = {}
        for r in rs:
            counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
        bad = [r["case"].split(": ", 1)[1] for r in rs if not r["ok"]]
        sample = next((r["message"] for r in rs if r["outcome"] == "clear_error"), "")
        lines.append(f"| {g} | {len(rs)} | {', '.join(f'{v} {k}' for k, v in counts.items())} | "
                     f"{', '.join(bad) or 'none'} | {sample[:110].replace('|', '/')} |")
    return head + "\n".join(lines) + "\n"
