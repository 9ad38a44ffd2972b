"""Peer codes on the benchmark's model classes: pyHarm and NLvib, each in its own process.

Each peer gets a case file (the model's :meth:`~harmonic_balance.bench_models.BenchCase.spec`
plus the peer settings) and writes a result file (omega, first harmonic of the response
DOF per point, points, evaluations, wall and CPU time of its solve); the drivers are
``peer_pyharm.py`` (run by pyHarm's interpreter) and ``peer_nlvib.m`` (run by GNU
Octave), next to this module. Nothing here imports a peer.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from .common import run_child

HERE = Path(__file__).resolve().parent
#: A peer's run counts as complete when its points reach both ends of the band within
#: this fraction of the band (its last step may stop short of or overshoot the end).
END_TOL = 1e-3
#: Starting points tried in order: the peer's usual stuck linear solution, then the free one.
STARTS = ("stuck", "free")


def available(kind: str, path: str | None, octave: str | None = None, work: Path | None = None) -> str | None:
    """None when the peer can run, else why not (the row's status). ``work``: the folder the
    check runs in (pyHarm writes a ``.pyHarm`` folder where it is imported)."""
    if not path:
        return f"not available (give --{kind} {'PYTHON' if kind == 'pyharm' else 'NLVIB_DIR'})"
    if kind == "pyharm":
        if shutil.which(path) is None and not Path(path).is_file():
            return f"not available: no interpreter {path}"
        r = run_child([], 120.0, cwd=work, command=[path, "-c", "import pyHarm"])
        return None if r.code == 0 else f"not available: {path} cannot import pyHarm"
    if not (Path(path) / "SRC" / "HB_residual.m").is_file():
        return f"not available: {path} is not an NLvib folder (no SRC/HB_residual.m)"
    if shutil.which(octave or "octave") is None:
        return f"not available: no GNU Octave ({octave or 'octave'}) on PATH"
    return None


def _command(kind: str, path: str, octave: str | None, case_file: Path, out_file: Path) -> list[str]:
    if kind == "pyharm":
        return [path, str(HERE / "peer_pyharm.py"), str(case_file), str(out_file)]
    call = (f"addpath('{HERE}'); peer_nlvib('{case_file}', '{out_file}', '{Path(path).resolve()}')")
    return [octave or "octave", "--no-gui", "--no-window-system", "--quiet", "--eval", call]


def _spec(case, kind: str, settings: dict, start: str) -> dict:
    spec = case.spec()
    if kind == "nlvib":   # Octave's JSON reader has no None in a number array: -1 is the ground
        spec["links"] = [[a, -1 if b is None else b, k, fs] for a, b, k, fs in spec["links"]]
    return {**spec, **settings, "x0": start}


def _complete(out: dict, band) -> bool:
    w = np.asarray(out.get("omega") or [], float)
    lo, hi = sorted(band)
    tol = END_TOL * (hi - lo)
    return bool(w.size) and not out.get("error") and w.min() <= lo + tol and w.max() >= hi - tol


def run(kind: str, case, path: str, work: Path, settings: dict, octave: str | None = None,
        timeout: float = 600.0) -> dict:
    """One curve by a peer: its points and costs; from the free start when the stuck one
    fails within ``timeout`` [s] (each start has that much).

    Returns a dict with omega, a1, points, evaluations, time_s (the peer's solve, wall),
    cpu_s, wall_s (the whole process), memory_mb, start, complete, status, and
    ``failed_starts`` (the time spent on starts that did not complete).
    """
    failed = []
    for start in STARTS:
        case_file = work / f"{kind}_{start}_case.json"
        out_file = work / f"{kind}_{start}_out.json"
        case_file.write_text(json.dumps(_spec(case, kind, settings, start)))
        out_file.unlink(missing_ok=True)
        r = run_child([], timeout, command=_command(kind, path, octave, case_file, out_file), cwd=work)
        try:
            out = json.loads(out_file.read_text())
        except (OSError, ValueError):
            tail = (r.stderr or r.stdout).strip().splitlines()
            why = "timed out" if r.code is None else f"exit {r.code}: {tail[-1] if tail else 'no output'}"
            out = {"error": f"no result ({why})"[:300]}
        out.update(memory_mb=r.memory_mb, wall_s=r.time_s, start=start, time_s=out.get("solve_s"))
        if _complete(out, case.band):
            out.update(complete=True, status=f"complete from the {start} linear solution",
                       failed_starts=failed)
            return out
        reached = np.asarray(out.get("omega") or [np.nan], float)
        failed.append({"start": start, "error": out.get("error") or "stopped before the end of the band",
                       "omega_reached": float(reached[-1]), "time_s": r.time_s})
        if r.code is None:
            break   # out of time: another start would only spend as much again
    return {**out, "complete": False, "failed_starts": failed,
            "status": "; ".join(f"{f['start']} start: {f['error']} (last omega {f['omega_reached']:.5g})"
                                for f in failed)[:400]}
