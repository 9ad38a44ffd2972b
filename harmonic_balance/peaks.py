"""Resonance peaks of a traced forced-response curve: detection and refinement.

:func:`refine_peaks` refines every interior local maximum of the curve's amplitude
whose prominence exceeds :data:`PEAK_PROMINENCE` of the highest amplitude, and the
highest point of the curve whatever its prominence (a resonance of 0.6 % on a nearly
flat curve is still the curve's peak), on the branch between its neighbours
(:func:`continuation.refine_max`) to :data:`PEAK_TOL_REL` in frequency. A refinement
that fails (a corrector that converges nowhere near the peak) is retried with exact
friction links when the curve's were sampled, else the curve's highest point is kept
and said so (``peak_refined`` False, a warning in the status): a complete curve never
ends in failure for its peak.
"""
from __future__ import annotations

import numpy as np

from .continuation import refine_max

#: Peak frequency located to this relative tolerance (the amplitude error is second
#: order in it, ~1e-12 relative).
PEAK_TOL_REL = 1e-6
#: A local maximum is a resonance peak (refined, listed in ``peaks``) when its
#: prominence exceeds this fraction of the curve's maximum (the highest point is
#: refined whatever its prominence); sampled-AFT ripples are ~1e-4.
PEAK_PROMINENCE = 0.01


def peak_indices(a: np.ndarray, prominence: float) -> list[int]:
    """Interior local maxima of ``a`` (n,) whose prominence exceeds ``prominence``.

    A plateau counts once (its middle point, rounded down). The prominence of a maximum
    is its height over the higher of the two lowest points between it and the nearest
    higher point on each side (or the end of the curve): the definition of
    ``scipy.signal.find_peaks``, whose import alone costs ~0.7 s of a command's start.
    O(n x peak width), n ~ a few hundred curve points.
    """
    a = np.asarray(a, dtype=float)
    out, n, i = [], a.size, 1
    while i < n - 1:
        if a[i] > a[i - 1]:
            j = i
            while j + 1 < n and a[j + 1] == a[i]:
                j += 1  # plateau i..j
            if j < n - 1 and a[j + 1] < a[i]:
                left = _side_min(a[:i][::-1], a[i])
                right = _side_min(a[j + 1:], a[i])
                if a[i] - max(left, right) > prominence:
                    out.append((i + j) // 2)
            i = j + 1
        else:
            i += 1
    return out


def _side_min(side: np.ndarray, top: float) -> float:
    """Lowest value of ``side`` (walking away from a maximum of height ``top``) before
    the first value above ``top``."""
    above = np.flatnonzero(side > top)
    return float(side[:above[0] if above.size else side.size].min())


def candidates(result) -> list[int]:
    """Indices of the curve points whose peaks are refined (module docstring): not next
    to a restart gap (no continuous neighbours to refine between)."""
    amp = result.amplitude
    idx = peak_indices(amp, PEAK_PROMINENCE * amp.max())
    top = int(np.argmax(amp))
    if 0 < top < amp.size - 1 and amp[top] > max(amp[top - 1], amp[top + 1]) and top not in idx:
        idx.append(top)
    edges = {w for gap in result.extra.get("gaps", ()) for w in gap}
    return sorted(i for i in idx
                  if not edges & {result.omega[i - 1], result.omega[i], result.omega[i + 1]})


def refine_peaks(prob, branch, result, tol, exact_problem=None) -> None:
    """Refine the peaks of ``result`` (module docstring) in place: ``peaks``, the
    highest refined one as ``peak_*``, ``extra["peak_refined"]``.

    Parameters
    ----------
    prob : frf.FRFProblem of the curve (callable (x, omega), amplitude, response, basis)
    branch : continuation.Branch
    result : frf.FRFResult
    tol : float, corrector tolerance on |R|
    exact_problem : callable () -> FRFProblem or None, the same model with exact
        friction links (the retry of a failed refinement of a sampled curve)
    """
    peaks, nfev, failed = [], 0, []
    for i in candidates(result):
        tol_lam = PEAK_TOL_REL * abs(result.omega[i])
        tries = [prob] + ([exact_problem] if exact_problem is not None else [])
        for k, p in enumerate(tries):
            p = p if k == 0 else p()
            try:
                x, w, a, n = refine_max(p, branch, i, p.amplitude, tol, tol_lam)
            except RuntimeError as err:
                why = f"near omega = {result.omega[i]:.6g} rad/s: {err}"
                continue
            peaks.append((a, w, x, p))
            nfev += n
            break
        else:
            failed.append(why)
    result.extra["peak_refinement_evaluations"] = nfev
    result.extra["peak_refined"] = not failed
    result.peaks = [{"omega": w, "amplitude": a} for a, w, _, _ in sorted(peaks, key=lambda q: q[1])]
    if failed:
        result.status += ("; warning: peak refinement failed " + "; ".join(failed)
                          + " (the curve's highest point is reported there)")
    refine_h1_peak(prob, branch, result, tol)
    amp = result.amplitude
    if not peaks or max(peaks, key=lambda q: q[0])[0] < amp.max():
        return  # the maximum is at an end of the range, or its refinement failed
    a, w, x, p = max(peaks, key=lambda q: q[0])
    r = p.response(x, w)
    result.peak_omega, result.peak_amplitude, result.peak_solution = w, a, x
    result.peak_amplitude_h1 = (float(p.basis.magnitude(r, 1)) if 1 in p.basis.harmonics
                                else float("nan"))
    result.peak_interior = True


def refine_h1_peak(prob, branch, result, tol) -> None:
    """The first harmonic's own maximum over the curve, refined on the branch like the
    peak of max|x| (``peak_h1_max`` [m] at ``peak_h1_max_omega`` [rad/s], in place).

    It differs from ``peak_amplitude_h1`` (the first harmonic at the peak of max|x|):
    the higher harmonics shift the peak of max|x| away from the first harmonic's
    (a chain: 0.614848 at 0.5621 against 0.615010 at 0.5629 rad/s). The curve's highest
    point is kept when the maximum is at an end of the band or its refinement fails.
    """
    h1 = np.asarray(result.amplitude_h1, dtype=float)
    if 1 not in prob.basis.harmonics or not h1.size or not np.all(np.isfinite(h1)):
        return
    j = int(np.argmax(h1))
    result.peak_h1_max, result.peak_h1_max_omega = float(h1[j]), float(result.omega[j])
    if not 0 < j < h1.size - 1:
        return

    def first(x, w):
        return float(prob.basis.magnitude(prob.response(x, w), 1))
    try:
        _, w, a, _ = refine_max(prob, branch, j, first, tol, PEAK_TOL_REL * abs(result.omega[j]))
    except RuntimeError:
        return
    result.peak_h1_max, result.peak_h1_max_omega = a, w
