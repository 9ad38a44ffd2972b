"""Damper design: the refined resonance peak against the centrifugal load (optimal-load curve).

For each CF of a log-spaced list the peak of the first-harmonic |u_a| is found on a
coarse frequency grid and refined (:func:`solve.frf`). The optimum is then located by
Brent's bounded scalar search in log CF between the neighbours of the smallest grid
value, each evaluation a refined peak. (casadi is not used: the objective is a
maximum over frequency of a non-smooth branch, which a bounded scalar search on the
refined peak handles directly; see the README.)
"""
from __future__ import annotations

import time

import numpy as np
from scipy.optimize import minimize_scalar

from .hb import SectorHB
from .sector import Sector
from .solve import frf

#: Relative tolerance of the optimum CF (log-space Brent bracket).
CF_XTOL = 1e-3
#: Relative half-width of the frequency grid around the previous peak.
NARROW = 0.03
#: Points of that grid (3 % / 8 = 0.4 % of the peak frequency apart).
NARROW_POINTS = 17


def peak_at(sector: Sector, cf: float, H: int, omegas, f0=None, mu=None) -> tuple[float, float]:
    """Refined peak (omega [rad/s], first-harmonic amplitude [m]) at centrifugal load cf [N]."""
    c = frf(SectorHB(sector, H, cf=cf, f0=f0, mu=mu), omegas)
    return c.peak_omega, c.peak_amplitude


class _Peaks:
    """Refined peaks against CF; after the first, each search runs on a narrow grid
    around the previous peak frequency (NARROW relative half-width, NARROW_POINTS points)
    and falls back to the full band when the peak lands on the narrow grid's edge."""

    def __init__(self, sector, H, omegas, f0):
        self.sector, self.H, self.omegas, self.f0 = sector, H, omegas, f0
        self.last = None
        self.calls = 0

    def __call__(self, cf: float) -> tuple[float, float]:
        self.calls += 1
        if self.last is not None:
            grid = self.last * np.linspace(1 - NARROW, 1 + NARROW, NARROW_POINTS)
            w, a = peak_at(self.sector, cf, self.H, grid, self.f0)
            if grid[1] < w < grid[-2]:
                self.last = w
                return w, a
        w, a = peak_at(self.sector, cf, self.H, self.omegas, self.f0)
        self.last = w
        return w, a


def optimal_load(sector: Sector, cf_range, points: int = 20, H: int = 7, band_hz=None,
                 grid: int = 40, f0=None) -> dict:
    """Peak amplitude against CF and the optimum CF.

    Parameters
    ----------
    sector : Sector
    cf_range : (2,) CF bounds [N], log-spaced ``points`` values
    H : int, highest harmonic
    band_hz : (2,) frequency band [Hz] (default the config's)
    grid : int, frequency points per curve before the peak refinement

    Returns
    -------
    dict with cf, peak_amplitude, peak_frequency_hz (lists), optimum_cf,
    optimum_peak_amplitude, method, interior (bool), time_s.
    """
    lo, hi = (float(v) for v in cf_range)
    if not (0 < lo < hi and np.isfinite(hi)) or points < 3:
        raise ValueError(f"--cf-range needs 0 < low < high and --points >= 3, got {cf_range}, {points}")
    t0 = time.perf_counter()
    band = sector.cfg["load.band_hz"] if band_hz is None else band_hz
    omegas = 2 * np.pi * np.linspace(band[0], band[1], grid)
    cfs = np.geomspace(lo, hi, points)
    peak = _Peaks(sector, H, omegas, f0)
    peaks = [peak(cf) for cf in cfs]
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
        peak.last = peaks[i][0]
        res = minimize_scalar(lambda z: peak(np.exp(z))[1],
                              bounds=(np.log(cfs[i - 1]), np.log(cfs[i + 1])), method="bounded",
                              options={"xatol": CF_XTOL})
        out.update(optimum_cf=float(np.exp(res.x)), optimum_peak_amplitude=float(res.fun),
                   method="bounded scalar search (Brent, log CF) on the refined peak",
                   interior=True, search_evaluations=int(res.nfev))
    out["time_s"] = time.perf_counter() - t0
    return out
