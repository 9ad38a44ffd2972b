"""Ours against a peer at the harmonics that bring each tool within 1 % of the converged peak.

A fixed H favours neither tool only when both converge alike; what a user pays for is a
peak within a stated accuracy. So for a bench case with a dense reference
(:mod:`.hb_reference`) each tool traces the case over its band at H = SCAN[0], SCAN[1],
... until its first-harmonic peak is within TARGET_REL of the reference; that H and
that curve's time are the tool's. Ours is ``damper frf --harmonics H`` (the fixed-H
command, its truncation check included) in a child process (:func:`.hb_classes.run_ours`),
the peer its driver (:func:`.peers.run`) with the bench's settings, one after the other
in the same run (side by side on the same machine). The ratios are of CPU times (process
time of the solve: less sensitive than wall time to the load of a shared machine), the
wall-time ratio beside it; > 1 means ours is faster. Two of ours:

* the command (``x_cpu``): what a user runs, with its parsing, output, Hill stability of
  the points and truncation-error estimate;
* the curve alone (``x_cpu_curve``, like with like): at the same H, our curve timed as the
  peer's driver times the peer's (:mod:`.peer_ours`: imports first, then the model's build
  and the continuation with its peak refinement; no stability, no truncation check, which
  the peer does not make either). Its peak must be the command's (CURVE_SAME_REL).

The peaks are read as in :mod:`.hb_classes`: ours the engine's refined peak, the peer's
the largest first harmonic of its points refined by a parabola
(:func:`.hb_reference.curve_peak`).
"""
from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

from .common import Row
from .hb_reference import curve_peak

#: The accuracy both tools must reach, relative to the reference peak.
TARGET_REL = 1e-2
#: Harmonics tried in order (0..H each), until the peak is within TARGET_REL.
SCAN = (1, 3, 5, 7, 11, 15, 21, 31, 41)
#: The like-with-like curve (:mod:`.peer_ours`) is the command's curve without the extras
#: that do not move it (stability, truncation check): same points, same peak to round-off.
CURVE_SAME_REL = 1e-9


def _error(peak, ref: dict) -> float | None:
    if peak is None or not math.isfinite(peak):
        return None
    return abs(peak / ref["amplitude"] - 1.0)


def scan_ours(case, work: Path, ref: dict, run_ours, log=print) -> dict:
    """Our curves at SCAN until the peak is within TARGET_REL: the last curve's numbers
    with ``H``, ``error`` and ``scan`` (H, error, time_s, cpu_s of each curve tried);
    ``H`` None when no H of SCAN got there. ``run_ours(name, work, case)`` runs one curve
    (:func:`.hb_classes.run_ours`, passed in: that module calls this one)."""
    tried = []
    for H in SCAN:
        o = run_ours(case.name, work, replace(case, harmonics=H))
        err = _error(o.get("peak_amplitude"), ref) if o.get("complete") else None
        tried.append({"H": H, "error": err, "time_s": o.get("time_s"), "cpu_s": o.get("cpu_s")})
        log(f"    damper H {H:3d}: error {_pct(err)}, {o.get('time_s') or 0:.2f} s")
        if err is not None and err <= TARGET_REL:
            return {**o, "H": H, "error": err, "scan": tried}
    return {**o, "H": None, "error": None, "scan": tried}


def curve_alone(name: str, H: int, work: Path, timeout: float = 600.0) -> dict:
    """Our curve of case ``name`` at H timed like the peer's (:mod:`.peer_ours`, in a child):
    its numbers (``cpu_s``, ``solve_s``, ``peak_amplitude``...), or ``error``."""
    import json

    from .common import run_child

    out_file = work / f"ours_curve_H{H}.json"
    out_file.unlink(missing_ok=True)
    r = run_child([], timeout, cwd=work,
                  command=[sys.executable, "-m", "damper.bench.peer_ours", name, str(H), str(out_file)])
    try:
        return json.loads(out_file.read_text())
    except (OSError, ValueError):
        tail = (r.stderr or r.stdout).strip().splitlines()
        return {"error": f"no result (exit {r.code}: {tail[-1] if tail else 'no output'})"[:300]}


def with_curve_alone(ours: dict, name: str, work: Path, timeout: float = 600.0, curve=curve_alone) -> dict:
    """``ours`` (of :func:`scan_ours`) with ``cpu_curve_s``/``time_curve_s``: the like-with-like
    curve at its H, kept only when its peak is the command's (CURVE_SAME_REL), else
    ``curve_status`` says why not."""
    if ours.get("H") is None:
        return ours
    c = curve(name, ours["H"], work, timeout)
    same = (c.get("error") is None and c.get("peak_amplitude") and ours.get("peak_amplitude")
            and abs(c["peak_amplitude"] / ours["peak_amplitude"] - 1.0) <= CURVE_SAME_REL)
    if not same:
        return {**ours, "curve_status": c.get("error") or
                f"curve alone's peak {c.get('peak_amplitude')} is not the command's {ours.get('peak_amplitude')}"}
    return {**ours, "cpu_curve_s": c["cpu_s"], "time_curve_s": c["solve_s"], "curve_status": "same peak"}


def scan_peer(kind: str, case, path: str, work: Path, settings: dict, ref: dict, octave=None,
              timeout: float = 600.0, log=print) -> dict:
    """The peer's curves at SCAN until its peak is within TARGET_REL (as :func:`scan_ours`)."""
    from . import peers

    tried = []
    for H in SCAN:
        p = peers.run(kind, replace(case, harmonics=H), path, work, settings, octave, timeout)
        pa = curve_peak(p.get("omega") or [], p.get("a1") or [])[0] if p.get("complete") else None
        err = _error(pa, ref)
        tried.append({"H": H, "error": err, "time_s": p.get("time_s"), "cpu_s": p.get("cpu_s"),
                      "status": p.get("status")})
        log(f"    {kind} H {H:3d}: error {_pct(err)}, {p.get('time_s') or 0:.2f} s, {p.get('status')}")
        if err is not None and err <= TARGET_REL:
            return {**p, "H": H, "error": err, "peak_amplitude": pa, "scan": tried}
        if p.get("wall_s") is not None and p["wall_s"] >= timeout:
            break   # out of time at this H: more harmonics only cost more
    return {**p, "H": None, "error": None, "scan": tried}


def row(name: str, tool: str, case, ours: dict, peer: dict) -> Row:
    """The row of one case: the peer's H and time at 1 %, ours beside it, the ratios."""
    both = ours.get("H") is not None and peer.get("H") is not None

    def ratio(key, ours_key=None):   # the peer's over ours, where both reached 1 %
        a, b = peer.get(key), ours.get(ours_key or key)
        return a / b if both and a and b else None
    extra = {"tool": tool, "model": name, "mode": f"each tool at its own H for {100 * TARGET_REL:g} %",
             "H_peer": peer.get("H"), "H_ours": ours.get("H"), "error_peer": peer.get("error"),
             "error_ours": ours.get("error"), "time_peer_s": peer.get("time_s"),
             "time_ours_s": ours.get("time_s"), "cpu_peer_s": peer.get("cpu_s"),
             "cpu_ours_s": ours.get("cpu_s"), "speedup_cpu_1pct": ratio("cpu_s"),
             "speedup_1pct": ratio("time_s"), "check_ours_s": ours.get("check_s"),
             "speedup_curve_1pct": _curve_ratio(peer, ours) if both else None,
             "cpu_curve_ours_s": ours.get("cpu_curve_s"), "time_curve_ours_s": ours.get("time_curve_s"),
             "speedup_cpu_curve_1pct": ratio("cpu_s", "cpu_curve_s"),
             "curve_status": ours.get("curve_status"),
             "points_ours": ours.get("points"), "evaluations_ours": ours.get("evaluations"),
             "points_peer": peer.get("points"), "evaluations_peer": peer.get("evaluations"),
             "scan_peer": peer.get("scan"), "scan_ours": ours.get("scan"),
             "status": peer.get("status") if peer.get("H") is None else "both within 1 %"}
    H = peer.get("H") or SCAN[-1]
    return Row(f"{name} [{tool} @1%]", float(case.n * (2 * H + 1)), peer.get("error"), peer.get("time_s"),
               peer.get("memory_mb"), False, extra)


def _curve_ratio(peer: dict, ours: dict) -> float | None:
    """The peer's wall time over our curve's alone (our command's time less its
    truncation check, which the peer does not make)."""
    t, c = ours.get("time_s"), ours.get("check_s") or 0.0
    return peer["time_s"] / (t - c) if peer.get("time_s") and t and t > c else None


def run(names, kind: str, path: str, work: Path, settings: dict, run_ours, octave=None,
        timeout: float = 600.0, log=print) -> list[Row]:
    """The rows of :func:`row` for the named bench cases that have a stored reference
    (``run_ours`` as in :func:`scan_ours`)."""
    from harmonic_balance.bench_models import by_name

    from .hb_reference import load as load_reference
    from .hb_reference import reference_key

    tool = {"pyharm": "pyHarm", "nlvib": "NLvib"}[kind]
    rows = []
    for name in names:
        ref = load_reference(reference_key(name), log, compute_missing=False)
        if ref is None or name == "upd24":
            continue
        case = by_name(name)
        sub = work / f"{name.replace(' ', '_').replace('=', '')}_1pct"
        sub.mkdir(parents=True, exist_ok=True)
        log(f"  {name}: each tool at its own H for {100 * TARGET_REL:g} %")
        ours = with_curve_alone(scan_ours(case, sub, ref, run_ours, log), name, sub, timeout)
        peer = scan_peer(kind, case, path, sub, settings, ref, octave, timeout, log)
        rows.append(row(name, tool, case, ours, peer))
        e = rows[-1].extra
        log(f"  {name}: damper H {e['H_ours']}, {tool} H {e['H_peer']}; {tool} / damper CPU "
            f"{_num(e['speedup_cpu_1pct'])}, wall {_num(e['speedup_1pct'])}")
    return rows


def _pct(v) -> str:
    return "-" if v is None else f"{100 * v:.3g} %"


def _num(v) -> str:
    return "-" if v is None else f"{v:.1f}"


#: Columns of :func:`markdown`: header, row key, format.
COLUMNS = (("case", "model", "s"), ("tool", "tool", "s"), ("H ours", "H_ours", "d"), ("H peer", "H_peer", "d"),
           ("CPU ours, command [s]", "cpu_ours_s", ".3f"), ("CPU ours, curve [s]", "cpu_curve_ours_s", ".3f"),
           ("CPU peer [s]", "cpu_peer_s", ".2f"), ("x_cpu", "speedup_cpu_1pct", ".1f"),
           ("x_cpu_curve", "speedup_cpu_curve_1pct", ".1f"), ("x_wall", "speedup_1pct", ".1f"))


def markdown(rows: list[dict]) -> list[str]:
    """Markdown table of the rows of :func:`run` (as dicts), with its legend."""
    out = ["| " + " | ".join(h for h, _, _ in COLUMNS) + " | status |", "|" + "---|" * (len(COLUMNS) + 1)]
    for r in rows:
        cells = [_fmt(r.get(k), f) for _, k, f in COLUMNS]
        out.append("| " + " | ".join(cells) + f" | {(r.get('status') or '')[:80]} |")
    out += ["", f"H: the first of {', '.join(map(str, SCAN))} whose first-harmonic peak is within "
            f"{100 * TARGET_REL:g} % of the case's dense reference. x_cpu: the peer's CPU time over our "
            "command's (`damper frf --harmonics H`, with Hill stability and the truncation-error "
            "estimate); x_cpu_curve: over our curve timed as the peer's driver times the peer's "
            "(imports first, no stability, no truncation check; `damper.bench.peer_ours`), like with "
            "like; x_wall: wall time of the peer over our command's."]
    return out


def _fmt(v, fmt: str) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return format(v, fmt)
