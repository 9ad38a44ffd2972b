"""Model classes of the forced-response engine, with peers: the hb stage's curve rows.

Cases (:mod:`harmonic_balance.bench_models`, defined once): the single-DOF Jenkins
oscillator soft (k_t = k) and stiff (1e4 k, 1e6 k); NLvib's 3-mass friction chain
over force 0.5 / 1 / 2 N and link stiffness 20 / 200 / 2000 N/m, both directions
(:data:`CHAIN3_DEFAULT` by default, all 18 with ``full``); the 5-mass chain with three
links, both directions; UPD-24 (``damper upd frf`` with its defaults).

Each curve is run the way a user runs it -- the ``damper frf`` / ``damper upd frf``
command with its default settings, in a child process (its ``--json`` output; the
imports happen before the clock starts) -- so the rows follow whatever version of the
engine is installed. A row gives points, residual evaluations, the solver's time
(``time_s``, wall; ``cpu_s``, process time: less sensitive to the load of a shared
machine), the child's peak memory, and the first-harmonic peak of the response DOF
with its error against the model's dense reference (:mod:`.hb_reference`): ``error``
against the high-H trace (truncation in H included), ``trace_error`` against the dense
trace at the case's own H (what the curve's points, steps and AFT cost).

The peak of a row: the engine's refined peak where it reports one (``peak_omega``,
first harmonic there); else, and for peers (which report points only), the largest
first harmonic of the traced points refined by a parabola through its neighbours
(:func:`.hb_reference.curve_peak`). ``points_error`` gives the engine's points read the
peers' way (against the dense trace at the same H), so both can be compared alike.

Peers (optional, never in CI): pyHarm (``pyharm`` = path of a Python that has
``pyharm-os``; :mod:`.peer_pyharm`, pseudo-arclength) and NLvib (``nlvib`` = its folder,
run by GNU Octave; ``peer_nlvib.m``, arc-length), each given the same model, H, band and
direction, with :data:`PEER_SETTINGS`. A peer that fails from its usual start (the
linear solution with the links stuck) is run again from the free linear solution, and
the row says so. ``speedup`` = the peer's time / ours, measured in the same run, one
case after the other.
"""
from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .common import Row, run_child
from .hb_reference import curve_peak, reference_key
from .hb_reference import load as load_reference

#: The 3-mass chain's curves in the default run (the full grid with ``full``): the
#: stalled-corrector case (F = 1, knl = 20, down), its upward twin, the curve that
#: stepped over its peak (0.5, 2000, up) and the longest one (2, 2000).
CHAIN3_DEFAULT = ("chain3 F=1 knl=20 up", "chain3 F=1 knl=20 down", "chain3 F=0.5 knl=2000 up",
                  "chain3 F=2 knl=2000 up")
#: Peer settings of every curve: AFT samples, first and largest continuation step (as the
#: peers' own examples and the measurements the engine's goals quote).
PEER_SETTINGS = {"nti": 1024, "ds0": 0.01, "ds_max": 0.05, "corrector": "pseudo_arc_length"}
#: Time limits of one curve [s]: ours, a peer's from one start (NLvib in Octave needs
#: 1-3 min for a curve it completes; measured on the stiff single-DOF case it ran for
#: over 15 min without finishing).
TIMEOUT_S, PEER_TIMEOUT_S = 1800.0, 600.0
#: The child that runs a ``damper`` command: imports first (start-up has its own
#: measurement; a peer's driver, too, imports the peer before its clock starts), also
#: those the command makes on first use (scipy.linalg, the C core: 0.2 s of CPU, four
#: times a 42-point 3-mass curve), then the command with its CPU time on stderr.
_CHILD = ("import importlib, sys, time\n"
          "for m in ('harmonic_balance.frf', 'harmonic_balance.bladed_disk.solve', 'damper.cli', 'scipy.linalg',\n"
          "          'fmu_src.element', 'harmonic_balance.frf_accuracy', 'harmonic_balance.stability',\n"
          "          'damper.limits', 'damper.provenance'):\n"
          "    try:\n"
          "        importlib.import_module(m)\n"
          "    except ImportError:\n"
          "        pass\n"
          "from damper.cli import main\n"
          "c0 = time.process_time()\n"
          "code = main(sys.argv[1:])\n"
          "sys.stderr.write('\\n@@cpu %r\\n' % (time.process_time() - c0))\n"
          "sys.exit(code)\n")


@dataclass
class ModelOptions:
    """What the model rows run: all 3-mass curves (``full``), a name filter, the peers."""

    full: bool = False
    cases: tuple = ()             # substrings; a case runs when its name contains one
    pyharm: str | None = None     # Python interpreter with pyHarm
    nlvib: str | None = None      # NLvib folder
    octave: str | None = None     # GNU Octave executable (default: "octave" on PATH)


def case_names(quick: bool, opts: ModelOptions) -> list[str]:
    """The model rows' cases in run order: with ``opts.cases``, every case whose name
    contains one of them (the whole grid); else the quick, default or full set."""
    from harmonic_balance.bench_models import all_cases

    every = [c.name for c in all_cases()] + ["upd24"]
    if opts.cases:
        return [n for n in every if any(s in n for s in opts.cases)]
    if quick:
        return ["sdof soft"]
    return [n for n in every if not n.startswith("chain3") or opts.full or n in CHAIN3_DEFAULT]


def _write_model(case, folder: Path) -> list[str]:
    """``damper frf`` arguments of a case (files for a chain) with the command's defaults."""
    if case.name.startswith("sdof"):
        link = case.links[0]
        model = ["--model", "sdof", "--mass", _arg(case.M[0, 0]), "--stiffness", _arg(case.K[0, 0]),
                 "--damping", _arg(case.C[0, 0]), "--contact-stiffness", _arg(link.k),
                 "--slip-force", _arg(link.fs), "--force", _arg(case.force[0])]
    else:
        # the name as the files' stem: "F=0.5" holds a dot, so no with_suffix (it would
        # cut the name there and let two cases share a file)
        stem = case.name.replace(" ", "_").replace("=", "")
        npz, toml = folder / f"{stem}.npz", folder / f"{stem}.toml"
        np.savez(npz, M=case.M, K=case.K, C=case.C, force=case.force, response_dof=case.response_dof)
        tables = [f"[[element]]\ndofs = {[j.dof_a] if j.dof_b is None else [j.dof_a, j.dof_b]}\n"
                  f"type = \"jenkins\"\nk = {j.k!r}\nfs = {j.fs!r}\n" for j in case.links]
        toml.write_text("\n".join(tables))
        model = ["--model", str(npz), "--elements", str(toml)]
    return ["frf", *model, "--harmonics", str(case.harmonics), "--omega", *map(_arg, case.band), "--json"]


def _arg(v) -> str:
    """A number as a command-line argument, exactly (the shortest repr of the float)."""
    return repr(float(v))


def _cpu(stderr: str) -> float | None:
    """The child's CPU time of the command [s] (the line _CHILD writes), or None."""
    _, sep, tail = stderr.rpartition("@@cpu ")
    try:
        return float(tail.split()[0]) if sep else None
    except (ValueError, IndexError):
        return None


def run_ours(name: str, work: Path, case=None) -> dict:
    """One curve of the engine through the CLI (module docstring): the row's numbers
    (``case``: this BenchCase instead of the named one, e.g. at another H)."""
    if name == "upd24":
        argv, dofs, H = ["upd", "frf", "--json"], None, 7
    else:
        from harmonic_balance.bench_models import by_name

        case = case or by_name(name)
        argv, dofs, H = _write_model(case, work), case.n, case.harmonics
    r = run_child(argv, TIMEOUT_S, python_code=_CHILD)
    out = {"tool": "damper", "code": r.code, "memory_mb": r.memory_mb, "wall_s": r.time_s,
           "cpu_s": _cpu(r.stderr), "dofs": dofs, "harmonics": H}
    try:
        j = r.json()
    except ValueError:
        msg = r.stderr.replace(f"@@cpu {out['cpu_s']!r}", "").strip().splitlines()
        return {**out, "status": f"failed (exit {r.code}): {msg[-1] if msg else 'no output'}"[:300]}
    if name == "upd24":
        return {**out, **_upd_numbers(j)}
    w, a1 = np.asarray(j["omega"], float), np.asarray(j["amplitude_h1"], float)
    engine = j.get("peak_interior") and j.get("peak_amplitude_h1") is not None
    pa, pw, _ = curve_peak(w, a1)
    return {**out, "points": j["points"], "evaluations": j.get("residual_evaluations"),
            "time_s": j.get("time_s"), "check_s": (j.get("truncation_error") or {}).get("time_s"),
            "status": j.get("status", ""),
            "complete": r.code == 0, "gaps": "restart" in j.get("status", ""),
            "peak_amplitude": j["peak_amplitude_h1"] if engine else pa,
            "peak_omega": j["peak_omega"] if engine else pw, "peak_refined": bool(engine),
            "points_peak": [pa, pw], "omega_range": [float(w.min()), float(w.max())] if w.size else None}


def _upd_numbers(j: dict) -> dict:
    """Row numbers of a ``damper upd frf --json`` result."""
    f = np.asarray(j["frequency_hz"], float)
    pa, pw, _ = curve_peak(2 * np.pi * f, j["amplitude"])
    # the solved points: the continuation's own (the curve is reported interpolated on the
    # output grid); a linear curve (no continuation) is solved at each grid point
    points = j.get("branch_points") or int(f.size)
    return {"points": points, "evaluations": j.get("evaluations"), "time_s": j.get("time_s"),
            "status": j.get("method", ""), "complete": True, "gaps": False, "dofs": j.get("dofs"),
            "harmonics": j.get("harmonics", 7), "peak_amplitude": j["peak_amplitude"],
            "peak_omega": 2 * np.pi * j["peak_frequency_hz"], "peak_refined": True, "points_peak": [pa, pw]}


def _peak_error(peak, ref, key: str | None = None) -> float | None:
    """|peak / reference - 1|: the high-H reference, or its entry ``key`` (``same_h``)."""
    ref = ref.get(key) if ref is not None and key else ref
    if ref is None or peak is None or not math.isfinite(peak):
        return None
    return abs(peak / ref["amplitude"] - 1.0)


def _unknowns(dofs, H) -> float:
    return float(dofs * (2 * H + 1)) if dofs else float("nan")


def _our_row(name: str, o: dict, ref: dict | None) -> Row:
    pa = o.get("points_peak", [None])[0]
    extra = {k: o.get(k) for k in ("tool", "dofs", "harmonics", "points", "evaluations", "cpu_s", "wall_s",
                                   "status", "complete", "gaps", "peak_amplitude", "peak_omega",
                                   "peak_refined")}
    extra.update(_ref_extra(ref))
    ref = ref if o.get("complete") else None   # a curve that stopped part-way has no peak error
    extra.update(model=name, points_error=_peak_error(pa, ref, "same_h"),
                 trace_error=_peak_error(o.get("peak_amplitude"), ref, "same_h"))
    return Row(f"{name} [damper]", _unknowns(o["dofs"], o["harmonics"]),
               _peak_error(o.get("peak_amplitude"), ref), o.get("time_s"), o["memory_mb"], False, extra)


def _ref_extra(ref: dict | None) -> dict:
    if ref is None:
        return {"reference": None}
    return {"reference": {k: ref.get(k) for k in ("amplitude", "omega", "error_estimate", "same_h", "how",
                                                  "revision")}}


def _peer_row(name: str, kind: str, case, p: dict, ours: dict, ref: dict | None) -> Row:
    tool = {"pyharm": "pyHarm", "nlvib": "NLvib"}[kind]
    pa, pw, _ = curve_peak(p.get("omega") or [], p.get("a1") or [])
    t, c = p.get("time_s"), p.get("cpu_s")
    both = p.get("complete") and ours.get("complete")
    ref_shown, ref = ref, ref if p.get("complete") else None   # no peak error of a curve cut short
    extra = {"tool": tool, "model": name, "dofs": case.n, "harmonics": case.harmonics,
             "points": p.get("points"), "evaluations": p.get("evaluations"), "cpu_s": c,
             "wall_s": p.get("wall_s"), "status": p.get("status"), "complete": p.get("complete"),
             "start": p.get("start"), "failed_starts": p.get("failed_starts"),
             "peak_amplitude": pa, "peak_omega": pw, "peak_refined": False,
             "trace_error": _peak_error(pa, ref, "same_h"),
             # ours against theirs on a curve both complete, measured in this run (> 1: ours is faster)
             "speedup": t / ours["time_s"] if both and t and ours.get("time_s") else None,
             "speedup_cpu": c / ours["cpu_s"] if both and c and ours.get("cpu_s") else None,
             **_ref_extra(ref_shown)}
    return Row(f"{name} [{tool}]", _unknowns(case.n, case.harmonics), _peak_error(pa, ref), t,
               p.get("memory_mb"), False, extra)


def _finite(v):
    """NaN / inf -> None, through dicts and lists (JSON has no NaN)."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite(x) for x in v]
    return v


def _clean(row: Row) -> Row:
    return Row(row.case, _finite(row.size), _finite(row.error), _finite(row.time_s), _finite(row.memory_mb),
               row.cached, _finite(row.extra))


def _absent_row(name: str, kind: str, dofs, H, why: str) -> Row:
    tool = {"pyharm": "pyHarm", "nlvib": "NLvib"}[kind]
    return Row(f"{name} [{tool}]", _unknowns(dofs, H), None, None, None, False,
               {"tool": tool, "model": name, "dofs": dofs, "harmonics": H, "status": why})


def _upd_dofs() -> int | None:
    try:
        from harmonic_balance.bladed_disk.config import load_config
        from harmonic_balance.bladed_disk.sector import Sector

        return int(Sector(load_config(None)).n_dof)
    except (ImportError, AttributeError):
        return None


def run(quick: bool, work: Path, log=print, opts: ModelOptions | None = None) -> list[Row]:
    """The model rows (module docstring): ours for every case, then each configured peer,
    then each peer against ours at the H that brings each within 1 % (:mod:`.peer_accuracy`)."""
    from . import peer_accuracy, peers

    opts = opts or ModelOptions()
    kinds = {}
    if not quick:
        octave = opts.octave or shutil.which("octave")
        kinds = {k: (p, peers.available(k, p, octave, work))
                 for k, p in (("pyharm", opts.pyharm), ("nlvib", opts.nlvib))}
    rows = []
    for name in case_names(quick, opts):
        # a quick run never spends minutes on a missing reference: its rows then have no error
        ref = load_reference(reference_key(name), log, compute_missing=not quick)
        if ref is None:
            log(f"{name}: no stored reference (python -m damper.bench.hb_reference --write)")
        sub = work / name.replace(" ", "_").replace("=", "")
        sub.mkdir(parents=True, exist_ok=True)
        ours = run_ours(name, sub)
        if name == "upd24":
            ours["dofs"] = _upd_dofs()
        rows.append(_clean(_our_row(name, ours, ref)))
        log(_line(rows[-1].as_dict()))
        for kind, (path, why) in kinds.items():
            if name == "upd24":
                rows.append(_absent_row(name, kind, ours["dofs"], 7, "not posed (contacts with a varying "
                                        "normal load and cyclic symmetry: no such element in the peer)"))
                continue
            from harmonic_balance.bench_models import by_name

            case = by_name(name)
            if why:
                rows.append(_absent_row(name, kind, case.n, case.harmonics, why))
                continue
            p = peers.run(kind, case, path, sub, PEER_SETTINGS, octave, PEER_TIMEOUT_S)
            rows.append(_clean(_peer_row(name, kind, case, p, ours, ref)))
            log(_line(rows[-1].as_dict()))
    for kind, (path, why) in kinds.items():   # then each tool at its own H for 1 %
        if not why:
            rows += [_clean(r) for r in peer_accuracy.run(case_names(quick, opts), kind, path, work,
                                                          PEER_SETTINGS, run_ours, octave, PEER_TIMEOUT_S,
                                                          log)]
    return rows


def _num(v, fmt: str) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, fmt)


HEAD = (f"{'case':26s} {'tool':7s} {'DOFs':>4s} {'H':>3s} {'points':>6s} {'evals':>6s} {'time_s':>7s} "
        f"{'cpu_s':>7s} {'peak_a1':>11s} {'peak_w':>9s} {'error':>8s} {'trace':>8s} {'pts_err':>8s} {'mem_MB':>6s} "
        f"{'x_wall':>6s} {'x_cpu':>6s}  status")


def _line(r: dict) -> str:
    return (f"{r['model']:26s} {r['tool']:7s} {_num(r.get('dofs'), 'd'):>4s} {_num(r.get('harmonics'), 'd'):>3s} "
            f"{_num(r.get('points'), 'd'):>6s} {_num(r.get('evaluations'), 'd'):>6s} "
            f"{_num(r.get('time_s'), '.2f'):>7s} {_num(r.get('cpu_s'), '.2f'):>7s} "
            f"{_num(r.get('peak_amplitude'), '.6e'):>11s} {_num(r.get('peak_omega'), '.6g'):>9s} "
            f"{_num(r.get('error'), '.1e'):>8s} {_num(r.get('trace_error'), '.1e'):>8s} "
            f"{_num(r.get('points_error'), '.1e'):>8s} "
            f"{_num(r.get('memory_mb'), '.0f'):>6s} {_num(r.get('speedup'), '.1f'):>6s} "
            f"{_num(r.get('speedup_cpu'), '.1f'):>6s}  "
            f"{(r.get('status') or '')[:90]}")


def table(rows: list[dict]) -> str:
    """Plain-text table of the model rows, with the references they are measured against."""
    at_1pct = [r for r in rows if r.get("mode")]
    rows = [r for r in rows if not r.get("mode")]
    lines = [HEAD] + [_line(r) for r in rows]
    lines.append("error: against the dense high-H reference; trace: against the dense trace at the case's "
                 "own H; pts_err: our points read the peers' way (parabola through the largest first "
                 "harmonic), against the same; x_wall, x_cpu: the peer's time over ours (wall, CPU), "
                 "measured in this run")
    lines += at_1pct_lines(at_1pct)
    for tool in dict.fromkeys(r["tool"] for r in rows if r["tool"] != "damper"):
        ran = [r for r in rows if r["tool"] == tool and r.get("time_s")]
        done = [r for r in ran if r.get("complete")]
        x = [r["speedup"] for r in done if r.get("speedup")]
        xc = [r["speedup_cpu"] for r in done if r.get("speedup_cpu")]
        if ran:
            lines.append(f"{tool}: {len(done)} of {len(ran)} curves complete; ours faster by "
                         f"{_num(float(np.median(x)) if x else None, '.1f')} (wall) and "
                         f"{_num(float(np.median(xc)) if xc else None, '.1f')} (CPU), medians over "
                         "the complete ones")
    refs = {reference_key(r["model"]): r["reference"] for r in rows if r.get("reference")}
    lines.append("references (dense traces, hb_reference.py):")
    for name, ref in refs.items():
        same = ref.get("same_h") or {}
        lines.append(f"  {name}: {ref['amplitude']:.9g} at {ref['omega']:.7g} rad/s, own error "
                     f"<= {ref['error_estimate']:.1e}; at H = {same.get('H')}: {same.get('amplitude', 0):.9g}; "
                     f"{ref['how']}")
    return "\n".join(lines)


def at_1pct_lines(rows: list[dict]) -> list[str]:
    """Lines of the rows of :mod:`.peer_accuracy` (each tool at its own H for 1 %)."""
    if not rows:
        return []
    out = [f"each tool at the H that brings its peak within 1 % of the reference: {'case':24s} "
           f"{'tool':7s} {'H ours':>6s} {'H peer':>6s} {'cpu ours':>8s} {'cpu peer':>8s} {'x_cpu':>6s} "
           f"{'x_cpu_curve':>11s} {'x_wall':>6s} {'x_curve':>7s}"]
    for r in rows:
        out.append(f"  {r['model']:24s} {r['tool']:7s} {_num(r.get('H_ours'), 'd'):>6s} "
                   f"{_num(r.get('H_peer'), 'd'):>6s} {_num(r.get('cpu_ours_s'), '.2f'):>8s} "
                   f"{_num(r.get('cpu_peer_s'), '.2f'):>8s} {_num(r.get('speedup_cpu_1pct'), '.1f'):>6s} "
                   f"{_num(r.get('speedup_cpu_curve_1pct'), '.1f'):>11s} "
                   f"{_num(r.get('speedup_1pct'), '.1f'):>6s} {_num(r.get('speedup_curve_1pct'), '.1f'):>7s}  "
                   f"{(r.get('status') or '')[:60]}")
    out.append("  x_cpu, x_wall: the peer's time over our command's (its truncation check included); "
               "x_cpu_curve: over our curve timed like the peer's (peer_ours); x_curve: over our "
               "command's wall time less its truncation check")
    return out


def markdown(rows: list[dict]) -> list[str]:
    """Markdown table of the model rows."""
    out = ["| case | tool | DOFs | H | points | evaluations | time [s] | CPU [s] | peak a1 | peak omega | "
           "error | trace error | memory [MB] | speed-up (wall) | speed-up (CPU) | status |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['model']} | {r['tool']} | {_num(r.get('dofs'), 'd')} | {_num(r.get('harmonics'), 'd')} | "
                   f"{_num(r.get('points'), 'd')} | {_num(r.get('evaluations'), 'd')} | "
                   f"{_num(r.get('time_s'), '.2f')} | {_num(r.get('cpu_s'), '.2f')} | "
                   f"{_num(r.get('peak_amplitude'), '.6e')} | {_num(r.get('peak_omega'), '.6g')} | "
                   f"{_num(r.get('error'), '.1e')} | {_num(r.get('trace_error'), '.1e')} | "
                   f"{_num(r.get('memory_mb'), '.0f')} | "
                   f"{_num(r.get('speedup'), '.1f')} | {_num(r.get('speedup_cpu'), '.1f')} | "
                   f"{(r.get('status') or '')[:80]} |")
    return out
