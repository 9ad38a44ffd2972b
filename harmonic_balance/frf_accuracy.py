"""Truncation error of a forced-response curve's peak, and curves to a requested accuracy.

:func:`truncation_error` estimates the error in H of a :class:`frf.FRFResult`'s peak
amplitude and frequency by :mod:`accuracy`'s check at a richer harmonic set;
:func:`frf_to_accuracy` traces the curve once and raises H at its peak only
(:func:`accuracy.raise_at_peak`) until the richest level's estimate is below a relative
tolerance on the peak amplitude.
"""
from __future__ import annotations

import math

import numpy as np

from . import accuracy as acc
from . import peak_search
from .fourier import default_samples, parse_harmonics

#: Highest harmonic the library goes to when raising H for an accuracy (the CLI passes
#: its own limit): ~H^2 time per curve point.
MAX_HARMONIC = 200
#: Margin and largest factor on H (one definition, :mod:`accuracy`; the backbone's and the
#: sector's runs use them too).
H_MARGIN, RAISE_MAX = acc.H_MARGIN, acc.RAISE_MAX


def check_problem(prob, harmonics):
    """The FRFProblem of ``prob``'s model at the richer ``harmonics`` (same residual kind,
    at least the curve's AFT samples)."""
    from .residual import CondensedResidual

    n_t = max(prob.basis.n_t, default_samples(max(harmonics)))
    # the problem's own class (frf.FRFProblem): this module sits above frf, not beside it
    return type(prob)(prob.model, harmonics, n_t, isinstance(prob.residual, CondensedResidual))


#: Richer levels checked at the peak (H' and H'' = richer(H')): three levels give the
#: observed order; on the 5-mass chain (order ~1) a single check with the assumed order
#: underestimates the error 3-7 times, while the second check costs ~2-3 times the first,
#: 5-30 % of the curve (docs/method/accuracy.md).
CHECK_LEVELS = 2


def check_peak(result, limit: int = MAX_HARMONIC, levels: int = CHECK_LEVELS, *, tol_rel: float) -> list:
    """[(H', amplitude, omega), ...] of ``result``'s peak re-solved at up to ``levels``
    successively richer sets (:func:`accuracy.richer`, capped at ``limit``; empty when
    the limit leaves no richer set). RuntimeError when the first richer set finds no peak.
    ``tol_rel``: the Newton tolerance relative to the problem's reference size."""
    prob = result.problem
    out, hs = [], prob.basis.harmonics
    om = np.asarray(result.omega)
    i = int(np.argmax(result.amplitude))
    prev = None   # (x, basis) of the last check's peak
    for k in range(levels):
        nxt = acc.richer(hs, limit=limit)
        if nxt == hs:
            break
        hs = nxt
        rich = check_problem(prob, hs)
        tol = tol_rel * max(rich.reference(result.peak_omega), 1e-300)
        try:
            if result.peak_interior:
                x, w, a = _check_at_peak(result, rich, out, prev, i, tol)
            else:  # the maximum is at an end of the band: the amplitude there
                from .newton import newton

                w = float(om[i])
                x = newton(lambda z, r=rich, w=w: r(z, w)[:2], acc.pad(result.solutions[i], prob.basis, rich.basis),
                           tol, 40, factor=rich.factorize).x
                a = rich.amplitude(x, w)
        except RuntimeError:
            if k == 0:
                raise
            break   # the first check stands alone
        prev = (x, rich.basis)
        out.append((hs[-1], float(a), float(w)))
    return out


def _check_at_peak(result, rich, checks, prev, i, tol):
    """(x, omega, amplitude) of ``result``'s peak at the richer problem ``rich``: the first
    check from the curve's points around its peak (:func:`peak_search.peak_at`), a later one
    from the previous check's peak (:func:`peak_search.near_peak`: measured on the 5-mass
    chain at H = 31, the check at H'' = 71 in 7 solves instead of 13), the curve's points
    again when that finds no peak."""
    om = np.asarray(result.omega)
    tol_lam = 1e-6 * abs(om[i])
    if prev is not None:
        levels = [(result.problem.basis.H, result.peak_amplitude, result.peak_omega), checks[-1]]
        got = peak_search.near_peak(rich, rich.amplitude, acc.pad(prev[0], prev[1], rich.basis), levels,
                                    tol, tol_lam, 0.0, peak_search.spacing(om, i))
        if got is not None:
            return got[:3]
    xs = [acc.pad(x, result.problem.basis, rich.basis) for x in result.solutions]
    return peak_search.peak_at(rich, rich.amplitude, xs, om, i, tol, tol_lam)[:3]


def truncation_error(result, limit: int = MAX_HARMONIC, levels: int = CHECK_LEVELS, *,
                     tol_rel: float) -> dict:
    """The ``truncation_error`` record (:func:`accuracy.estimate`) of ``result``'s peak,
    checked at up to ``levels`` richer sets. A check that fails or finds no richer set
    within ``limit`` gives a record with null estimates and a ``note`` saying why."""
    import time

    t0 = time.perf_counter()
    H = result.problem.basis.H
    base = {"method": "richer harmonic sets at the peak", "H_used": int(H)}
    if not np.isfinite(result.peak_amplitude):
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": "no peak to check"}
    try:
        checks = check_peak(result, limit, levels, tol_rel=tol_rel)
    except RuntimeError as err:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": f"check failed: {err}"}
    if not checks:
        return {**base, "peak_amplitude_rel": None, "peak_frequency_rel": None,
                "note": f"no richer harmonic set within the limit H <= {limit}"}
    w = result.peak_omega if result.peak_interior else float("nan")
    out = acc.estimate([(H, result.peak_amplitude, w)] + checks,
                       base["method"] + ("" if result.peak_interior else " (band end: amplitude only)"))
    out["time_s"] = time.perf_counter() - t0
    return out


def frf_to_accuracy(curve, model, accuracy: float, omega_range, harmonics="3",
                    limit: int = MAX_HARMONIC, *, tol_rel: float, **kwargs):
    """Forced-response curve traced once, its peak raised in H until the peak amplitude's
    estimated truncation error is below ``accuracy`` (relative).

    The curve is traced at ``harmonics`` (its kind, odd or all, is kept; at least
    :data:`accuracy.MIN_START_HARMONIC`); then only its peak is re-solved at richer
    harmonic sets (:func:`accuracy.raise_at_peak`: the padded curve points around the
    peak corrected at each level and the peak refined, a few dozen solves per level, up to
    H = ``limit``), level after level, until the richest level's estimate
    (:func:`accuracy.richest_error`) is below ``accuracy``.
    ``curve(model, harmonics, omega_range, truncation_check=False, **kwargs)`` traces the
    curve (:func:`frf.compute_frf`, which passes itself: this module sits above frf);
    other keyword arguments go to it.

    Returns
    -------
    FRFResult of the curve (its ``harmonics``, ``solutions``, ``problem`` and
    ``peak_solution`` at the curve's H), with ``peak_amplitude``, ``peak_omega`` and
    ``peak_amplitude_h1`` those of the richest level; ``time_s`` and ``evaluations`` of
    the whole run; ``truncation_error`` the richest level's estimate
    (:func:`accuracy.peak_records`); ``extra["accuracy"]``: target, met, H_curve,
    H_peak, peak_amplitude, peak_omega, levels, extrapolated, message;
    ``extra["peak_problem"]`` and ``extra["peak_level_solution"]`` the richest level's
    problem and peak solution.

    Raises
    ------
    ValueError (bad accuracy), frf.FRFError (a RuntimeError) when the first curve fails.
    When the first level finds no peak from the padded curve, the curve is traced again
    at that level's set (up to CURVE_RETRIES times; ``H_curve`` says which).
    """
    import time

    tol = acc.check_accuracy(accuracy)
    hs = parse_harmonics(harmonics)
    if hs[-1] < acc.MIN_START_HARMONIC:
        hs = _harmonic_set(acc.MIN_START_HARMONIC, all(h % 2 for h in hs), 0 in hs)
    t0, evaluations, res = time.perf_counter(), 0, None
    for _ in range(CURVE_RETRIES + 1):
        try:
            new = curve(model, hs, omega_range, truncation_check=False, **kwargs)
        except RuntimeError:
            if res is None:
                raise
            break   # a retried curve that fails: the previous one and its message stand
        res = new
        evaluations += res.evaluations
        t_levels = time.perf_counter()
        run, riches = _levels(res, tol, limit, tol_rel)
        evaluations += sum(r.evaluations for r in riches)
        nxt = acc.richer(hs, limit=limit)
        if len(run["levels"]) > 1 or not res.peak_interior or nxt == hs:
            break
        # the first level found no peak from the padded curve (the 3-mass chain at
        # F = 0.5 N from H = 3): the curve again at that richer set, closer to its peaks
        hs = nxt
    H0 = res.problem.basis.H
    rec, a = acc.peak_records(run, tol, H0, PEAK_METHOD)
    rec["time_s"] = time.perf_counter() - t_levels
    _report_peak(res, run, rec, a, riches)
    res.evaluations = evaluations
    res.time_s = time.perf_counter() - t0   # the curves and every level at the peak
    return res


#: Curves traced again at the next richer set when the first peak level finds no peak
#: from the padded curve.
CURVE_RETRIES = 2


def _levels(res, tol: float, limit: int, tol_rel: float):
    """(:func:`accuracy.raise_at_peak` run, the level problems) of the curve ``res``."""
    prob, riches = res.problem, []

    def problem_at(h):
        rich = check_problem(prob, h)
        riches.append(rich)
        return rich, rich.amplitude, tol_rel * max(rich.reference(res.peak_omega), 1e-300), rich.basis

    level0 = (prob.basis.H, res.peak_amplitude, res.peak_omega)
    if not (res.peak_interior and np.isfinite(res.peak_amplitude)):   # a maximum at the band's end
        return {"levels": [level0], "harmonics": prob.basis.harmonics, "x": None, "error": None,
                "met": False, "solves": 0, "message": "the maximum is at an end of the band (widen the band)"}, riches
    return acc.raise_at_peak(problem_at, prob.basis, res.solutions, np.asarray(res.omega),
                             int(np.argmax(res.amplitude)), level0, tol, limit,
                             1e-6 * abs(res.peak_omega)), riches


def _report_peak(res, run, rec, a, riches) -> None:
    """``res`` (in place) with the richest level's peak and the run's records."""
    if run["x"] is not None:
        rich = next((r for r in reversed(riches) if r.basis.harmonics == run["harmonics"]), None) \
            or check_problem(res.problem, run["harmonics"])
        res.peak_amplitude, res.peak_omega = a["peak_amplitude"], a["peak_omega"]
        r = rich.response(run["x"], res.peak_omega)
        res.peak_amplitude_h1 = float(rich.basis.magnitude(r, 1)) if 1 in rich.basis.harmonics else float("nan")
        res.extra["peak_problem"], res.extra["peak_level_solution"] = rich, run["x"]
    res.truncation_error = rec
    res.extra["truncation_warning"] = None if a["met"] else acc.warning(rec)
    res.extra["accuracy"] = a


#: The ``method`` of a peak raised to an accuracy.
PEAK_METHOD = "the curve's peak re-solved at richer harmonic sets (peak-local levels)"


def _pct(e) -> str:
    return "unknown" if e is None else f"{100 * e:.3g} %"


def _harmonic_set(H: int, odd: bool, zero: bool) -> tuple:
    if odd:
        return tuple(range(1, H + 1 + (H % 2 == 0), 2))
    return tuple(range(0 if zero else 1, H + 1))


def _curve_limit(hs, limit: int) -> int:
    """Highest H of a curve whose richer check set still fits within ``limit``."""
    odd = all(h % 2 for h in hs)
    H = limit
    while H > hs[-1] and acc.richer(_harmonic_set(H, odd, 0 in hs), limit=None)[-1] > limit:
        H -= 1
    return max(H, hs[-1])


def summary_lines(summary, hz: bool = False) -> list[str]:
    """Text lines of the truncation-error estimate, the accuracy run and its warnings
    (``hz``: frequencies in Hz, else rad/s)."""
    rec = summary.get("truncation_error") or {}
    if not rec:
        return []
    e, ef = rec.get("peak_amplitude_rel"), rec.get("peak_frequency_rel")
    if e is None:
        lines = [f"truncation error: not estimated ({rec.get('note', 'no check')})"]
    elif rec.get("levels"):
        how = ("the levels oscillate: their last difference" if rec.get("oscillating") else
               f"order {rec['order']:.2g}, " + (
                   "observed and stable" if rec.get("order_stable") else "assumed" if rec.get("order_observed") is None
                   else f"the observed one not stable: the lower of it and {acc.ASSUMED_ORDER:g}"))
        lines = [f"truncation error (estimate of the peak at H = {rec['H_used']} from the levels H = "
                 f"{', '.join(str(lv['H']) for lv in rec['levels'])}, {how}): peak amplitude {100 * e:.2g} %"
                 + ("" if ef is None else f", peak frequency {100 * ef:.2g} %")]
    else:
        lines = [f"truncation error (estimate, H = {rec['H_used']} checked at H = {rec['H_check']}, "
                 f"order {rec['order']:.2g}{' observed' if rec.get('order_observed') else ' assumed'}): "
                 f"peak amplitude {100 * e:.2g} %"
                 + ("" if ef is None else f", peak frequency {100 * ef:.2g} %")]
    ex = rec.get("extrapolated")
    if ex:
        w = ex["peak_omega"]
        at = ("" if w is None or not math.isfinite(w) else   # frequency not extrapolated
              f" at {_num(w / (2 * math.pi))} Hz" if hz else f" at omega = {_num(w)} rad/s")
        lines.append(f"extrapolated in H: peak amplitude {_num(ex['peak_amplitude'])} m{at}")
    a = summary.get("accuracy")
    lines += accuracy_lines(a)
    if summary.get("truncation_warning") and not (a and a["met"]):
        lines.append(summary["truncation_warning"])
    return lines


def accuracy_lines(a: dict | None) -> list[str]:
    """Text lines of a run to an accuracy (its ``accuracy`` record: target, met,
    H_sequence, message), for forced responses and backbones alike."""
    if not a:
        return []
    if "H_peak" in a:   # a peak raised to the accuracy
        lines = [f"accuracy {a['target']:g}: {'met' if a['met'] else 'not met'}; curve at H = "
                 f"{a['H_curve']}, peak at H = {a['H_peak']} (levels H = "
                 f"{', '.join(str(lv[0]) for lv in a['levels'])})"]
        return lines + ([f"warning: {a['message']}"] if a.get("message") else [])
    lines = [f"accuracy {a['target']:g}: {'met' if a['met'] else 'not met'}, harmonics "
             f"tried {a['H_sequence']}"]
    return lines + ([f"warning: {a['message']}"] if a.get("message") else [])


def _num(v, fmt=".9g") -> str:
    return "none" if v is None else format(v, fmt)
