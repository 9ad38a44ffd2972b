"""Worst mistuning pattern of a UPD bladed disk (``damper upd mistuning --worst``).

The factors within 1 +- B (B = ``bound``, default 3 std) that maximize the largest blade
peak of the linear ring, damper free or stuck (``harmonic_balance.bladed_disk.worst``:
L-BFGS-B on the peak's adjoint gradient from several starts). The band is the tuned
linear peak f_t times 1 -+ (BAND_MARGIN + B): a blade's frequency moves by about B / 2
at most, so the worst peak stays inside.
"""
from __future__ import annotations

import time

import numpy as np

#: Band margin beyond the factors' reach (fraction of the tuned peak's frequency).
BAND_MARGIN = 0.02
#: Grid points of the band (each blade-0 peak: the grid's maximum refined by Brent, on the
#: modal form: a grid point costs a sum over the modes, no solve).
GRID = 2001
#: Largest bound: factors stay within 0.25 .. 1.75.
MAX_BOUND = 0.75


def check_worst(study, bound) -> float:
    """The search box's half-width B (ValueError naming what to change)."""
    if study.damper not in ("free", "stuck"):
        raise ValueError("--worst searches the linear ring: give --damper free or --damper stuck "
                         "(a worst-pattern search with the friction damper is not implemented)")
    if study.factors is not None:
        raise ValueError("--worst searches the factors itself: drop --factors")
    b = 3.0 * study.std if bound is None else float(bound)
    if not (np.isfinite(b) and 0.0 < b <= MAX_BOUND):
        raise ValueError(f"worst-pattern bound {b:g}: give 0 < --bound <= {MAX_BOUND} (or a std "
                         f"with 0 < 3 std <= {MAX_BOUND}); the factors lie within 1 +- bound")
    return b


def run_worst(study, bound: float | None = None, starts: int = 32) -> dict:
    """The worst pattern and its amplification (JSON-able; module docstring)."""
    from harmonic_balance.bladed_disk.mistuning import frequency_factors, tuned_linear_peak, whitehead_bound
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.worst import LinearPeak, worst_pattern

    t0 = time.perf_counter()
    study.check()
    b = check_worst(study, bound)
    cfg = study.load()
    sector = Sector(cfg)
    search = study.band_hz or cfg["load.band_hz"]
    om = 2 * np.pi * np.linspace(search[0], search[1], GRID)
    w_t, a_t = tuned_linear_peak(sector, om, study.damper, study.f0)
    band = list(study.band_hz or [w_t * (1 - BAND_MARGIN - b) / (2 * np.pi),
                                  w_t * (1 + BAND_MARGIN + b) / (2 * np.pi)])
    peak = LinearPeak(sector, study.damper, 2 * np.pi * np.linspace(band[0], band[1], GRID), study.f0)
    r = worst_pattern(peak, b, starts, study.seed)
    edge = min(abs(r["omega"] - peak.omegas[0]), abs(r["omega"] - peak.omegas[-1]))
    if edge <= 1e-9 * peak.omegas[-1]:
        raise RuntimeError(f"the worst pattern's peak lies at the band's end {r['omega'] / 2 / np.pi:.6g} "
                           "Hz: give a wider --band")
    return {"blades": cfg.blades, "engine_order": cfg.engine_order, "damper": study.damper,
            "bound": b, "std": study.std, "band_hz": band,
            "factors": r["kappa"].tolist(), "frequency_factors": frequency_factors(r["kappa"]).tolist(),
            "worst_blade": 0, "peak": r["peak"], "frequency_hz": r["omega"] / (2 * np.pi),
            "tuned_peak": float(a_t), "tuned_frequency_hz": float(w_t / (2 * np.pi)),
            "amplification": r["peak"] / float(a_t),
            "amplification_per_start": [a / float(a_t) for a in r["starts"]],
            "whitehead_bound": whitehead_bound(cfg.blades), "converged": r["converged"],
            "message": r["message"], "evaluations": r["evaluations"],
            "time_s": time.perf_counter() - t0}
