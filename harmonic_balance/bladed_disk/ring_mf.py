"""Mistuned ring in two fidelities: the band traced at a low H, the peaks solved at the asked H.

The continuation of :mod:`.ring_fast` over the whole band runs on the ring truncated at a
low harmonic H_T (fewer unknowns, each blade's block factorization ~((2H_T + 1)/(2H + 1))^3
of the cost, a coarser AFT grid): it only has to tell where each blade may peak. The
ring at the asked H is then continued only over windows around those places:

* **Candidates.** Every local maximum of a blade's low-H amplitude (on the trace's
  points, the band's ends included) within :data:`TRACE_MARGIN` of that blade's low-H
  maximum. The truncation moves a blade's peaks by a few per cent and not all alike
  (measured on UPD-24 at H_T = 3 against H = 7: -2 % to +9 %, so a blade's highest peak
  can move from one resonance to another); the margin keeps every peak that could be
  the highest at H.
* **Windows.** Each candidate's neighbouring trace points bound a window; overlapping
  ones merge. The window is continued at H from its highest candidate (the low-H
  solution padded with zeros in the harmonics above H_T, then Newton), and each end is
  pushed outwards while a blade with a candidate in it still rises towards that end:
  the peak is bracketed at H, whatever the shift of its frequency.
* **Peaks.** Every blade's peak is the largest of its cubic Hermite peaks over the
  windows (each window's points a branch of :mod:`.ring_fast`), and the largest is
  polished as there. Values at H only: a peak is never taken from the trace.

When a window fails to start or the largest peak is not bracketed, the whole band is
continued at H (:func:`.ring_fast.fast_ring_frf`), the equal fallback.

Symbols: omega [rad/s]; H the asked highest harmonic, H_T the trace's; a_j the
first-harmonic magnitude of blade j's response DOF [m].
"""
from __future__ import annotations

import time

import numpy as np

from ..newton import NewtonError
from .hb import SectorHB
from .ring_fast import Branch, FastRingSolver, _flank, _polish_largest, fast_ring_frf, hermite_peaks
from .ring_hb import MistunedRingHB
from .ring_solve import RingCurve
from .solve import SolverError

#: A blade's local maximum of the low-H trace within this fraction of its largest is a
#: candidate peak. At H_T = 3 the blades' peaks move by -2 % to +9 % against H = 7 on
#: UPD-24 (five patterns), at H_T = 5 by -4 % to +4 %: 0.8 keeps twice the largest
#: difference between two peaks of one blade.
TRACE_MARGIN = 0.8
#: AFT samples of the trace at H_T (128 at H_T = 3: the trace's cost ~30 % below 256
#: with its peaks within 0.3 % of those at 256 samples; 64 alias into more iterations).
TRACE_SAMPLES = 128
#: Trace harmonics of the default (module docstring; measured in the method page).
TRACE_HARMONICS = 3
#: How far an end of a window may be pushed out, in first steps (the trace's spacing at
#: the window's top, which follows the resonance's width): the blades' peaks moved by at
#: most ~2 such steps between H_T = 3 and H = 7 on UPD-24 where they stayed on one
#: resonance. A blade still rising there peaks elsewhere at H (another window, else
#: the fallback).
EXTEND_STEPS = 3
#: Windows this many trace points apart or closer are one (a start at H costs ~2 points).
MERGE_GAP = 2


def trace_ring(ring: MistunedRingHB, H_T: int, n_t: int = TRACE_SAMPLES) -> tuple:
    """The same ring (pattern, loads, friction) truncated at H_T; (ring, tuned sector)."""
    low = MistunedRingHB(ring.sector, ring.kappa, H_T, cf=ring.cf, f0=ring.f0, mu=ring.mu, n_t=n_t)
    tuned = SectorHB(ring.sector, H_T, cf=ring.cf, f0=ring.f0, mu=ring.mu, n_t=low.basis.n_t)
    return low, tuned


def pad(x_low: np.ndarray, low: MistunedRingHB, ring: MistunedRingHB) -> np.ndarray:
    """Unknowns of ``ring`` (harmonics 0..H) from those of ``low`` (0..H_T <= H), zero above
    H_T. Both are coefficient-major with coefficients ordered by harmonic (mean, cos 1,
    sin 1, ...), so the low ring's coefficients are the leading ones."""
    x = np.zeros(ring.size)
    x[:low.size] = x_low
    return x


def candidate_windows(w: np.ndarray, a: np.ndarray, margin: float = TRACE_MARGIN) -> list:
    """Windows of trace point indices around every blade's candidate peaks.

    Parameters
    ----------
    w : (n,) trace frequencies [rad/s], increasing
    a : (n, N_b) amplitudes [m]
    margin : float   a local maximum at least ``margin`` times the blade's largest is kept

    Returns
    -------
    list of (i_lo, i_hi, i_start, blades): the window's first and last trace points, its
    highest candidate (where the solve at H starts) and the blades with a candidate in it.
    """
    n = w.size
    marks = []
    for j in range(a.shape[1]):
        aj = a[:, j]
        aj_pad = np.concatenate(([-np.inf], aj, [-np.inf]))
        local = (aj_pad[1:-1] >= aj_pad[:-2]) & (aj_pad[1:-1] >= aj_pad[2:])
        for i in np.flatnonzero(local & (aj >= margin * aj.max())):
            marks.append((max(i - 1, 0), min(i + 1, n - 1), int(i), j))
    marks.sort()
    windows = []
    for lo, hi, i, j in marks:
        if windows and lo <= windows[-1][1] + MERGE_GAP:
            wl = windows[-1]
            wl[1] = max(wl[1], hi)
            wl[3].add(j)
            wl[4].append(i)
        else:
            windows.append([lo, hi, i, {j}, [i]])
    out = []
    for lo, hi, _, blades, idx in windows:
        top = max(idx, key=lambda i: a[i, sorted(blades)].max())
        out.append((lo, hi, top, sorted(blades)))
    return out


class _Unbracketed(Exception):
    """The solve at H did not bracket a blade's peak, or a window failed: fall back."""


def _window(solver: FastRingSolver, trace: RingCurve, low: MistunedRingHB, win, band) -> Branch:
    """The branch at H over one window (:func:`candidate_windows`), each end pushed out
    while a blade of the window still rises towards it; raises _Unbracketed."""
    lo, hi, top, blades = win
    w, blo, bhi = trace.omega, float(band[0]), float(band[1])
    w0 = float(w[top])
    try:
        x0, xp0 = solver.solve(w0, pad(trace.x[top], low, solver.ring), 40)
    except NewtonError:
        try:
            x0, xp0 = solver.restart(w0)
        except (NewtonError, SolverError) as err:
            raise _Unbracketed(f"no solution at {w0 / 2 / np.pi:.6g} Hz ({err})") from None
    # first steps as the trace's there (it resolved the same resonances at H_T)
    h0 = 0.5 * float(w[min(top + 1, w.size - 1)] - w[max(top - 1, 0)])
    parts = []
    for end, edge in ((float(w[lo]), blo), (float(w[hi]), bhi)):
        br = Branch(solver.ring)
        br.add(w0, x0, xp0)
        sgn = np.sign(end - w0) or (1.0 if edge == bhi else -1.0)
        step, last = h0, end + sgn * EXTEND_STEPS * h0
        tol = 1e-12 * edge   # as _flank's end test
        while True:
            if sgn * (end - br.w[-1]) > tol:
                err = _flank(solver, br, end, bhi - blo, h0)
                if err:
                    raise _Unbracketed(err)
            rising = sgn * br.da[-1][blades] > 0
            if (not rising.any() or sgn * (edge - br.w[-1]) <= tol
                    or sgn * (last - br.w[-1]) <= tol):
                break
            end = min(end + step, last, bhi) if sgn > 0 else max(end - step, last, blo)
        parts.append(br)
    return _join(*parts)


def _join(down: Branch, up: Branch) -> Branch:
    """One branch, by increasing frequency, of two flanks sharing their first point."""
    out = Branch.__new__(Branch)
    out.__dict__.update(down.__dict__)
    for k in ("w", "x", "xp", "a", "da"):
        setattr(out, k, getattr(down, k)[::-1] + getattr(up, k)[1:])
    return out


def _bracketed(br: Branch, j: int, w_peak: float, band) -> bool:
    """Whether blade j's Hermite peak at w_peak lies inside the window (or at a band end)."""
    for k, e in ((0, band[0]), (-1, band[1])):
        if abs(w_peak - br.w[k]) <= 1e-12 * w_peak and abs(br.w[k] - e) > 1e-12 * e:
            return False
    return True


def multi_fidelity_frf(ring: MistunedRingHB, band, tuned: SectorHB | None = None,
                       start_omega: float | None = None, trace_harmonics: int = TRACE_HARMONICS,
                       polish: bool = True) -> RingCurve:
    """Per-blade peaks of the ring at its H over the band [lo, hi] [rad/s], traced at
    ``trace_harmonics`` (module docstring).

    As :func:`.ring_fast.fast_ring_frf` (same residual at H, tolerance, starts, polish and
    failure rules); ``trace_harmonics >= ring.H`` is that function. ``omega`` of the result
    are the points solved at H (the windows'), ``extra["trace"]`` the trace's counts and
    ``extra["windows"]`` the windows [rad/s].
    """
    if trace_harmonics >= ring.H:
        return fast_ring_frf(ring, band, tuned, start_omega, polish)
    t0 = time.perf_counter()
    lo, hi = float(band[0]), float(band[-1])
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"band {lo} {hi}: give 0 < lo < hi [rad/s]")
    low, tuned_low = trace_ring(ring, trace_harmonics)
    trace = fast_ring_frf(low, (lo, hi), tuned_low, start_omega, polish=False)
    e0 = ring.evaluations
    solver = FastRingSolver(ring, tuned)
    try:
        c = _solve_windows(solver, trace, low, (lo, hi))
    except _Unbracketed as why:
        c = fast_ring_frf(ring, (lo, hi), tuned, start_omega, polish)
        c.extra["fallback"] = str(why)
        c.evaluations += trace.evaluations
        c.time_s = time.perf_counter() - t0
        return c
    if polish:
        _polish_largest(solver, c, c.extra.pop("dA"))
    c.evaluations = ring.evaluations - e0 + trace.evaluations
    c.newton_iterations = solver.iterations + trace.newton_iterations
    c.extra |= {"factorizations": solver.factor.factorizations + trace.extra["factorizations"],
                "refinements": solver.factor.refinements, "landed": solver.landed,
                "fallbacks": getattr(solver.factor.lu, "fallbacks", 0), "missed": solver.missed,
                "points": int(c.omega.size), "fallback": None,
                "trace": {"harmonics": trace_harmonics, "points": trace.extra["points"],
                          "evaluations": trace.evaluations,
                          "factorizations": trace.extra["factorizations"]}}
    c.time_s = time.perf_counter() - t0
    return c


def _solve_windows(solver: FastRingSolver, trace: RingCurve, low: MistunedRingHB, band) -> RingCurve:
    """The windows solved at H and their per-blade peaks; raises _Unbracketed."""
    if trace.extra["truncated"]:
        raise _Unbracketed("the trace " + "; ".join(trace.extra["truncated"]))
    nb = solver.ring.blades
    best, where, owner = np.full(nb, -np.inf), np.zeros(nb), [None] * nb
    branches = []
    for win in candidate_windows(trace.omega, np.asarray(trace.amplitude)):
        br = _window(solver, trace, low, win, band)
        pk, wk = hermite_peaks(np.array(br.w), np.array(br.a), np.array(br.da))
        up = pk > best
        best[up], where[up] = pk[up], wk[up]
        for j in np.flatnonzero(up):
            owner[j] = br
        branches.append(br)
    for j in range(nb):
        if not _bracketed(owner[j], j, where[j], band):
            raise _Unbracketed(f"blade {j}'s peak at {where[j] / 2 / np.pi:.6g} Hz lies at a "
                               "window's end")
    order = np.argsort(np.concatenate([br.w for br in branches]), kind="stable")
    cat = {k: [v for br in branches for v in getattr(br, k)] for k in ("w", "x", "xp", "a", "da")}
    c = RingCurve(np.array(cat["w"])[order], np.array(cat["a"])[order], [cat["x"][i] for i in order])
    c.extra["tangents"] = [cat["xp"][i] for i in order]
    c.extra["truncated"] = []
    c.extra["windows"] = [(float(br.w[0]), float(br.w[-1])) for br in branches]
    c.extra["dA"] = np.array(cat["da"])[order]
    c.peak_per_blade, c.peak_omega_per_blade = best, where
    j = int(best.argmax())
    c.worst, c.peak, c.peak_omega = j, float(best[j]), float(where[j])
    return c
