"""Truncation error of the UPD sector's peak, and sector curves to a requested accuracy.

The sector's counterpart of :mod:`..frf_accuracy`, with the same method
(:mod:`..accuracy`): the curve's solutions near the refined peak (first-harmonic
amplitude of the response DOF) padded to a richer set 0..H' (H' = ceil(1.5 H)), corrected
at their frequencies, and the peak of that short branch refined; the difference of the
two peaks, scaled for the error left at H', estimates the truncation error of the
computed peak.
"""
from __future__ import annotations

import math
import time

import numpy as np

from .. import accuracy as acc
from .hb import SectorHB, sector_basis
from .solve import SolverError, frf

#: Highest harmonic the library goes to for an accuracy (the CLI passes its own limit).
MAX_HARMONIC = 50
#: Margin on the H predicted to meet a tolerance (the order is an estimate).
H_MARGIN = 1.15


def check_sector(hb: SectorHB, H: int) -> SectorHB:
    """The same sector and loads with harmonics 0..H (at least ``hb``'s AFT samples)."""
    n_t = max(hb.basis.n_t, sector_basis(hb.sector, H).n_t)
    return SectorHB(hb.sector, H, cf=hb.cf, f0=hb.f0, mu=hb.mu, n_t=n_t)


def truncation_error(hb: SectorHB, curve, limit: int = MAX_HARMONIC, levels=()) -> dict:
    """The ``truncation_error`` record (:func:`..accuracy.estimate`) of ``curve``'s peak
    (computed by :func:`.solve.frf` with ``hb``); ``levels``: earlier (H, peak amplitude,
    peak omega) of the same curve at fewer harmonics. A check that fails, or no richer set
    within ``limit``, gives null estimates and a ``note``."""
    t0 = time.perf_counter()
    base = {"method": "richer harmonic set at the peak", "H_used": hb.H}
    hs = acc.richer(hb.basis.harmonics, limit=limit)
    if hs == hb.basis.harmonics:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": f"no richer harmonic set within the limit H <= {limit}"}
    rich = check_sector(hb, hs[-1])
    amp = np.asarray(curve.amplitude)
    i = int(np.argmax(amp))
    if not 0 < i < amp.size - 1:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": "the peak is at the band's end"}
    xs = [acc.pad(x, hb.basis, rich.basis) for x in curve.x]
    tol = 1e-10 * max(hb.f0, hb.cf)
    try:
        _, wc, ac, _ = acc.peak_at(rich.__call__, lambda x, w: rich.amplitude_h1(x), xs,
                                   np.asarray(curve.omega), i, tol, 1e-6 * curve.peak_omega)
    except RuntimeError as err:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": f"check failed: {err}"}
    own = [lv for lv in levels if lv[0] < hb.H] + [(hb.H, curve.peak_amplitude, curve.peak_omega),
                                                   (hs[-1], ac, wc)]
    out = acc.estimate(own, base["method"])
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
        rec = truncation_error(hb, curve, limit, levels)
        best = (hb, curve, rec)
        seq.append(H)
        levels = [lv for lv in levels if lv[0] < H] + [(H, curve.peak_amplitude, curve.peak_omega)]
        e = rec.get("peak_amplitude_rel")
        if e is not None and e <= tol:
            break
        if e is None or H >= top:
            why = rec.get("note") or f"H = {H} is the highest whose check fits the limit H <= {limit}"
            rec["message"] = (f"accuracy {tol:g} not reached: {why}; the estimate is "
                              f"{'unknown' if e is None else f'{100 * e:.3g} %'} at H = {H}")
            break
        want = H * (e / tol) ** (1.0 / (rec.get("order") or acc.ASSUMED_ORDER)) * H_MARGIN
        H = min(max(int(math.ceil(want)), rec["H_check"]), top)
    hb, curve, rec = best
    e = rec.get("peak_amplitude_rel")
    rec["accuracy"] = {"target": tol, "met": e is not None and e <= tol, "H_sequence": seq,
                       "levels": [list(lv) for lv in levels], "message": rec.get("message")}
    return best
