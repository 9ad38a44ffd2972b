"""Accuracy table of the harmonic balance: the truncation-error estimate against the true error.

For each model (the bench's Jenkins chains, :mod:`harmonic_balance.bench_models`, the
mass on one 3D contact point with lift-off, and the UPD-24 sector at three centrifugal
loads) and each H: the refined peak amplitude, its estimated truncation error
(:mod:`harmonic_balance.accuracy`), the true error against a reference peak at
REFERENCE_H (the curve's peak re-solved with 0..REFERENCE_H harmonics, the same corrector
as the estimate's check), their ratio, and the times of the curve and of the check; then
per accuracy target the H the engine chose, the estimate, the true error and the total
time.

Each row also says whether it meets the goals of the estimate and of the defaults:

* ``ratio_ok``: the estimate lies within a factor RATIO_BAND of the true error (None
  without an estimate, or when the true error is below the reference's own resolution:
  TRUE_FLOOR, or REFERENCE_MARGIN times the reference's own estimated truncation error,
  ``reference_error``, from the levels it was raised through).
* ``target_met`` (accuracy rows): the true error is at or below the target; with
  ``engine_met``, whether the engine said so (it says "not met" when the harmonic limit
  stopped it, and the result then carries its message).
* ``default`` (the row of what a command does without accuracy options: ``damper frf``'s
  ``--accuracy 0.01`` from H = 3; ``damper upd frf``'s H = 7): "ok" when its true error is
  within 1 %, "warned" when it is not but its estimate exceeds 1 % (the command prints the
  warning), "FAIL" otherwise.

Run: ``python -m damper.bench.hb_accuracy [--quick] [--only frf|contact|upd] [--json]``
(``make docs-accuracy`` records it for docs/method/accuracy.md). ``damper bench --stage hb``
adds the same rows to its report (:func:`bench_rows`; with ``--quick``, the soft single-DOF
model only: :data:`BENCH_QUICK_MODELS`).
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from .common import Row, self_peak_mb

#: Harmonics of the reference peak (at least; twice the richest peak level of a model's
#: accuracy rows when higher, :func:`_reference_h`). The reference is the first curve's
#: peak raised level after level (:func:`harmonic_balance.accuracy.raise_at_peak`), the
#: same corrector as the runs'. At 61 the references' own estimated errors were 3e-5 to
#: 9e-5 on the stiff single-DOF oscillator, the 3-mass chain at F = 2 N and the contact
#: point (orders ~1), as large as the true errors of the targets' rows.
REFERENCE_H = 122
#: Highest harmonic of the chains' runs to an accuracy.
LIMIT_FRF = 200
#: Reference of the sector, beyond the peak levels' limit (bladed_disk.accuracy.
#: PEAK_MAX_HARMONIC = 80): at 80 UPD-24's peak was still moving at CF 60 and 120 N (own
#: estimated errors 6.8e-4 and 2.8e-4); at 160 they are 7.7e-5 and 6.6e-5, and the CF 120 N
#: peak is within 3e-5 of the ring's time integration. ~25 s of CPU per load.
REFERENCE_H_UPD = 160
#: A target no level meets: the reference's levels run to their limit.
REFERENCE_TOL = 1e-15
#: H of the table's rows.
HS = (3, 7, 15)
#: Accuracy targets of the table's rows.
TOLS = (1e-2, 1e-3)
#: The estimate's goal: within this factor of the true error.
RATIO_BAND = 3.0
#: The defaults' goal: within 1 % of the converged peak, or a warning.
DEFAULT_REL = 1e-2
#: Setting of each model class's default row (what its command does with no accuracy
#: option): ``damper frf`` runs --accuracy 0.01 from H = 3, ``damper upd frf`` H = 7.
DEFAULT_FRF, DEFAULT_UPD = "tol 0.01", "H 7"
#: True errors below this are the reference's own resolution (its truncation left and
#: the corrector's tolerance): a ratio there says nothing.
TRUE_FLOOR = 1e-6
#: A true error is measured only where it exceeds this multiple of the reference's own
#: estimated error e_ref: the true error t is then known within t +- t / 3, so a ratio
#: inside [1/3, 3] is not an artefact of the reference (UPD-24 at CF 120 N: the H = 80
#: reference moves 4.7e-5 from H = 65 at an observed order 0.75, e_ref ~ 3e-4, beside
#: true errors of 1.5e-4 and 3.7e-4 at the targets).
REFERENCE_MARGIN = 3.0
#: Centrifugal loads [N] of the UPD-24 rows (F0 = 30 N).
UPD_CF = (60.0, 120.0, 600.0)
#: Models of ``damper bench --quick``'s accuracy rows: one whose reference costs a second,
#: so the bench's smoke run stays short.
BENCH_QUICK_MODELS = ("sdof soft",)


def _frf_cases(quick: bool):
    from harmonic_balance import bench_models as bm

    cases = [bm.sdof(1.0), bm.sdof(1e4), bm.chain3(1.0, 20.0), bm.chain3(2.0, 200.0), bm.chain5()]
    return cases[:3] if quick else cases


def _contact_cases():
    from harmonic_balance import bench_models as bm

    return [bm.contact_point()]


def _frf_reference(result, H_ref: int) -> tuple[float, float | None]:
    """The peak of ``result``'s curve raised level after level (:func:`accuracy.raise_at_peak`
    with a target no level meets) to the set 0..``H_ref``: (its amplitude [m], its own
    estimated relative error, :func:`_chain`)."""
    from harmonic_balance.frf import TOL_REL
    from harmonic_balance.frf_accuracy import check_problem

    prob = result.problem

    def problem_at(hs):
        rich = check_problem(prob, hs)
        return rich, rich.amplitude, TOL_REL * rich.reference(result.peak_omega), rich.basis
    return _chain(problem_at, prob.basis, result.solutions, result.omega, result.amplitude,
                  (prob.basis.H, result.peak_amplitude, result.peak_omega), H_ref)


def _chain(problem_at, basis, xs, omegas, amplitude, level0, H_ref: int) -> tuple[float, float | None]:
    """(amplitude [m] of the richest level, its estimated relative truncation error from
    the levels below it, :func:`accuracy.richest_error`, or None)."""
    from harmonic_balance import accuracy as acc

    run = acc.raise_at_peak(problem_at, basis, xs,
                            np.asarray(omegas), int(np.argmax(amplitude)), level0, REFERENCE_TOL,
                            H_ref, 1e-6 * level0[2])
    if run["levels"][-1][0] < H_ref - 1:
        raise RuntimeError(f"the reference stopped at H = {run['levels'][-1][0]}: {run['message']}")
    err = (run["error"] or {}).get("peak_amplitude_rel")
    return run["levels"][-1][1], err


def _reference_h(h_peaks, base: int) -> int:
    """Harmonics of a model's reference: ``base``, or twice the richest peak level of its
    accuracy rows when that is higher (the reference must lie well beyond what it judges)."""
    return max([base] + [2 * h for h in h_peaks])


def frf_rows(quick: bool = False, names: tuple[str, ...] | None = None, contact: bool = False) -> list[dict]:
    """Rows of the chain models (``contact``: of the 3D contact point instead): per H and
    per accuracy target (``names``: only these models). The reference of a model is its
    first curve's peak raised to :func:`_reference_h` (after every row of the model)."""
    from harmonic_balance.frf import compute_frf

    rows = []
    for case in _contact_cases() if contact else _frf_cases(quick):
        if names is not None and case.name not in names:
            continue
        model, pending, first = case.model(), [], None
        for H in HS[:2] if quick else HS:
            t0 = time.process_time()
            r = compute_frf(model, H, case.band, stability="off")
            first = first or r
            pending.append((case.name, f"H {H}", r.peak_amplitude, r.truncation_error, None,
                            time.process_time() - t0, H, None, None, DEFAULT_FRF))
        for tol in TOLS[:1] if quick else TOLS:
            t0 = time.process_time()
            r = compute_frf(model, 3, case.band, stability="off", accuracy=tol,
                            max_harmonic=LIMIT_FRF)
            a = r.extra["accuracy"]
            pending.append((case.name, f"tol {tol:g} -> H {a['H_curve']}/{a['H_peak']}", r.peak_amplitude,
                            r.truncation_error, None, time.process_time() - t0, a["H_peak"], tol, a,
                            DEFAULT_FRF))
        ref, ref_err = _frf_reference(first, _reference_h([p[6] for p in pending if p[7] is not None],
                                                          REFERENCE_H))
        rows += [_row(*p[:4], ref, *p[5:], ref_error=ref_err) for p in pending]
    return rows


def upd_rows(quick: bool = False) -> list[dict]:
    """Rows of UPD-24 (F0 = 30 N, the config's band, 200 points) at UPD_CF; at the stored
    time integration's load (hb_reference.json) the peak against it too (``vs_time_integration``)."""
    from harmonic_balance.bladed_disk.accuracy import check_sector, peak_to_accuracy, truncation_error
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.solve import frf

    sector = Sector(load_config(None))
    lo, hi = sector.cfg["load.band_hz"]
    om = 2 * np.pi * np.linspace(lo, hi, 200)
    rows, ti = [], _time_integration()
    for cf in UPD_CF[1:2] if quick else UPD_CF:
        name, pending, first = f"UPD-24 CF {cf:g}", [], None
        for H in (7,) if quick else (7, 15):
            t0 = time.process_time()
            hb = SectorHB(sector, H, cf=cf, f0=30.0)
            c = frf(hb, om)
            rec = truncation_error(hb, c)
            first = first or (hb, c)
            pending.append((name, f"H {H}", c.peak_amplitude, rec, None, time.process_time() - t0, H,
                            None, None, DEFAULT_UPD))
        for tol in TOLS[:1] if quick else TOLS:
            t0 = time.process_time()
            hb, c, rec = peak_to_accuracy(sector, om, tol, 7, cf=cf, f0=30.0)
            a = rec["accuracy"]
            pending.append((name, f"tol {tol:g} -> H {a['H_curve']}/{a['H_peak']}", a["peak_amplitude"], rec,
                            None, time.process_time() - t0, a["H_peak"], tol, a, DEFAULT_UPD))
        hb, c = first

        def problem_at(hs, hb=hb):
            rich = check_sector(hb, hs[-1])
            return rich.__call__, lambda x, w, r=rich: r.amplitude_h1(x), 1e-10 * max(hb.f0, hb.cf), rich.basis
        ref, ref_err = _chain(problem_at, hb.basis, c.x, c.omega, c.amplitude, (hb.H, c.peak_amplitude, c.peak_omega),
                     REFERENCE_H_UPD)
        for p in pending:
            row = _row(*p[:4], ref, *p[5:], ref_error=ref_err)
            if ti is not None and cf == ti["cf"]:
                row["vs_time_integration"] = p[2] / ti["amplitude"] - 1.0
            rows.append(row)
    return rows


def _time_integration() -> dict | None:
    """The ring time integration stored with the UPD-24 reference (hb_reference.json):
    cf [N] (the config's) and amplitude [m] (first harmonic at the peak), or None."""
    from pathlib import Path

    from harmonic_balance.bladed_disk.config import load_config

    path = Path(__file__).with_name("hb_reference.json")
    ti = json.loads(path.read_text()).get("upd24", {}).get("time_integration")
    cfg = load_config(None)
    if not ti or float(cfg["load.f0"]) != 30.0:
        return None
    return {"cf": float(cfg["load.cf"]), "amplitude": float(ti["amplitude"])}


#: Where each row is printed as soon as it is computed (None: not printed).
ECHO = None


def _row(model, setting, amp, rec, ref, dt, H, target=None, run=None, default_of=None, *,
         ref_error=None) -> dict:
    """One row (module docstring): ``run`` the accuracy record of a target's run,
    ``default_of`` the setting of the model class's default row, ``ref_error`` the
    reference's own estimated relative error (None: unknown, TRUE_FLOOR alone applies).
    ``levels``: [H, peak amplitude, peak frequency] of the row's own level and of every
    level or check its estimate came from."""
    est = (rec or {}).get("peak_amplitude_rel")
    true = abs(amp - ref) / abs(ref)
    ratio = est / true if est is not None and true > 0 else None
    floor = max(TRUE_FLOOR, REFERENCE_MARGIN * (ref_error or 0.0))
    row = {"model": model, "setting": setting, "H": int(H), "target": target, "peak_amplitude": amp,
           "reference_amplitude": float(ref), "reference_error": ref_error, "estimate": est,
           "true_error": true, "ratio": ratio, "levels": _levels(rec, amp),
           "ratio_ok": None if ratio is None or true < floor else 1 / RATIO_BAND <= ratio <= RATIO_BAND,
           "target_met": None if target is None else true <= target,
           "engine_met": None if run is None else bool(run.get("met")),
           "default": None, "order": (rec or {}).get("order_observed"),
           "check_time_s": (rec or {}).get("time_s"), "time_s": dt,
           "H_curve": None if run is None else run.get("H_curve")}
    if default_of is not None and setting.split(" -> ")[0] == default_of:
        row["default"] = ("ok" if true <= DEFAULT_REL else
                          "warned" if est is not None and est > DEFAULT_REL else "FAIL")
    row["flags"] = flags(row)
    if ECHO is not None:
        print_table([row], ECHO, header=False)
    return row


def _levels(rec, amp) -> list:
    """[H, peak amplitude, peak omega] of the levels (a run to a target) or of the curve
    (amplitude ``amp``, its frequency not recorded: None) and its checks (a fixed H) that a
    truncation_error record was estimated from."""
    rec = rec or {}
    if rec.get("levels"):
        return [[lv["H"], lv["peak_amplitude"], lv["peak_omega"]] for lv in rec["levels"]]
    own = [] if "H_used" not in rec else [[rec["H_used"], amp, None]]
    return own + [[c["H"], c["peak_amplitude"], c["peak_omega"]] for c in rec.get("checks", [])]


def goals(rows) -> dict:
    """Counts of the goals over ``rows``: ``ratio`` (rows with a ratio, those outside the
    band), ``target`` (target rows, true error above the target), ``default`` (default
    rows, FAIL), and the failing rows' "model / setting" per goal."""
    out = {}
    for key, bad in (("ratio_ok", False), ("target_met", False), ("default", "FAIL")):
        mine = [r for r in rows if r.get(key) is not None]
        out[key] = {"rows": len(mine), "failing": [f"{r['model']} / {r['setting']}" for r in mine
                                                    if r[key] == bad]}
    return out


def bench_rows(quick: bool, log=print) -> list[Row]:
    """The rows of ``damper bench --stage hb``: every model of :func:`frf_rows` and
    :func:`upd_rows` (``quick``: :data:`BENCH_QUICK_MODELS` at the quick H and target).

    A row's ``case`` is ``"accuracy <model>"`` (``"accuracy <model> target"`` for an
    accuracy target), ``size`` the H used, ``error`` the true error against the reference
    peak, ``time_s`` the CPU time of the curve and its check (of a target: every curve and
    check it took); the rest of :func:`frf_rows`'s row rides along (``estimate``, ``ratio``,
    ``setting``, ``target``...).
    """
    log(table_lines([])[0])
    rows = (frf_rows(True, BENCH_QUICK_MODELS) if quick else
            frf_rows(False) + frf_rows(False, contact=True) + upd_rows(False))
    out = []
    for r in rows:
        log(table_lines([r])[1])
        case = f"accuracy {r['model']}" + (" target" if r["target"] is not None else "")
        out.append(Row(case, r["H"], r["true_error"], r["time_s"], self_peak_mb(), False,
                       {k: v for k, v in r.items() if k not in ("H", "true_error", "time_s")}
                       | {"true_error": r["true_error"], "clock": "process"}))
    return out


def table_lines(rows) -> list[str]:
    """The plain-text table of accuracy rows (dicts of :func:`frf_rows`): a header, a line per
    row. ``flags``: ``R`` the ratio outside [1/3, 3], ``u`` a ratio not judged (the true
    error within REFERENCE_MARGIN times the reference's own, or below TRUE_FLOOR), ``T`` a target's true error above it
    (``t`` when the engine said it was not met: the harmonic limit), ``D!`` a default row
    more than 1 % off without a warning, ``D~`` more than 1 % off with the warning."""
    def pct(v):
        return "-" if v is None else f"{100 * v:.3g}%"

    lines = [f"{'model':24s} {'setting':18s} {'peak':>12s} {'estimate':>9s} {'true':>9s} "
             f"{'ratio':>6s} {'check s':>8s} {'total s':>8s} flags"]
    for r in rows:
        lines.append(f"{r['model']:24s} {r['setting']:18s} {r['peak_amplitude']:12.6g} {pct(r['estimate']):>9s} "
                     f"{pct(r['true_error']):>9s} {'-' if r['ratio'] is None else format(r['ratio'], '.2f'):>6s} "
                     f"{'-' if r['check_time_s'] is None else format(r['check_time_s'], '.2f'):>8s} "
                     f"{r['time_s']:8.2f} {r.get('flags') or ''}".rstrip())
    return lines


def flags(r: dict) -> str:
    """The row's goal flags (:func:`table_lines`)."""
    out = []
    if r.get("ratio_ok") is False:
        out.append("R")
    elif r.get("ratio_ok") is None and r.get("ratio") is not None:
        out.append("u")   # the true error is within the reference's own: not judged
    if r.get("target_met") is False:
        out.append("t" if r.get("engine_met") is False else "T")
    if r.get("default") in ("FAIL", "warned"):
        out.append("D!" if r["default"] == "FAIL" else "D~")
    return " ".join(out)


def print_table(rows, out=sys.stdout, header: bool = True) -> None:
    lines = table_lines(rows)
    print("\n".join(lines if header else lines[1:]), file=out, flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer models and settings")
    ap.add_argument("--only", choices=("frf", "contact", "upd"),
                    help="one model class (frf: the Jenkins chains; contact: the 3D contact point)")
    ap.add_argument("--json", action="store_true",
                    help="print the rows as one JSON object on stdout (the table on stderr)")
    a = ap.parse_args(argv)
    global ECHO
    ECHO = sys.stderr
    print_table([], sys.stderr)
    rows = []
    if a.only in (None, "frf"):
        rows += frf_rows(a.quick)
    if a.only in (None, "contact") and not a.quick:
        rows += frf_rows(a.quick, contact=True)
    if a.only in (None, "upd"):
        rows += upd_rows(a.quick)
    if not a.json:
        print_table(rows)
        print(json.dumps(goals(rows), indent=1))
    if a.json:
        print(json.dumps({"reference_H": REFERENCE_H, "reference_H_upd": REFERENCE_H_UPD,
                          "quick": a.quick, "rows": rows, "goals": goals(rows)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
