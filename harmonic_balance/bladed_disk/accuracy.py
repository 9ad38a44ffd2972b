"""Truncation error of the UPD sector's peak, and sector curves to a requested accuracy.

The sector's counterpart of :mod:`..frf_accuracy`, with the same method
(:mod:`..accuracy`): the refined peak (first-harmonic amplitude of the response DOF) and
the curve's solutions around it (:func:`..accuracy.with_peak`) padded to a richer set
0..H' (H' = ceil(1.5 H)), corrected
at their frequencies, and the peak of that short branch refined; the difference of the
two peaks, scaled for the error left at H' with the assumed order, estimates the
truncation error of the computed peak (CHECK_LEVELS).

:func:`peak_to_accuracy` (``damper upd frf --accuracy``) traces the curve once and raises
H at its peak only (:func:`..accuracy.raise_at_peak`, up to PEAK_MAX_HARMONIC).
:func:`frf_to_accuracy` raises H per whole curve: the mistuning study and the load
optimum need one H for whole curves (every ring sample, every load of the sweep).
"""
from __future__ import annotations

import math
import time

import numpy as np

from .. import accuracy as acc
from .. import peak_search
from .hb import SectorHB, sector_basis
from .solve import SolverError, frf

#: Highest harmonic the library goes to for an accuracy (the CLI passes its own limit).
MAX_HARMONIC = 50


def check_sector(hb: SectorHB, H: int) -> SectorHB:
    """The same sector and loads with harmonics 0..H (at least ``hb``'s AFT samples)."""
    n_t = max(hb.basis.n_t, sector_basis(hb.sector, H).n_t)
    return hb.with_harmonics(H, n_t)


#: Richer levels checked at the sector's peak: one (H' ~ 1.5 H). The sector's peak
#: converges regularly (estimate / true error 0.9-2.4 measured on UPD-24 at CF 60, 120,
#: 600 N with one check), and a second check at ~2.25 H would cost more than the curve.
CHECK_LEVELS = 1


def truncation_error(hb: SectorHB, curve, limit: int = MAX_HARMONIC, levels: int = CHECK_LEVELS) -> dict:
    """The ``truncation_error`` record (:func:`..accuracy.estimate`) of ``curve``'s peak
    (computed by :func:`.solve.frf` with ``hb``), checked at up to ``levels`` richer sets.
    A check that fails, or no richer set within ``limit``, gives null estimates and a
    ``note``."""
    t0 = time.perf_counter()
    base = {"method": "richer harmonic sets at the peak", "H_used": hb.H}
    amp = np.asarray(curve.amplitude)
    i = int(np.argmax(amp))
    if not 0 < i < amp.size - 1:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": "the peak is at the band's end"}
    checks, hs = [], hb.basis.harmonics
    pts, om, i = acc.with_peak(curve.x, curve.omega, i, curve.peak_x, curve.peak_omega)
    for k in range(levels):
        nxt = acc.richer(hs, limit=limit)
        if nxt == hs:
            break
        hs = nxt
        rich = check_sector(hb, hs[-1])
        xs = [acc.pad(x, hb.basis, rich.basis) for x in pts]
        try:
            _, wc, ac, _ = peak_search.peak_at(rich.__call__, lambda x, w, r=rich: r.amplitude_h1(x), xs,
                                               om, i, 1e-10 * max(hb.f0, hb.cf), 1e-6 * curve.peak_omega)
        except RuntimeError as err:
            if k == 0:
                return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                        "note": f"check failed: {err}"}
            break
        checks.append((hs[-1], ac, wc))
    if not checks:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": f"no richer harmonic set within the limit H <= {limit}"}
    out = acc.estimate([(hb.H, curve.peak_amplitude, curve.peak_omega)] + checks, base["method"])
    out["time_s"] = time.perf_counter() - t0
    return out


def frf_to_accuracy(sector, omegas, accuracy: float, H: int = 7, limit: int = MAX_HARMONIC,
                    cf=None, f0=None, mu=None):
    """(hb, curve, record) of the sector curve over ``omegas`` [rad/s] whose peak's
    estimated truncation error is below ``accuracy`` (relative), raising H per curve from
    ``H`` as :func:`..frf_accuracy.frf_to_accuracy` does; the record carries
    ``accuracy`` (target, met, H_sequence, levels, message).

    Raises
    ------
    ValueError (bad accuracy); the first curve's StartError / SolverError.
    """
    tol = acc.check_accuracy(accuracy)
    H = max(int(H), acc.MIN_START_HARMONIC)   # from H = 1 the check is not yet in its steady range
    top = limit
    while top > H and acc.richer(tuple(range(top + 1)))[-1] > limit:
        top -= 1
    levels, seq, best = [], [], None
    while True:
        hb = SectorHB(sector, H, cf=cf, f0=f0, mu=mu)
        try:
            curve = frf(hb, omegas)
        except SolverError as err:
            if best is None:
                raise
            best[2]["note_failed"] = f"the curve at H = {H} failed ({err}); H = {best[0].H} kept"
            break
        rec = truncation_error(hb, curve, limit)
        best = (hb, curve, rec)
        seq.append(H)
        levels.append((H, curve.peak_amplitude, curve.peak_omega))
        levels += [(c["H"], c["peak_amplitude"], c["peak_omega"]) for c in rec.get("checks", ())]
        e = rec.get("peak_amplitude_rel")
        if e is not None and e <= tol:
            break
        if e is None or H >= top:
            why = rec.get("note") or f"H = {H} is the highest whose check fits the limit H <= {limit}"
            rec["message"] = (f"accuracy {tol:g} not reached: {why}; the estimate is "
                              f"{'unknown' if e is None else f'{100 * e:.3g} %'} at H = {H}")
            break
        want = min(H * (e / tol) ** (1.0 / (rec.get("order") or acc.ASSUMED_ORDER)) * acc.H_MARGIN,
                   acc.RAISE_MAX * H)
        H = min(max(int(math.ceil(want)), rec["checks"][0]["H"]), top)
    hb, curve, rec = best
    e = rec.get("peak_amplitude_rel")
    rec["accuracy"] = {"target": tol, "met": e is not None and e <= tol, "H_sequence": seq,
                       "levels": [list(lv) for lv in levels], "message": rec.get("message")}
    return best


#: Highest harmonic of the peak-local levels of :func:`peak_to_accuracy`: above the
#: curves' limit (MAX_HARMONIC) because a level is a few dozen solves at the peak, not a
#: curve of 200 points. Its unknowns are (2H + 1) times the sector's DOFs; the dense
#: Jacobian at H = 80 holds ~10 MB on UPD-24 (7 DOFs, 1127 unknowns).
PEAK_MAX_HARMONIC = 80
#: The ``method`` of a sector peak raised to an accuracy.
PEAK_METHOD = "the curve's peak re-solved at richer harmonic sets (peak-local levels)"


def peak_to_accuracy(sector, omegas, accuracy: float, H: int = 7, limit: int = PEAK_MAX_HARMONIC,
                     cf=None, f0=None, mu=None):
    """(hb, curve, record): the sector curve over ``omegas`` [rad/s] traced once at ``H``
    (at least :data:`..accuracy.MIN_START_HARMONIC`), then its peak only raised in H
    (:func:`..accuracy.raise_at_peak`, up to ``limit``) until the richest level's
    estimated truncation error is below ``accuracy`` (relative).

    ``hb`` and ``curve`` are the curve's (its H); ``record`` is the richest level's
    ``truncation_error`` (:func:`..accuracy.peak_records`) carrying ``accuracy``: target,
    met, H_curve, H_peak, peak_amplitude [m] and peak_omega [rad/s] at H_peak, levels,
    extrapolated, message; ``time_s`` of the levels.

    Raises
    ------
    ValueError (bad accuracy); the curve's StartError / SolverError.
    """
    tol = acc.check_accuracy(accuracy)
    hb = SectorHB(sector, max(int(H), acc.MIN_START_HARMONIC), cf=cf, f0=f0, mu=mu)
    curve = frf(hb, omegas)
    t0 = time.perf_counter()
    amp = np.asarray(curve.amplitude)
    i = int(np.argmax(amp))
    level0 = (hb.H, curve.peak_amplitude, curve.peak_omega)
    if 0 < i < amp.size - 1:
        def problem_at(hs):
            rich = check_sector(hb, hs[-1])
            return (rich, lambda x, w, r=rich: r.amplitude_h1(x),   # rich itself: its value() too
                    1e-10 * max(hb.f0, hb.cf), rich.basis)
        pts, om, i = acc.with_peak(curve.x, curve.omega, i, curve.peak_x, curve.peak_omega)
        run = acc.raise_at_peak(problem_at, hb.basis, pts, om, i, level0, tol, limit, 1e-6 * curve.peak_omega)
    else:
        run = {"levels": [level0], "harmonics": hb.basis.harmonics, "x": None, "error": None,
               "met": False, "solves": 0, "message": "the peak is at the band's end (widen the band)"}
    rec, accuracy_record = acc.peak_records(run, tol, hb.H, PEAK_METHOD)
    rec["accuracy"] = accuracy_record
    rec["time_s"] = time.perf_counter() - t0
    return hb, curve, rec


def optimum_truncation(sector, out: dict, grid: int = 40, limit: int = MAX_HARMONIC, f0=None) -> dict:
    """The ``truncation_error`` record of the peak at the optimum CF of ``out`` (a result of
    :func:`.optimize.optimal_load` at its ``harmonics``): the optimum's curve on the
    load band's grid of ``grid`` points, checked as :func:`truncation_error` does;
    ``at`` = "the optimum CF". A curve that fails gives null estimates and a ``note``."""
    lo, hi = sector.cfg["load.band_hz"]
    hb = SectorHB(sector, out["harmonics"], cf=out["optimum_cf"], f0=f0)
    try:
        c = frf(hb, 2 * np.pi * np.linspace(lo, hi, grid))
    except SolverError as err:
        return {"method": "richer harmonic sets at the peak", "H_used": hb.H, "at": "the optimum CF",
                "peak_amplitude_rel": None, "peak_frequency_rel": None, "note": f"check failed: {err}"}
    rec = truncation_error(hb, c, limit)
    rec["at"] = "the optimum CF"
    return rec


def optimal_load_to_accuracy(sector, cf_range, accuracy: float, points: int = 20, H: int = 7,
                             grid: int = 40, workers: int = 1, limit: int = MAX_HARMONIC,
                             f0=None) -> dict:
    """Optimal-load curve (:func:`.optimize.optimal_load`) whose optimum's peak has an
    estimated truncation error below ``accuracy`` (relative).

    The load sweep runs at ``H``; the curve at its optimum CF is raised to the accuracy by
    :func:`frf_to_accuracy` (from ``H``), which chooses H_acc. When H_acc > H the sweep runs
    again at H_acc (the optimum CF moves with H: the minimum is flat) and the new
    optimum's peak is checked at H_acc. Costs one sweep when ``H`` already meets the
    accuracy, two sweeps and a few sector curves otherwise.

    Returns
    -------
    dict of :func:`.optimize.optimal_load` at the H used (``harmonics``), with
    ``truncation_error`` (the optimum's record, ``at`` = "the optimum CF") carrying
    ``accuracy``: target, met, sweep_harmonics (H of each sweep), H_sequence and levels
    (the curves that chose H_acc at the first optimum), message (why not met, or None).

    Raises
    ------
    ValueError (bad accuracy or range); SolverError when the first optimum's curve fails.
    """
    from .optimize import optimal_load

    tol = acc.check_accuracy(accuracy)
    H = max(int(H), acc.MIN_START_HARMONIC)   # as frf_to_accuracy: the sweep starts there too
    lo, hi = sector.cfg["load.band_hz"]
    omegas = 2 * np.pi * np.linspace(lo, hi, grid)
    out = optimal_load(sector, cf_range, points, H, grid=grid, f0=f0, workers=workers)
    _, _, rec = frf_to_accuracy(sector, omegas, tol, H, limit, cf=out["optimum_cf"], f0=f0)
    chosen, sweeps = rec["accuracy"], [H]
    if rec["H_used"] != H:
        sweeps.append(rec["H_used"])
        out = optimal_load(sector, cf_range, points, rec["H_used"], grid=grid, f0=f0, workers=workers)
        hb = SectorHB(sector, rec["H_used"], cf=out["optimum_cf"], f0=f0)
        rec = truncation_error(hb, frf(hb, omegas), limit)
    e = rec.get("peak_amplitude_rel")
    met = e is not None and e <= tol
    message = chosen["message"]
    if message is None and not met:  # the optimum moved with H, and its peak converges slower there
        message = (f"accuracy {tol:g} not reached at the new optimum: the estimate is "
                   f"{'unknown' if e is None else f'{100 * e:.3g} %'} at H = {rec['H_used']}")
    rec["at"] = "the optimum CF"
    rec["accuracy"] = {"target": tol, "met": met, "sweep_harmonics": sweeps,
                       "H_sequence": chosen["H_sequence"], "levels": chosen["levels"],
                       "message": message}
    out["truncation_error"] = rec
    return out
