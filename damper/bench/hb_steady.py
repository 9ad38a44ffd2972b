"""Harmonic balance against time integration, one row per model: is it the same steady state?

For every model of the hb stage's model classes (:mod:`.hb_classes`; the two sweep
directions of a model share one row): the first-harmonic peak of the dense high-H
reference (:mod:`.hb_reference`: the converged harmonic balance) against the peak of
the time integration from rest (:func:`harmonic_balance.timeint.march_curve`: every
link virgin, at the reference's peak frequency and +-TI_REL of it, the first harmonic
through a parabola; its step error from 256 against 512 steps a period), their
difference, and whether the two are different steady states: the curve at the case's
own H near the peak, checked by :func:`harmonic_balance.steady_state.check_peak` (time
integrations at its peak from rest and from the harmonic balance's state; both carry
the same truncation and step, so only the states differ). UPD-24: its reference's ring
time integration (stored with the reference), and the same question for the sector at
the bench's H = 7 near the peak by :func:`harmonic_balance.bladed_disk.steady.check_peak`
(the tuned ring marched from rest and from the sector HB's state; ~3 s of CPU at CF
120 N).

A row: ``case`` "steady <model>" ("steady UPD-24 CF <CF>" for UPD-24), ``size`` the
reference's H, ``error`` |HB / TI - 1|,
``time_s`` the time integrations' and the check's wall time; ``states_differ`` the flag,
``beyond_errors`` whether the difference exceeds the reference's error estimate, the
time integration's step error and TI_PEAK_TOL together.
"""
from __future__ import annotations

import time

import numpy as np

from .common import Row, self_peak_mb

#: Frequencies of the time integration around the reference peak: +- this fraction
#: (as the UPD-24 reference's ring check, hb_reference.UPD_TI_REL).
TI_REL = 2e-3
#: Time steps per period of the time integration (raised for stability by timeint); its
#: step error is the change from half as many.
TI_STEPS = 512
#: Settling tolerance of the curve's time integrations (timeint's extrapolated
#: distance to steady state), well below the differences the rows measure.
TI_TOL = 1e-7
#: Difference of the HB and TI peaks still explained by the three-point parabola's
#: reading of the TI peak (curvature over +-TI_REL: < 1e-4 on the bench's peaks) and the
#: HB reference's own peak reading (1e-5); added to the measured errors before
#: ``beyond_errors``.
TI_PEAK_TOL = 1e-3
#: Half-width of the window of the case's own-H curve that the state check traces
#: around the reference peak (relative; the peak moves by < 1 % with H on the bench).
CHECK_WINDOW = 0.03
#: UPD-24's state check: the bench's (``damper upd frf``'s) H and the grid of its window
#: (the continuation refines the peak on the branch; the grid only starts it).
UPD_H, UPD_CHECK_POINTS = 7, 30
#: Models of a quick run: one whose time integration costs a second.
QUICK_MODELS = ("sdof soft",)


def models(quick: bool) -> list[str]:
    """The reference keys of the rows: the hb stage's model classes (each once)."""
    from .hb_classes import ModelOptions, case_names
    from .hb_reference import reference_key

    if quick:
        return list(QUICK_MODELS)
    return list(dict.fromkeys(reference_key(n) for n in case_names(False, ModelOptions())))


def _ti_peak(model, omega: float) -> dict:
    """Time-integration first-harmonic peak near ``omega`` (parabola through three
    frequencies) at 512 steps a period, with its step error against 256."""
    from harmonic_balance.timeint import march_curve

    w = omega * np.array([1.0 - TI_REL, 1.0, 1.0 + TI_REL])
    coarse = march_curve(model, w, TI_STEPS // 2, tol=TI_TOL)
    fine = march_curve(model, w, 2 * coarse.steps_per_period, tol=TI_TOL)
    if not (coarse.converged.all() and fine.converged.all()):
        raise RuntimeError(f"time integration did not reach steady state near omega = {omega:g}")
    a1 = fine.amplitude_h1
    c2, c1, c0 = np.polyfit(w - omega, a1, 2)
    peak, at = (c0 - c1 * c1 / (4 * c2), omega - c1 / (2 * c2)) if c2 < 0 else (a1.max(), w[np.argmax(a1)])
    err = np.abs(a1 / coarse.amplitude_h1 - 1.0)
    return {"amplitude": float(peak), "omega": float(at), "step_error": float(err.max()),
            "steps_per_period": int(fine.steps_per_period), "periods": int(fine.periods.max())}


def _state_check(case, omega: float) -> dict:
    """The case's own-H curve near ``omega`` and :func:`check_peak` at its peak."""
    from harmonic_balance.frf import compute_frf
    from harmonic_balance.steady_state import check_peak

    lo, hi = sorted(case.band)
    win = (max(lo, omega * (1 - CHECK_WINDOW)), min(hi, omega * (1 + CHECK_WINDOW)))
    r = compute_frf(case.model(), case.harmonics, win, stability="off", truncation_check=False)
    return check_peak(r)


def _upd_state_check(omega: float) -> dict:
    """UPD-24's curve at the bench's H near ``omega`` (``damper upd frf`` defaults) and the
    ring check at its peak."""
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.solve import frf
    from harmonic_balance.bladed_disk.steady import check_peak

    hb = SectorHB(Sector(load_config()), UPD_H)
    c = frf(hb, omega * np.linspace(1 - CHECK_WINDOW, 1 + CHECK_WINDOW, UPD_CHECK_POINTS))
    return check_peak(hb, c)


def case_label(key: str) -> str:
    """The row's case name: "steady <model>", UPD-24 with its centrifugal load."""
    if key != "upd24":
        return f"steady {key}"
    from harmonic_balance.bladed_disk.config import load_config

    return f"steady UPD-24 CF {load_config().cf:g}"


def model_row(key: str, log=print) -> dict:
    """One model's row (module docstring) as a dict."""
    from harmonic_balance.bench_models import by_name

    from .hb_reference import load

    t0 = time.perf_counter()
    ref = load(key, log, compute_missing=True)
    row = {"model": key, "hb_peak": ref["amplitude"], "hb_omega": ref["omega"],
           "hb_H": ref.get("dense", {}).get("H"), "hb_error": ref.get("error_estimate"),
           "states_differ": None, "check": None}
    if key == "upd24":
        ti = ref.get("time_integration") or {}
        chk = _upd_state_check(ref["omega"])
        row.update(ti_peak=ti.get("amplitude"), ti_omega=ti.get("omega"), ti_error=ti.get("settle_error"),
                   states_differ=chk.get("states_differ"), check=_check_fields(chk),
                   how=f"ring time integration stored with the reference; state check on the ring at "
                       f"H = {UPD_H} (bladed_disk.steady)")
    else:
        case = by_name(key + " up") if key.startswith(("chain3", "chain5")) else by_name(key)
        ti = _ti_peak(case.model(), ref["omega"])
        chk = _state_check(case, ref["omega"])
        row.update(ti_peak=ti["amplitude"], ti_omega=ti["omega"], ti_error=ti["step_error"],
                   states_differ=chk.get("states_differ"),
                   check=_check_fields(chk),
                   how=f"timeint.march_curve at {ti['steps_per_period']} steps a period, "
                       f"+-{TI_REL:g} of the reference peak; state check at H = {case.harmonics}")
    d = row["hb_peak"] / row["ti_peak"] - 1.0 if row.get("ti_peak") else None
    allowed = (row["hb_error"] or 0.0) + (row["ti_error"] or 0.0) + TI_PEAK_TOL
    row.update(difference=d, beyond_errors=None if d is None else bool(abs(d) > allowed),
               time_s=time.perf_counter() - t0)
    return row


def _check_fields(chk: dict) -> dict:
    """The state check's fields a row keeps."""
    return {k: chk.get(k) for k in ("omega", "hb_amplitude", "from_rest", "from_hb_state", "states_rel",
                                    "hb_mean", "mean_from_rest", "mean_from_hb_state", "stuck_links",
                                    "periods", "converged", "cpu_s", "note")}


def bench_rows(quick: bool, log=print) -> list[Row]:
    """The rows of ``damper bench --stage hb`` (module docstring), printed as they come."""
    log(HEAD)
    out = []
    for key in models(quick):
        r = model_row(key, lambda s: log("  " + s))
        log(line(r))
        out.append(Row(case_label(key), r["hb_H"] or 0, None if r["difference"] is None else abs(r["difference"]),
                       r["time_s"], self_peak_mb(), False,
                       {k: v for k, v in r.items() if k != "time_s"} | {"clock": "wall"}))
    return out


HEAD = (f"{'model':22s} {'HB peak':>12s} {'at omega':>10s} {'H':>3s} {'TI peak':>12s} {'at omega':>10s} "
        f"{'HB/TI-1':>9s} {'HB err':>8s} {'TI err':>8s} {'states':>9s}  note")


def _pct(v, fmt=".2g", sign="+") -> str:
    return "-" if v is None else f"{100 * v:{sign}{fmt}}%"


def line(r: dict) -> str:
    """One text line of a row (dict of :func:`model_row` or the Row's as_dict)."""
    flag = {None: "-", True: "DIFFERENT", False: "same"}[r.get("states_differ")]
    note = "HB and TI differ beyond their errors" if r.get("beyond_errors") else ""
    return (f"{r['model']:22s} {r['hb_peak']:12.6g} {r['hb_omega']:10.6g} {r.get('hb_H') or '-':>3} "
            f"{'-' if r.get('ti_peak') is None else format(r['ti_peak'], '12.6g'):>12s} "
            f"{'-' if r.get('ti_omega') is None else format(r['ti_omega'], '10.6g'):>10s} "
            f"{_pct(r.get('difference')):>9s} {_pct(r.get('hb_error'), '.1g', ''):>8s} "
            f"{_pct(r.get('ti_error'), '.1g', ''):>8s} {flag:>9s}  {note}")


def table_lines(rows: list[dict]) -> list[str]:
    """Header, a line per row and the legend."""
    return [HEAD, *(line(r) for r in rows),
            "HB: first-harmonic peak of the dense high-H reference; TI: time integration from rest at its "
            "frequency +-0.2 % (parabola); states: time integrations at the case's own-H peak from rest and "
            "from the HB state settle at the same (same) or different (DIFFERENT) peaks"]


def markdown(rows: list[dict]) -> list[str]:
    """Markdown table of the rows."""
    def num(v, fmt):
        return "-" if v is None else format(v, fmt)

    out = ["| model | HB peak | at omega | H | TI peak | at omega | HB/TI - 1 | HB error | TI error | "
           "steady states |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        flag = {None: "-", True: "different", False: "same"}[r.get("states_differ")]
        out.append(f"| {r['model']} | {r['hb_peak']:.6g} | {r['hb_omega']:.6g} | {r.get('hb_H') or '-'} | "
                   f"{num(r.get('ti_peak'), '.6g')} | {num(r.get('ti_omega'), '.6g')} | "
                   f"{_pct(r.get('difference'))} | {_pct(r.get('hb_error'), '.1g', '')} | "
                   f"{_pct(r.get('ti_error'), '.1g', '')} | {flag} |")
    return out
