"""Truncation error of a forced response's peak: a richer harmonic set at the peak.

Symbols: H the highest retained harmonic of the curve, H' > H that of the check,
a_H and omega_H the refined peak amplitude [m] and frequency [rad/s] with H harmonics,
p the convergence order (|a_H - a_inf| ~ C H^-p).

Method (docs/method/accuracy.md). The curve's solutions near its refined peak are padded
with zeros to a richer harmonic set of the same kind (H' = the next admissible harmonic
at or above RICHER_FACTOR H: odd sets stay odd), corrected at their frequencies by
Newton, and the peak of that short branch is refined (:func:`continuation.refine_max`):
a few dozen solves at H', no curve (the UPD sector's checks also start from the refined
peak itself, :func:`with_peak`: a coarse grid's points can miss a sharp peak). A second
check at H'' (the same rule from H') gives three levels. Where their differences give a
convergence order p in ORDER_RANGE (|a_H - a_inf| ~ C H^-p), the peak is extrapolated
(Richardson 1911; Roache 1998, ch. 5, for the observed order of grid-convergence studies),

    a_inf = a_H'' + (a_H'' - a_H') / ((H'' / H')^p - 1),

and the error of a_H is |a_H - a_inf| / |a_inf|. Otherwise (two levels, or an order out
of range) the error is the largest two-level estimate over the checks with the assumed
order p = ASSUMED_ORDER,

    e_H = |a_H - a_c| / |a_c| / (1 - (H / H_c)^p);

when the three levels oscillate (their differences change sign), the middle one
overshoots the limit and the richest one is the nearest to it: the estimate is then the
two-level one against the richest check alone (measured on the bench: the largest
overestimated 1.5-4 times where the richest check alone gives 0.9-1.4 times the true error).

The same for omega. A friction force has kinks at stick-slip transitions, so its
spectrum falls like h^-2 and the response's truncation error slowly (p ~ 0.5-4 measured
on the bench models and UPD-24): hence checks at 1.5 H and 2.25 H, not H + 2, whose
difference would be too small to tell the error from.

A peak to an accuracy (:func:`raise_at_peak`): the curve is traced once; its peak alone
is re-solved at richer sets, level after level (the first from the curve's points around
its peak, each later one from the previous level's peak, by successive parabolas in
frequency: :func:`near_peak`), and the RICHEST level's error is estimated from the levels below it
(:func:`richest_error`: Richardson with the observed order when two successive triples
agree on it, else with the smaller of it and ASSUMED_ORDER; the last difference itself
when the levels oscillate) until it is below the target with at least MIN_LEVELS levels.

The estimate is of the truncation in H only: the AFT sampling error (exact friction
links have none) and the continuation's tolerance (the peak is refined to 1e-6 in
frequency) are far smaller in the cases measured.
"""
from __future__ import annotations

import math

import numpy as np

from .fourier import FourierBasis
from .peak_search import WINDOW, near_peak, peak_window, spacing

#: The check's highest harmonic is at least this multiple of H (then the next of the set's
#: kind): close enough to cost ~2.5x a point of the curve per solve, far enough that the
#: difference of the two peaks is a fair share of the error left at H.
RICHER_FACTOR = 1.5
#: Convergence order assumed with two levels: the friction response's peak converges like
#: H^-p with p ~ 1.5-2 (kinks in the contact forces); measured in docs/method/accuracy.md.
ASSUMED_ORDER = 1.7
#: Observed orders outside this range are not trusted for extrapolation (the peak's
#: sequence is not yet in its asymptotic range, or changes sign). Low orders occur (the
#: 5-mass chain of the bench, docs/method/accuracy.md).
ORDER_RANGE = (0.3, 6.0)
#: Relative truncation error above which a result carries a warning.
WARN_REL = 1e-2
#: Lowest H a run to an accuracy starts from (a lower ``harmonics`` is raised to it): from
#: H = 1 the check at H' = 3 is not yet in the range where the error falls steadily, and
#: the estimate can say "met" far from it (UPD-24 load optimum: 0.13 % estimated at H = 1,
#: about 8 % against H = 33; the EPMC damping ratio of a Jenkins oscillator: 4x under).
MIN_START_HARMONIC = 3
#: Accuracy targets accepted (relative, on the peak amplitude): below 1e-6 the estimate
#: meets the corrector's and the peak search's own accuracy; above 0.5 it means nothing.
ACCURACY_RANGE = (1e-6, 0.5)


def check_accuracy(tol) -> float:
    """``tol`` as a float inside ACCURACY_RANGE (open interval), else ValueError."""
    lo, hi = ACCURACY_RANGE
    if tol is None or isinstance(tol, bool) or not isinstance(tol, (int, float)) \
            or not math.isfinite(tol) or not lo < tol < hi:
        raise ValueError(f"accuracy must be a relative tolerance in ({lo:g}, {hi:g}), got {tol!r}")
    return float(tol)


def richer(harmonics: tuple, factor: float = RICHER_FACTOR, limit: int | None = None) -> tuple:
    """The harmonic set of the same kind as ``harmonics`` up to the next admissible
    harmonic at or above ``factor`` H (at least H + 2, so that a new odd harmonic enters: the
    even ones vanish on a symmetric friction loop and would check nothing), capped at
    ``limit``: an odd-only set stays odd, a set with 0 keeps 0 and every harmonic.

    Returns the new tuple (equal to ``harmonics`` when the limit leaves no room).
    """
    hs = tuple(harmonics)
    H = hs[-1]
    odd = all(h % 2 for h in hs)
    top = max(int(math.ceil(factor * H - 1e-9)), H + 2)
    if odd and top % 2 == 0:
        top += 1
    if limit is not None:
        top = min(top, limit - (1 if odd and limit % 2 == 0 else 0))
    if top <= H:
        return hs
    extra = range(H + 2, top + 1, 2) if odd else range(H + 1, top + 1)
    return hs + tuple(extra)


def pad(x: np.ndarray, basis: FourierBasis, rich: FourierBasis) -> np.ndarray:
    """Unknowns ``x`` ((n_b, m) row-major, :mod:`fourier`'s ordering) of ``basis`` in the
    richer basis ``rich`` (a superset), the new harmonics zero."""
    X = np.asarray(x).reshape(basis.nb, -1)
    Y = np.zeros((rich.nb, X.shape[1]))
    for h in basis.harmonics:
        (ic, isn), (jc, jsn) = basis.index(h), rich.index(h)
        Y[jc] = X[ic]
        if isn is not None:
            Y[jsn] = X[isn]
    return Y.ravel()


def with_peak(xs, omegas, i: int, x_peak, omega_peak: float):
    """The curve's points with its refined peak inserted in frequency order: (xs, omegas,
    index of the peak), from which a richer set's peak is searched.

    The check must start from the peak it checks: the curve's peak is refined on the
    continuation's branch, while its points lie on the report grid, and on a coarse grid
    a sharp peak falls between them. A search bracketed by grid points alone can then
    stop at the grid's highest point (UPD-24 stuck at CF 1e6 N on a 10-point grid: the
    H = 11 check at 477.78 Hz against the curve's 478.67 Hz, a 56 % "error" where the
    true one is 1e-6). Unchanged when the peak coincides with a grid point or the grid is
    not increasing (a folded branch reported at its own points).

    Parameters
    ----------
    xs : list of (N,) arrays, the curve's solutions at ``omegas`` [rad/s]
    i : int, index of the curve's highest point
    x_peak : (N,) array, the refined peak's solution at ``omega_peak`` [rad/s]
    """
    om = np.asarray(omegas, dtype=float)
    if x_peak is None or not np.isfinite(omega_peak) or not np.all(np.diff(om) > 0) \
            or np.any(om == omega_peak):
        return list(xs), om, i
    k = int(np.searchsorted(om, omega_peak))
    return list(xs[:k]) + [np.asarray(x_peak)] + list(xs[k:]), np.insert(om, k, omega_peak), k


def observed_order(levels) -> float | None:
    """Convergence order p from the last three levels (H, a) of increasing H, solving
    (a0 - a1) / (a1 - a2) = (H0^-p - H1^-p) / (H1^-p - H2^-p) by bisection; None when the
    differences change sign or p falls outside ORDER_RANGE."""
    if len(levels) < 3:
        return None
    (H0, a0), (H1, a1), (H2, a2) = [(lv[0], lv[1]) for lv in levels[-3:]]
    d01, d12 = a0 - a1, a1 - a2
    if d12 == 0 or d01 * d12 <= 0:
        return None
    target = d01 / d12

    def g(p):
        return (H0**-p - H1**-p) / (H1**-p - H2**-p) - target
    lo, hi = ORDER_RANGE
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(lo) * g(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def estimate(levels, method: str) -> dict:
    """The ``truncation_error`` record of a peak computed at several harmonic levels.

    Parameters
    ----------
    levels : list of (H, peak_amplitude, peak_omega), increasing H; levels[0] is the
        result's own (H_used), the others its checks at richer sets
    method : str, how the checks were computed (recorded)

    Returns
    -------
    dict: method, H_used, H_check (the richest check), order (p used), order_observed
    (or None), peak_amplitude_rel, peak_frequency_rel (estimated relative truncation
    error of H_used's peak), checks (H, peak_amplitude, peak_omega of each check),
    extrapolated (peak_amplitude, peak_omega at H -> infinity, or None without an
    observed order).

    With three levels whose differences give an order in ORDER_RANGE the error is
    |a_H - a_inf| / |a_inf| with a_inf extrapolated from the last two levels; with
    oscillating levels the two-level estimate against the richest check; otherwise the
    largest two-level estimate over the checks with ASSUMED_ORDER (module docstring).
    """
    H = levels[0][0]
    e_a, a_inf, p_a = _error([(lv[0], lv[1]) for lv in levels])
    e_w, w_inf, _ = _error([(lv[0], lv[2]) for lv in levels])
    out = {"method": method, "H_used": int(H), "H_check": int(levels[-1][0]),
           "order": ASSUMED_ORDER if p_a is None else p_a, "order_observed": p_a,
           "peak_amplitude_rel": e_a, "peak_frequency_rel": e_w,
           "checks": [{"H": int(h), "peak_amplitude": a, "peak_omega": w} for h, a, w in levels[1:]],
           "extrapolated": None}
    if a_inf is not None:
        out["extrapolated"] = {"peak_amplitude": a_inf, "peak_omega": w_inf}
    return out


def _error(seq):
    """(relative error of seq[0]'s value, extrapolated value or None, observed order or None)
    of a sequence (H, value) of increasing H (:func:`estimate`)."""
    H, v = seq[0]
    if not all(np.isfinite(x) for _, x in seq):
        return None, None, None
    p = observed_order(seq) if len(seq) >= 3 else None
    if p is not None:
        (H1, v1), (H2, v2) = seq[-2], seq[-1]
        v_inf = v2 + (v2 - v1) / ((H2 / H1) ** p - 1.0)
        return abs(v - v_inf) / abs(v_inf), v_inf, p
    checks = seq[1:]
    if len(seq) >= 3 and (seq[-3][1] - seq[-2][1]) * (seq[-2][1] - seq[-1][1]) < 0:
        checks = seq[-1:]   # oscillating levels: the middle one overshoots (module docstring)
    e = max(abs(v - vc) / abs(vc) / (1.0 - (H / Hc) ** ASSUMED_ORDER) for Hc, vc in checks)
    return e, None, None


def warning(record: dict | None, limit: float = WARN_REL) -> str | None:
    """One line warning when the estimated peak error exceeds ``limit``, else None."""
    if not record or record.get("peak_amplitude_rel") is None:
        return None
    e = record["peak_amplitude_rel"]
    if e <= limit:
        return None
    how = ("from the levels below it" if record.get("levels")
           else f"checked at H = {record['H_check']}")
    return (f"warning: estimated truncation error of the peak amplitude {100 * e:.2g} % "
            f"(H = {record['H_used']}, {how}) exceeds "
            f"{100 * limit:g} %: raise the harmonics or ask for an accuracy")


# --- a peak to an accuracy: the curve once, richer harmonic sets at its peak only ---------

#: Margin on the H predicted to meet a tolerance (the order is an estimate).
H_MARGIN = 1.15
#: Largest factor on H from one level to the next: an order below the true one would
#: otherwise overshoot (the 3-mass chain at 1e-3 from H = 3: order ~4, predicted H = 40
#: where 11 suffices).
RAISE_MAX = 2.5
#: Points on each side of the previous level's peak corrected at a level after the first.
LEVEL_WINDOW = 1
#: The peak of a level after the first is refined in frequency until the amplitude error
#: that leaves is this share of the target: far below the differences between levels
#: that the estimate is made of.
LEVEL_PRECISION = 1e-2
#: Smallest factor on H between predicted levels: closer levels differ too little for the
#: order to be told from the corrector's tolerance.
MIN_STEP = 1.25
#: Levels (the curve's H and the peak's richer sets) before a target counts as met: four
#: give two observed orders (their agreement says whether Richardson applies). With three,
#: UPD-24's peak at CF 60 and 600 N looked met at H = 17 (estimates 0.10 % and 0.076 %)
#: while 0.11 % and 0.16 % off: the peak converges irregularly below H ~ 20 (the contacts
#: lift off), and the 5-mass chain below H ~ 50.
MIN_LEVELS = 4


def richest_error(levels) -> dict:
    """Estimated relative truncation error of the RICHEST level's peak.

    Parameters
    ----------
    levels : list of (H, peak_amplitude, peak_omega), increasing H, at least two

    Returns
    -------
    dict: peak_amplitude_rel, peak_frequency_rel (None when a value is not finite),
    order_observed (p from the last three levels, :func:`observed_order`, or None),
    order_stable (the last two triples of levels agree on p within ORDER_STABLE), order
    (p used), oscillating (the last three amplitudes oscillate: no order used),
    extrapolated (peak_amplitude, peak_omega at H -> infinity when the order is stable,
    else None).

    The error of the richest value v_K is Richardson's (Roache 1998, eq. 5.4.1),
    |v_K - v_inf| = |v_K - v_{K-1}| / ((H_K / H_{K-1})^p - 1), with the observed order
    when it is stable; otherwise with the smaller of the last observed order and
    ASSUMED_ORDER (a lower order means a larger error left: a sequence still outside its
    asymptotic range, as the 5-mass chain below H ~ 50, is not trusted to have reached it).
    When the last three levels oscillate (their differences change sign) there is no
    power law to follow: the error is |v_K - v_{K-1}| / |v_K|.
    """
    out = {}
    for key, col in (("amplitude", 1), ("omega", 2)):
        out[key] = _richest([(lv[0], lv[col]) for lv in levels])
    (e_a, a_inf, p, stable), (e_w, w_inf, _, _) = out["amplitude"], out["omega"]
    a = [lv[1] for lv in levels[-3:]]
    return {"peak_amplitude_rel": e_a, "peak_frequency_rel": e_w, "order_observed": p,
            "order_stable": stable, "order": _used_order(p, stable),
            "oscillating": len(a) == 3 and (a[0] - a[1]) * (a[1] - a[2]) < 0,
            "extrapolated": None if a_inf is None else {"peak_amplitude": a_inf, "peak_omega": w_inf}}


#: Two observed orders (of successive triples of levels) are stable when within this
#: factor of each other.
ORDER_STABLE = 1.5


def _used_order(p, stable: bool) -> float:
    if stable:
        return p
    return ASSUMED_ORDER if p is None else min(p, ASSUMED_ORDER)


def _richest(seq):
    """(relative error of the last value, extrapolated value or None, observed order or
    None, order stable) of a sequence (H, value) of increasing H (:func:`richest_error`)."""
    if len(seq) < 2 or not all(np.isfinite(v) for _, v in seq):
        return None, None, None, False
    p = observed_order(seq[-3:]) if len(seq) >= 3 else None
    p0 = observed_order(seq[-4:-1]) if len(seq) >= 4 else None
    stable = p is not None and p0 is not None and max(p, p0) <= ORDER_STABLE * min(p, p0)
    (H1, v1), (H2, v2) = seq[-2], seq[-1]
    if len(seq) >= 3 and (seq[-3][1] - v1) * (v1 - v2) < 0:
        # oscillating levels: no power law; the limit lies between the last two, at most
        # their difference from the richest
        return abs(v2 - v1) / abs(v2), None, p, False
    d = (v2 - v1) / ((H2 / H1) ** _used_order(p, stable) - 1.0)
    return abs(d) / abs(v2 + d), (v2 + d if stable else None), p, stable


def next_level(hs: tuple, levels, error, tol: float, limit: int) -> tuple | None:
    """The harmonic set of the next peak level after ``hs`` (the richest so far), or None
    when ``limit`` leaves no richer set.

    Until MIN_LEVELS levels exist (or without an estimate): :func:`richer` (~1.5 H). Then
    the H predicted to meet ``tol``, H_K (e_K / tol)^(1/p) H_MARGIN, kept within
    [MIN_STEP H_K, RAISE_MAX H_K] (``error``: the :func:`richest_error` record).
    """
    e = None if error is None else error["peak_amplitude_rel"]
    if len(levels) < MIN_LEVELS or not e:
        nxt = richer(hs, limit=limit)
    else:
        want = (e / tol) ** (1.0 / error["order"]) * H_MARGIN
        nxt = richer(hs, min(max(want, MIN_STEP), RAISE_MAX), limit)
    return None if nxt == tuple(hs) else nxt


def raise_at_peak(problem_at, basis, xs, omegas, i, level0, tol: float, limit: int, tol_lam: float) -> dict:
    """The peak of a curve re-solved at successively richer harmonic sets, on a short
    branch around it only, until the richest level's estimated error is below ``tol``.

    Parameters
    ----------
    problem_at : callable (harmonics tuple) -> (fun, amplitude, newton_tol, basis) of the
        same model at that set (``fun(x, omega) -> (R, dR/dx, dR/domega)``,
        ``amplitude(x, omega) -> float``)
    basis : FourierBasis of the curve
    xs : list of (N,) arrays, the curve's solutions at ``omegas`` [rad/s] (monotone)
    i : int, index of the curve's highest point
    level0 : (H, peak_amplitude, peak_omega) of the curve's refined peak
    tol : float, relative target on the peak amplitude
    limit : int, highest harmonic of a level
    tol_lam : float, tolerance on the peak frequency [rad/s]

    Returns
    -------
    dict: levels (list of (H, amplitude, omega), the curve's first), harmonics (set of the
    richest level), x (its peak solution, None when no level beyond the curve was
    solved), error (:func:`richest_error` of the levels, None with one level), met
    (bool), message (why not met, else None), solves (Newton solves at the levels).

    The first level's starting guesses are the curve's points around its peak padded with
    zeros (:func:`pad`); a later level starts from the previous level's peak padded
    (:func:`near_peak`: four to seven solves), or, when that fails, from the previous
    level's corrected window, the other curve points padded from the curve.
    """
    levels, hs, cur, x_peak, solves = [tuple(level0)], tuple(basis.harmonics), list(xs), None, 0
    error, message = None, None
    while True:
        nxt = next_level(hs, levels, error, tol, limit)
        if nxt is None:
            message = f"H = {hs[-1]} at the peak is the limit H <= {limit}"
            break
        small = richer(hs, limit=limit)   # the retry when a predicted jump is too far for the guesses
        for nxt in [nxt] + ([small] if small[-1] < nxt[-1] else []):  # noqa: B020
            try:
                rich, x, w, a, n, guesses, i = _level(problem_at, nxt, basis, cur, levels, omegas, i,
                                                      tol, tol_lam, x_peak)
                break
            except RuntimeError as err:
                message = f"the peak at H = {nxt[-1]} failed ({err}); H = {hs[-1]} kept"
        else:
            break
        message = None
        hs, basis, cur, x_peak, solves = nxt, rich, guesses, x, solves + n
        levels.append((hs[-1], float(a), float(w)))
        error = richest_error(levels)
        e = error["peak_amplitude_rel"]
        if e is not None and e <= tol and len(levels) >= MIN_LEVELS:
            break
    met = error is not None and error["peak_amplitude_rel"] is not None \
        and error["peak_amplitude_rel"] <= tol and len(levels) >= MIN_LEVELS
    return {"levels": levels, "harmonics": hs, "x": x_peak, "error": error, "met": met,
            "message": None if met else message, "solves": solves}


def _level(problem_at, hs, basis, cur, levels, omegas, i, tol, tol_lam, x_prev=None):
    """One level of :func:`raise_at_peak` at the set ``hs``: (rich basis, x, omega,
    amplitude, solves, the curve points' guesses at ``hs``, index of the highest corrected
    point); RuntimeError when no peak is found. ``x_prev``: the previous level's peak
    solution (in ``basis``), None at the first level."""
    fun, amplitude, ntol, rich = problem_at(hs)
    guesses = [pad(x, basis, rich) for x in cur]
    first = len(levels) == 1
    if not first and x_prev is not None:
        # a later level: three solves around the previous level's peak, its parabola's
        # vertex, checked (:func:`near_peak`); the curve's window only when that fails
        got = near_peak(fun, amplitude, pad(x_prev, basis, rich), levels, ntol, tol_lam,
                        LEVEL_PRECISION * tol, spacing(omegas, i))
        if got is not None:
            return (rich, *got, guesses, i)
    # the first level looks around the curve's peak, later ones around the previous
    # level's (whose corrected points are the guesses), refined to LEVEL_PRECISION
    x, w, a, n, window = peak_window(fun, amplitude, guesses, omegas, i, ntol, tol_lam,
                                     WINDOW if first else LEVEL_WINDOW, 0.0 if first else LEVEL_PRECISION * tol)
    for j, xj in window.items():
        if xj is not None:
            guesses[j] = xj
    i = max((j for j, xj in window.items() if xj is not None), key=lambda j: amplitude(window[j], omegas[j]))
    return rich, x, w, a, n, guesses, i


def peak_records(run: dict, tol: float, H_curve: int, method: str) -> tuple[dict, dict]:
    """(truncation_error, accuracy) records of a :func:`raise_at_peak` run.

    truncation_error: method, H_used (the richest level's H), H_check (the same: the
    estimate comes from the levels below it), levels (H, peak_amplitude, peak_omega of
    each), order, order_observed, peak_amplitude_rel, peak_frequency_rel (of the richest
    level), extrapolated. accuracy: target, met, H_curve, H_peak, peak_amplitude and
    peak_omega (computed at H_peak), levels, extrapolated (with its order, or None),
    message.
    """
    levels, err = run["levels"], run["error"] or {}
    H = int(levels[-1][0])
    rec = {"method": method, "H_used": H, "H_check": H,
           "levels": [{"H": int(h), "peak_amplitude": a, "peak_omega": w} for h, a, w in levels],
           "order": err.get("order", ASSUMED_ORDER), "order_observed": err.get("order_observed"),
           "order_stable": bool(err.get("order_stable")), "oscillating": bool(err.get("oscillating")),
           "peak_amplitude_rel": err.get("peak_amplitude_rel"),
           "peak_frequency_rel": err.get("peak_frequency_rel"),
           "extrapolated": err.get("extrapolated")}
    if len(levels) < 2:
        rec["note"] = run["message"]
    ex = err.get("extrapolated")
    acc = {"target": tol, "met": bool(run["met"]), "H_curve": int(H_curve), "H_peak": H,
           "peak_amplitude": levels[-1][1], "peak_omega": levels[-1][2],
           "levels": [list(lv) for lv in levels],
           "extrapolated": None if ex is None else {**ex, "order": err["order_observed"]},
           "message": None if run["met"] else _not_met(run, tol)}
    return rec, acc


def _not_met(run, tol) -> str:
    e = (run["error"] or {}).get("peak_amplitude_rel")
    est = "unknown" if e is None else f"{100 * e:.3g} %"
    return (f"accuracy {tol:g} not reached: {run['message'] or 'too few levels'}; the estimate "
            f"is {est} at H = {run['levels'][-1][0]}")
