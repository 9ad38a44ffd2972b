"""Worst mistuning pattern of a UPD bladed disk (``damper upd mistuning --worst``).

The factors within 1 +- B (B = ``bound``, default 3 std) that maximize the largest blade
peak of the ring:

* damper free or stuck, the linear ring (``harmonic_balance.bladed_disk.worst``:
  L-BFGS-B on the peak's adjoint gradient from several starts). The band is the tuned
  linear peak f_t times 1 -+ (BAND_MARGIN + B): a blade's frequency moves by about B / 2
  at most, so the worst peak stays inside.
* the friction damper (``harmonic_balance.bladed_disk.worst_friction``: L-BFGS-B on the
  adjoint gradient of the ring's refined HB peak), started from the worst patterns of
  both linear limits (:data:`LINEAR_STARTS` starts each, the cheap search) and
  ``random_starts`` seeded uniform draws in the box, each limited to
  ``max_evaluations`` ring curves; then the ring's time integration at the worst
  blade's peak frequency (``worst_friction.timeint_check``). The band is the study's
  default band for the scatter B / 3 (``damper.mistuning.tuned_reference``: from the
  friction-damped tuned peak to the stuck one, widened by BAND_MARGIN + B / 2).
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
#: Friction damper: starts of each linear limit's worst-pattern search (its best is a
#: start of the friction search), the friction search's random starts, and its ring
#: curves per start at most.
LINEAR_STARTS, RANDOM_STARTS, MAX_EVALUATIONS = 8, 2, 25


def check_worst(study, bound) -> float:
    """The search box's half-width B (ValueError naming what to change)."""
    if study.factors is not None:
        raise ValueError("--worst searches the factors itself: drop --factors")
    b = 3.0 * study.std if bound is None else float(bound)
    if not (np.isfinite(b) and 0.0 < b <= MAX_BOUND):
        raise ValueError(f"worst-pattern bound {b:g}: give 0 < --bound <= {MAX_BOUND} (or a std "
                         f"with 0 < 3 std <= {MAX_BOUND}); the factors lie within 1 +- bound")
    return b


def run_worst(study, bound: float | None = None, starts: int = 32, **friction) -> dict:
    """The worst pattern and its amplification (JSON-able; module docstring); with the
    friction damper :func:`run_worst_friction` (``friction``: its keyword arguments)."""
    if study.damper == "nonlinear":
        return run_worst_friction(study, bound, **friction)
    return _run_worst_linear(study, bound, starts)


def _linear_search(study, b: float, starts: int):
    """(result of ``worst.worst_pattern``, its LinearPeak, tuned (omega, peak)) of the
    linear ring (damper free or stuck) in its band."""
    from damper.mistuning import check_tuned_inside
    from harmonic_balance.bladed_disk.mistuning import tuned_linear_peak
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.worst import LinearPeak, worst_pattern

    cfg = study.load()
    sector = Sector(cfg)
    search = study.band_hz or cfg["load.band_hz"]
    om = 2 * np.pi * np.linspace(search[0], search[1], GRID)
    w_t, a_t = tuned_linear_peak(sector, om, study.damper, study.f0)
    check_tuned_inside(w_t, om, study.band_hz is not None)
    band = list(study.band_hz or [w_t * (1 - BAND_MARGIN - b) / (2 * np.pi),
                                  w_t * (1 + BAND_MARGIN + b) / (2 * np.pi)])
    peak = LinearPeak(sector, study.damper, 2 * np.pi * np.linspace(band[0], band[1], GRID), study.f0)
    return worst_pattern(peak, b, starts, study.seed), peak, (w_t, a_t), band


def _run_worst_linear(study, bound, starts: int) -> dict:
    from harmonic_balance.bladed_disk.mistuning import frequency_factors, whitehead_bound

    t0 = time.perf_counter()
    study.check()
    b = check_worst(study, bound)
    cfg = study.load()
    r, peak, (w_t, a_t), band = _linear_search(study, b, starts)
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


def run_worst_friction(study, bound: float | None = None, linear_starts: int = LINEAR_STARTS,
                       random_starts: int = RANDOM_STARTS, max_evaluations: int = MAX_EVALUATIONS,
                       check: bool = True) -> dict:
    """The friction damper's worst pattern, its amplification over the tuned friction-damped
    peak and (``check``) the time-integration check (JSON-able; module docstring)."""
    from dataclasses import replace

    from damper.mistuning import tuned_reference
    from harmonic_balance.bladed_disk.mistuning import frequency_factors, whitehead_bound
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.worst_friction import FrictionPeak, timeint_check, worst_friction_pattern

    t0 = time.perf_counter()
    study.check()
    b = check_worst(study, bound)
    cfg = study.load()
    # the study's band for a scatter whose 3 sigma is the box (stiffness factors)
    ref = tuned_reference(replace(study, std=b / 3.0, kind="stiffness", factors=None), cfg)
    sector = Sector(cfg)
    starts, linear = [], {}
    for damper in ("stuck", "free"):
        r = _linear_search(replace(study, damper=damper, band_hz=None), b, linear_starts)[0]
        linear[damper] = {"factors": r["kappa"].tolist(), "peak": r["peak"]}
        starts.append((f"linear worst ({damper})", r["kappa"]))
    rng = np.random.default_rng([int(study.seed), 31, 1])
    starts += [(f"random {i}", 1.0 + b * rng.uniform(-1.0, 1.0, cfg.blades)) for i in range(random_starts)]
    band = 2 * np.pi * np.asarray(ref["band_hz"])
    H = ref["harmonics"]   # the study's, or the H its accuracy chose on the tuned sector
    peak = FrictionPeak(sector, band, H, cf=study.cf, f0=study.f0,
                        start_omega=2 * np.pi * ref["tuned_frequency_hz"], solver=study.solver,
                        points=study.points)
    r = worst_friction_pattern(peak, b, starts, ref["tuned_peak"], max_evaluations)
    a_t = ref["tuned_peak"]
    out = {"blades": cfg.blades, "engine_order": cfg.engine_order, "damper": study.damper,
           "bound": b, "std": study.std, "band_hz": ref["band_hz"], "harmonics": H,
           "cf": study.cf or cfg.cf, "f0": study.f0 or cfg.f0, "solver": study.solver,
           "factors": r["kappa"].tolist(), "frequency_factors": frequency_factors(r["kappa"]).tolist(),
           "worst_blade": r["blade"], "peak": r["peak"], "frequency_hz": r["omega"] / (2 * np.pi),
           "peak_per_blade": r["peak_per_blade"].tolist(),
           "tuned_peak": a_t, "tuned_frequency_hz": ref["tuned_frequency_hz"],
           "truncation_error": ref["truncation_error"], "lift_off_warning": ref["lift_off_warning"],
           "amplification": r["peak"] / a_t,
           "starts": [s | {"amplification": None if s["peak"] is None else s["peak"] / a_t}
                      for s in r["starts"]],
           "linear_worst": linear, "whitehead_bound": whitehead_bound(cfg.blades),
           "converged": r["converged"], "message": r["message"], "evaluations": r["evaluations"],
           "failures": r["failures"], "timeint_check": None}
    if check:
        c = timeint_check(sector, r["kappa"], r["omega"], r["blade"], r["peak"], study.cf, study.f0)
        out["timeint_check"] = c | {"within_1_percent": abs(c["rel_diff"]) <= 0.01}
    out["time_s"] = time.perf_counter() - t0
    return out
