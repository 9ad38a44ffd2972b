"""Truncation error of a backbone (:mod:`.epmc`): a few points re-solved with more harmonics.

Method (docs/method/accuracy.md, as for a forced response's peak, :mod:`harmonic_balance.accuracy`): at
CHECK_POINTS modal amplitudes of the backbone (the largest damping ratio, where the
contacts slip most, the middle of the range in log a and its end) the point's unknowns
(X~, omega, xi) are padded with zeros to the richer set H' (:func:`harmonic_balance.accuracy.richer`,
about 1.5 H) and corrected by Newton at the same amplitude a. The differences of omega
and of the damping ratio D, scaled for the error left at H' with the assumed order p
(:data:`harmonic_balance.accuracy.ASSUMED_ORDER`), estimate the relative truncation error at H::

    e_H = |v_H - v_H'| / |v_H'| / (1 - (H / H')^p),   v = omega or D.

A few Newton solves at H', no second backbone. :func:`backbone_to_accuracy` raises H
per backbone until the larger of the two estimates is below a requested accuracy, as
:func:`.frf_accuracy.frf_to_accuracy` does for a forced response.
"""
from __future__ import annotations

import math
import time

import numpy as np

from . import accuracy as acc
from .epmc import TOL, Backbone, EPMCError, EPMCProblem, compute_backbone
from .fourier import FourierBasis, parse_harmonics
from .frf_accuracy import H_MARGIN, RAISE_MAX, _curve_limit, _harmonic_set, accuracy_lines
from .model import Model
from .newton import NewtonError, newton

#: Backbone points re-solved: the largest damping ratio, the middle (in log a), the end.
CHECK_POINTS = 3
#: Highest harmonic of a check (the CLI passes its own limit).
MAX_HARMONIC = 200
METHOD = "richer harmonic set at sampled modal amplitudes (EPMC re-solved)"


def check_indices(bb: Backbone, count: int = CHECK_POINTS) -> list[int]:
    """Indices of the points to re-solve (sorted, distinct, never the linear start)."""
    n = bb.a.size
    d = np.nan_to_num(np.asarray(bb.damping_ratio, float), nan=-np.inf)
    z = np.log10(bb.a)
    mid = int(np.argmin(np.abs(z - 0.5 * (z[0] + z[-1]))))
    return sorted({int(np.argmax(d)), mid, n - 1} - {0})[:count] if n > 1 else []


def _rel(v, vc, H, Hc):
    if not (np.isfinite(v) and np.isfinite(vc)) or vc == 0:
        return None
    return abs(v - vc) / abs(vc) / (1.0 - (H / Hc) ** acc.ASSUMED_ORDER)


def truncation_error(model: Model, harmonics, bb: Backbone, n_t: int = 0, mode: int = 0,
                     limit: int = MAX_HARMONIC) -> dict:
    """The backbone's ``truncation_error`` record (module docstring).

    Returns
    -------
    dict: method, H_used, H_check, order (assumed), omega_rel and damping_ratio_rel (the
    largest over the points, or None), points (modal_amplitude, omega, omega_check,
    damping_ratio, damping_ratio_check, omega_rel, damping_ratio_rel per point), time_s;
    with a ``note`` instead of estimates when no check could run.
    """
    t0 = time.perf_counter()
    prob = EPMCProblem(model, harmonics, n_t, mode)
    hs, H = prob.basis.harmonics, prob.basis.harmonics[-1]
    base = {"method": METHOD, "H_used": int(H), "order": acc.ASSUMED_ORDER}
    rich_hs = acc.richer(hs, limit=limit)
    idx = check_indices(bb) if bb.y is not None else []
    if rich_hs == hs or not idx:
        why = (f"no richer harmonic set within the limit H <= {limit}" if rich_hs == hs
               else "the backbone has no point past its start")
        return {**base, "omega_rel": None, "damping_ratio_rel": None, "note": why}
    rich = EPMCProblem(model, rich_hs, max(n_t, FourierBasis(rich_hs).n_t), mode)
    Hc, points = rich_hs[-1], []
    for i in idx:
        y = bb.y[i]
        y0 = np.concatenate([acc.pad(y[:-2], prob.basis, rich.basis), y[-2:]])
        lam = float(np.log10(bb.a[i]))
        try:
            yc = newton(lambda v, lam=lam: rich(v, lam)[:2], y0, TOL, 40).x
        except NewtonError:
            continue
        wc, dc = float(yc[-2]), float(yc[-1] / (2.0 * yc[-2]))
        w, d = float(bb.omega[i]), float(bb.damping_ratio[i])
        points.append({"modal_amplitude": float(bb.a[i]), "omega": w, "omega_check": wc,
                       "damping_ratio": d, "damping_ratio_check": dc,
                       "omega_rel": _rel(w, wc, H, Hc), "damping_ratio_rel": _rel(d, dc, H, Hc)})
    out = {**base, "H_check": int(Hc), "points": points, "time_s": time.perf_counter() - t0}
    for k in ("omega_rel", "damping_ratio_rel"):
        vals = [p[k] for p in points if p[k] is not None]
        out[k] = max(vals) if vals else None
    if not points:
        out["note"] = "the richer harmonic set's Newton failed at every point checked"
    return out


def warning(record: dict | None, limit: float = acc.WARN_REL) -> str | None:
    """One line when the estimated error of omega or of the damping ratio exceeds ``limit``."""
    if not record:
        return None
    worst = max((record.get(k) or 0.0, k) for k in ("omega_rel", "damping_ratio_rel"))
    if worst[0] <= limit:
        return None
    what = "frequency" if worst[1] == "omega_rel" else "damping ratio"
    return (f"warning: estimated truncation error of the backbone's {what} {100 * worst[0]:.2g} % "
            f"(H = {record['H_used']}, checked at H = {record['H_check']}) exceeds "
            f"{100 * limit:g} %: raise the harmonics")


def summary_lines(record: dict | None) -> list[str]:
    """Text lines of the record and its warning."""
    if not record:
        return []
    if record.get("omega_rel") is None and record.get("damping_ratio_rel") is None:
        return [f"truncation error: not estimated ({record.get('note', 'no check')})"]

    def pct(v):
        return "unknown" if v is None else f"{100 * v:.2g} %"
    lines = [f"truncation error (estimate, H = {record['H_used']} checked at H = {record['H_check']} "
             f"at {len(record['points'])} amplitudes, order {record['order']:.2g} assumed): "
             f"frequency {pct(record['omega_rel'])}, damping ratio {pct(record['damping_ratio_rel'])}"]
    a = record.get("accuracy")
    lines += accuracy_lines(a)
    w = warning(record)
    return lines + ([w] if w and not (a and a["met"]) else [])


def _worst(rec: dict):
    vals = [rec.get(k) for k in ("omega_rel", "damping_ratio_rel") if rec.get(k) is not None]
    return max(vals) if vals else None


def backbone_to_accuracy(model: Model, harmonics, a_range, accuracy: float, n_t: int = 0,
                         mode: int = 0, limit: int = MAX_HARMONIC) -> tuple[Backbone, dict]:
    """(backbone, record) whose larger estimate (omega or damping ratio) is below
    ``accuracy`` (relative), raising H per backbone from ``harmonics`` (its kind kept):
    H_next = H (e / accuracy)^(1/p) H_MARGIN, at most RAISE_MAX H, at least the check's
    H, at most the highest H whose check fits within ``limit``. The record carries
    ``accuracy``: target, met, H_sequence, message (why not met, or None).

    Raises
    ------
    ValueError (bad accuracy); EPMCError when the first backbone stops early (a later one
    that does ends the run with the previous backbone and a message).
    """
    tol = acc.check_accuracy(accuracy)
    hs = parse_harmonics(harmonics)
    if hs[-1] < acc.MIN_START_HARMONIC:   # the check from H = 1 is not yet in its steady range
        hs = _harmonic_set(acc.MIN_START_HARMONIC, all(h % 2 for h in hs), 0 in hs)
    odd, top, seq, best, message = all(h % 2 for h in hs), _curve_limit(hs, limit), [], None, None
    while True:
        try:
            bb = compute_backbone(model, hs, a_range, n_t=n_t, mode=mode)
        except EPMCError as err:
            if best is None:
                raise
            message = f"the backbone at H = {hs[-1]} stopped ({err}); H = {seq[-1]} kept"
            break
        rec = truncation_error(model, hs, bb, n_t, mode, limit)
        best = (bb, rec)
        seq.append(hs[-1])
        e = _worst(rec)
        if e is not None and e <= tol:
            break
        if e is None or hs[-1] >= top:
            why = rec.get("note") or f"H = {hs[-1]} is the highest whose check fits the limit H <= {limit}"
            message = (f"accuracy {tol:g} not reached: {why}; the estimate is "
                       f"{'unknown' if e is None else f'{100 * e:.3g} %'} at H = {hs[-1]}")
            break
        want = min(hs[-1] * (e / tol) ** (1.0 / acc.ASSUMED_ORDER) * H_MARGIN, RAISE_MAX * hs[-1])
        hs = _harmonic_set(min(max(int(math.ceil(want)), rec["H_check"]), top), odd, 0 in hs)
    bb, rec = best
    e = _worst(rec)
    rec["accuracy"] = {"target": tol, "met": e is not None and e <= tol, "H_sequence": seq,
                       "message": message}
    return bb, rec
