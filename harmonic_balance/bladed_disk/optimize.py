"""Damper design: the refined resonance peak against the centrifugal load (optimal-load curve).

For each CF of a log-spaced list the curve of the first-harmonic |u_a| is traced over
the band (:func:`solve.frf`: continuation with at least ``grid`` points) and its peak
refined; after the first load only a narrow band around the predicted peak. The optimum is then located by
Brent's bounded scalar search in log CF between the neighbours of the smallest grid
value, each evaluation a refined peak. (casadi is not used: the objective is a
maximum over frequency of a non-smooth branch, which a bounded scalar search on the
refined peak handles directly.)

Measured (README.md at revision c58d443, UPD section): the objective is smooth and path-independent (warm
narrow grids equal independent full-band searches to 3e-5; n_t x4: 1e-4), but its
minimum is flat, so the optimum CF depends on the harmonic truncation (H 5: 150 N,
7: 131 N, 11-21: 135-141 N, ring time integration 138 N); hence ``optimum_band_cf``.
"""
from __future__ import annotations

import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy.optimize import minimize_scalar

from .hb import SectorHB
from .sector import Sector
from .solve import frf

#: Relative tolerance of the optimum CF (log-space Brent bracket).
CF_XTOL = 1e-3
#: Rise of the peak over the optimum that bounds the reported flat band (1 %): the
#: optimum CF itself is ill-conditioned (the minimum is flat; README.md at revision c58d443).
FLAT_BAND = 0.01
#: Relative half-width of the band around the predicted peak.
NARROW = 0.03
#: Frequency points of that band: its curve has steps of at most 1 / (NARROW_POINTS - 1)
#: of the band (0.4 % of the peak frequency).
NARROW_POINTS = 17
#: The CF list is dealt into this many interleaved chunks (chunk k takes loads k,
#: k + CHUNKS, ...), each swept upwards by its own :class:`_Peaks` (full band at its
#: first load, then the narrow grid). Interleaving balances the work: a load's cost
#: grows ~10x from 100 N to 3000 N (Newton through stick-slip kinks), and a full-band
#: start above ~700 N costs 4-12 s, so contiguous chunks were unbalanced (CPU 6.2 s /
#: 15.9 s at H = 7) while every interleaved chunk starts at the cheap low end. The
#: chunks are fixed whatever the number of worker processes, so a serial run and a
#: parallel one do the same arithmetic and give identical results.
CHUNKS = 2
#: Worker processes are spawned, not forked: a fork of a process whose BLAS or
#: OpenMP threads are running can deadlock (as in damper/studies).
SPAWN = multiprocessing.get_context("spawn")


def peak_at(sector: Sector, cf: float, H: int, omegas, f0=None, mu=None) -> tuple[float, float]:
    """Refined peak (omega [rad/s], first-harmonic amplitude [m]) at centrifugal load cf [N]."""
    c = frf(SectorHB(sector, H, cf=cf, f0=f0, mu=mu), omegas)
    return c.peak_omega, c.peak_amplitude


def flat_band(samples: dict, rise: float) -> list:
    """CF interval [N] where the peak stays within ``1 + rise`` of the smallest sampled
    peak, by linear interpolation in log CF between the samples {CF: peak} (a convex
    curve: the interval is slightly narrower than the true one). An end that the
    samples do not bracket is None."""
    cf = np.array(sorted(samples))
    a = np.array([samples[c] for c in cf]) / min(samples.values()) - 1 - rise
    i, z, ends = int(np.argmin(a)), np.log(cf), []
    for j in (range(i, 0, -1), range(i, cf.size - 1)):
        end = None
        for k in j:
            k2 = k - 1 if j.step < 0 else k + 1
            if a[k2] > 0:
                end = float(np.exp(z[k] + (z[k2] - z[k]) * a[k] / (a[k] - a[k2])))
                break
        ends.append(end)
    return ends


class _Peaks:
    """Refined peaks against CF; after the first, each search runs on a narrow grid
    (NARROW relative half-width, NARROW_POINTS points) around the peak frequency
    predicted from the last two peaks (linear in log CF, moved by at most NARROW from
    the last), and falls back to the full band when the peak lands on the narrow
    grid's edge. (A prediction rather than the last peak: the interleaved chunks step
    CF by ~1.6x, over which the peak moves by up to 3 % below 300 N.)"""

    def __init__(self, sector, H, omegas, f0):
        self.sector, self.H, self.omegas, self.f0 = sector, H, omegas, f0
        self.history = []  # (log CF, peak omega) of the latest peaks
        self.calls = self.full_band = 0

    def seed(self, cf: float, omega: float) -> None:
        """Record a known peak (omega [rad/s]) at load cf [N] for the prediction."""
        self.history = (self.history + [(float(np.log(cf)), float(omega))])[-2:]

    def predict(self, cf: float) -> float | None:
        """Predicted peak omega at cf [rad/s] (None before the first peak)."""
        if not self.history:
            return None
        z1, w1 = self.history[-1]
        if len(self.history) == 1:
            return w1
        z0, w0 = self.history[0]
        w = w1 + (w1 - w0) / (z1 - z0) * (np.log(cf) - z1) if z1 != z0 else w1
        return float(np.clip(w, w1 * (1 - NARROW), w1 * (1 + NARROW)))

    def __call__(self, cf: float) -> tuple[float, float]:
        self.calls += 1
        centre = self.predict(cf)
        if centre is not None:
            grid = centre * np.linspace(1 - NARROW, 1 + NARROW, NARROW_POINTS)
            w, a = peak_at(self.sector, cf, self.H, grid, self.f0)
            if grid[1] < w < grid[-2]:
                self.seed(cf, w)
                return w, a
        self.full_band += 1
        w, a = peak_at(self.sector, cf, self.H, self.omegas, self.f0)
        self.seed(cf, w)
        return w, a


def _chunk_peaks(sector, H, omegas, f0, cfs) -> tuple[list, float]:
    """Refined peaks (omega, amplitude) of one chunk of increasing loads, in order, and
    the CPU time [s] the chunk took in its process."""
    c0 = time.process_time()
    peak = _Peaks(sector, H, omegas, f0)
    return [peak(float(cf)) for cf in cfs], time.process_time() - c0


def load_curve(sector: Sector, cfs, H: int, omegas, f0=None,
               workers: int = 1) -> tuple[list, list]:
    """Refined peaks at every load of ``cfs`` (increasing), computed in the
    :data:`CHUNKS` interleaved chunks on ``workers`` spawned processes (``workers = 1``
    runs them in this process, same results), and the CPU time [s] of each chunk (on
    free cores the grid's wall time is about the largest)."""
    cfs = np.asarray(cfs, float)
    chunks = [cfs[k::CHUNKS] for k in range(min(CHUNKS, cfs.size))]
    if workers <= 1 or len(chunks) == 1:
        done = [_chunk_peaks(sector, H, omegas, f0, c) for c in chunks]
    else:
        with ProcessPoolExecutor(min(workers, len(chunks)), mp_context=SPAWN) as pool:
            futures = [pool.submit(_chunk_peaks, sector, H, omegas, f0, c) for c in chunks]
            done = [f.result() for f in futures]
    peaks = [None] * cfs.size
    for k, (p, _) in enumerate(done):
        peaks[k::CHUNKS] = p
    return peaks, [d[1] for d in done]


def optimal_load(sector: Sector, cf_range, points: int = 20, H: int = 7, band_hz=None,
                 grid: int = 40, f0=None, workers: int = 1) -> dict:
    """Peak amplitude against CF and the optimum CF.

    Parameters
    ----------
    sector : Sector
    cf_range : (2,) CF bounds [N], log-spaced ``points`` values
    H : int, highest harmonic
    band_hz : (2,) frequency band [Hz] (default the config's)
    grid : int, frequency points per curve before the peak refinement
    workers : int, processes for the load grid (results do not depend on it)

    Returns
    -------
    dict with cf, peak_amplitude, peak_frequency_hz (lists), optimum_cf,
    optimum_peak_amplitude, method, interior (bool), time_s; when interior also
    optimum_band_cf ([low, high] N: the peak within FLAT_BAND of the optimum).
    """
    lo, hi = (float(v) for v in cf_range)
    if not (0 < lo < hi and np.isfinite(hi)) or points < 3:
        raise ValueError(f"--cf-range needs 0 < low < high and --points >= 3, got {cf_range}, {points}")
    if workers < 1:
        raise ValueError(f"--workers needs at least 1 process, got {workers}")
    t0 = time.perf_counter()
    band = sector.cfg["load.band_hz"] if band_hz is None else band_hz
    omegas = 2 * np.pi * np.linspace(band[0], band[1], grid)
    cfs = np.geomspace(lo, hi, points)
    peaks, cpu_chunks = load_curve(sector, cfs, H, omegas, f0, workers)
    t_grid = time.perf_counter() - t0
    c_search = time.process_time()
    peak = _Peaks(sector, H, omegas, f0)
    amp = np.array([p[1] for p in peaks])
    i = int(np.argmin(amp))
    interior = 0 < i < points - 1
    out = {"cf": cfs.tolist(), "peak_amplitude": amp.tolist(),
           "peak_frequency_hz": [p[0] / (2 * np.pi) for p in peaks], "harmonics": H}
    if not interior:
        out.update(optimum_cf=float(cfs[i]), optimum_peak_amplitude=float(amp[i]),
                   method="grid (minimum at the end of the range: widen --cf-range)",
                   interior=False)
    else:
        peak.seed(cfs[i - 1], peaks[i - 1][0])
        peak.seed(cfs[i + 1], peaks[i + 1][0])
        seen = {float(c): float(a) for c, a in zip(cfs[i - 1:i + 2], amp[i - 1:i + 2])}

        def objective(z):
            seen[float(np.exp(z))] = a = peak(np.exp(z))[1]
            return a

        res = minimize_scalar(objective, bounds=(np.log(cfs[i - 1]), np.log(cfs[i + 1])),
                              method="bounded", options={"xatol": CF_XTOL})
        out.update(optimum_cf=float(np.exp(res.x)), optimum_peak_amplitude=float(res.fun),
                   method="bounded scalar search (Brent, log CF) on the refined peak",
                   interior=True, search_evaluations=int(res.nfev),
                   optimum_band_cf=flat_band(seen, FLAT_BAND))
    out["time_s"] = time.perf_counter() - t0
    out["time_grid_s"], out["workers"] = t_grid, int(workers)
    out["cpu_chunks_s"], out["cpu_search_s"] = cpu_chunks, time.process_time() - c_search
    return out
