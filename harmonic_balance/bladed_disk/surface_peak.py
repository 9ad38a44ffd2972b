"""The resonance peak of the sector with contact surfaces, and the optimal load walked over CF.

:func:`surface_peak` maximises the first-harmonic amplitude |u_a,1| of one sector model
over the frequency: an interval around the maximum found uphill from a guess
(:func:`bracket`), then Brent's search in it (:func:`harmonic_balance.brent.brent_min`),
each frequency a Newton solve started on the tangent of the nearest one solved.

:class:`SurfaceWalk` gives that peak at any centrifugal load CF for the condensed surface
model (:class:`~.surface_hb.CondensedSurfaceSectorHB`, the faces built for each load by
the caller's ``surfaces_at(cf)``, sized at that load as for ``damper upd frf --contacts
surface --cf CF``). Its unknowns are the sector's DOFs at every load and node count, so
each load's search starts from the peak solution and frequency of the nearest load
already solved; where Newton fails from there, the load step is halved in log CF
(:func:`.load_path.warm_path`), and as a last resort, while fewer than
:data:`MIN_WALKED` loads are solved, the load is reached from its open load
(:func:`.load_path.first_point`). The first load solved is the largest, where the
stuck start holds (the open load scales with the CF's own prestress).

:func:`optimal_load_surface` walks ``points`` log-spaced loads from the largest down and
refines the optimum as :func:`.optimize.optimal_load` does (Brent's bounded search in log
CF between the neighbours of the smallest walked peak), returning the same record plus a
``surface_model`` record (per load: nodes, evaluations, CPU time).

Symbols: CF centrifugal load of the damper [N], omega [rad/s], f [Hz].
"""
from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import minimize_scalar

from ..brent import brent_min
from ..newton import NewtonError
from . import load_path
from .optimize import FLAT_BAND, flat_band, peak_at
from .solve import SolverError, solve_point, start_point
from .surface_hb import CondensedSurfaceSectorHB

#: First step of the search for an interval around the peak, relative to the guess (the
#: surfaces' stiffness differs from the points' by a few per cent, the next load's peak
#: from the last by less), and the most doublings of it (0.5 % ... 32 % of the guess).
BRACKET_STEP, MAX_BRACKET = 0.005, 6
#: Frequency tolerance of the peak search, relative: the amplitude is flat at the peak, so
#: 1e-4 in frequency moves it by far less than the 0.5 % the node study resolves.
PEAK_XTOL = 1e-4
#: Newton iterations of a warm start in frequency (a converging one took 3-9 on UPD-24).
MAX_ITER = 80
#: Newton iterations of a load's first solve from the nearest load's peak solution before the
#: step is halved: a converging one took a few, a failing one spends ~8 evaluations per
#: iteration in its line search (UPD-24, H 7, 57.9 -> 30 N: more than 7 min CPU in 80).
LOAD_STEP_ITER = 15
#: Tolerance of the optimum in log CF (2 % in CF). The point model's 1e-3
#: (:data:`.optimize.CF_XTOL`) would double the refinement's loads, each a peak search of
#: minutes; the minimum is flat (the peak within 1 % over a wide CF band), so 2 % in CF
#: moves the optimum's peak by far less than the truncation in H does.
SURFACE_CF_XTOL = 0.02
#: Loads the walk must solve before a failed lower load stops it with a warning instead of
#: an error: two give the trend, the optimum then lies at the lowest solved (or between).
MIN_WALKED = 2
#: Residual evaluations expected per load (the cost estimate's, :func:`expected_evaluations`):
#: EVALUATIONS_BASE + EVALUATIONS_PER_H H. A load warm-started from the last took 112-130 at
#: H 7 (UPD-24, 5 nodes per side, CF 1554 ... 417 N: ~12 frequencies of bracket and Brent,
#: ~9 Newton evaluations each from the tangent predictor and one for the tangent); measured
#: at 4b13a0a with ``damper upd optimize --contacts surface --cf-range 300 1200 --points 3``:
#: 36 and 46 at H 1, 61 and 83 at H 3 (the Newton solves take more iterations with more
#: harmonics). The line gives 43, 69 and 121; a constant 120 was 3x too high at H 1.
EVALUATIONS_BASE, EVALUATIONS_PER_H = 30, 13
#: Loads of the refinement expected when the smallest walked peak is interior: Brent's
#: bounded search to SURFACE_CF_XTOL between its neighbours (none at a range's end).
REFINE_LOADS = 6
#: Evaluations of the first load's path from its open load beyond a warm load's, as a share
#: of a warm load's: 90 of 120 at H 7 (CF 3000 N: 211 in all); at 4b13a0a (the command above,
#: CF 1200 N) the first load took 72 at H 1 and 119 at H 3: 29 and 50 beyond a warm load's.
PATH_SHARE = 0.75


def bracket(neg, f0: float, step: float = BRACKET_STEP) -> tuple[float, float, float]:
    """An interval (lo, hi) [Hz] and its best point around a maximum of -neg: uphill from f0
    in steps of ``step`` f0, doubled, until the amplitude falls (Press et al., Numerical
    Recipes, sec. 10.1); every value is kept by neg's own cache.

    Raises
    ------
    SolverError
        No fall within MAX_BRACKET doublings (no peak near the guess).
    """
    h = step * f0
    a, b = f0, f0 + h
    fa, fb = neg(a), neg(b)
    if fb > fa:
        a, b, fa, fb, h = b, a, fb, fa, -h
    for _ in range(MAX_BRACKET):
        c = b + 2 * h
        fc = neg(c)
        if fc > fb:
            return min(a, c), max(a, c), b
        a, b, fa, fb, h = b, c, fb, fc, 2 * h
    raise SolverError(f"no amplitude maximum within {abs(b - f0):.0f} Hz of {f0:.1f} Hz: the surface "
                      "model has no resonance peak near the guess")


def surface_peak(hb, f_guess: float, xtol: float = PEAK_XTOL, first=None, report=None) -> dict:
    """Maximum over the frequency of the first harmonic of u_a (module docstring).

    Parameters
    ----------
    hb : SectorHB
        Any sector model (point contacts, surfaces with node DOFs or condensed).
    f_guess : float
        Start of the search [Hz].
    xtol : float
        Relative frequency tolerance of the peak.
    first : callable, optional
        ``first(omega)``: a solution where no warm start from a solved frequency converges
        (default :func:`.solve.start_point`, the stuck start).
    report : callable, optional
        ``report(f, amplitude)`` after each frequency solved.

    Returns
    -------
    dict: peak_hz, peak_amplitude_h1 [m], x (the solution there), points (Hz, amplitude of
    every frequency solved), cpu_s. (The residual evaluations are counted by the caller,
    over every model ``first`` builds too.)
    """
    p0 = time.process_time()
    solved = {}   # omega -> x
    first = first or (lambda w: start_point(hb, w))
    predict = _Tangents(hb, solved)

    def neg_amp(f):
        w = 2 * np.pi * f
        if w in solved:
            return -hb.amplitude_h1(solved[w])
        x = None
        if solved:   # from the nearest frequency's tangent; ``first`` when that fails
            try:
                x = solve_point(hb, w, predict(w), max_iter=MAX_ITER)
            except NewtonError:
                pass
        solved[w] = x = first(w) if x is None else x
        if report:
            report(f, hb.amplitude_h1(x))
        return -hb.amplitude_h1(x)

    lo, hi, best = bracket(neg_amp, f_guess)
    f, a, _ = brent_min(neg_amp, lo, hi, xtol * f_guess, start=best)
    pts = sorted((w / (2 * np.pi), hb.amplitude_h1(x)) for w, x in solved.items())
    return {"peak_hz": float(f), "peak_amplitude_h1": float(-a), "x": solved[2 * np.pi * f],
            "points": pts, "cpu_s": time.process_time() - p0}


class _Tangents:
    """The tangent predictor of a frequency's Newton start: x_n + (dx/domega)_n (omega - omega_n)
    from the nearest solved frequency omega_n, dx/domega = -J^-1 dR/domega there (one
    evaluation, kept per solved frequency). On UPD-24 (CF 1200 N, H 1, 5 nodes per side)
    Newton took 4 evaluations from it over a 0.5 % step where it took 35 from x_n itself,
    and 7 over the next 1 % step where the secant through the last two took 11."""

    def __init__(self, hb, solved: dict):
        self.hb, self.solved, self.slopes = hb, solved, {}

    def __call__(self, omega: float) -> np.ndarray:
        wn = min(self.solved, key=lambda v: abs(v - omega))
        if wn not in self.slopes:
            _, J, dR_dw = self.hb(self.solved[wn], wn)
            try:
                self.slopes[wn] = -np.linalg.solve(J, dR_dw)
            except np.linalg.LinAlgError:   # a singular Jacobian: the zero-order start
                self.slopes[wn] = np.zeros_like(dR_dw)
        return self.solved[wn] + self.slopes[wn] * (omega - wn)


class SurfaceWalk:
    """Peaks of the condensed surface model at any load, each warm-started from the nearest
    load solved (module docstring).

    Parameters
    ----------
    sector : Sector
    surfaces_at : callable
        ``surfaces_at(cf)``: the planar surfaces {"left", "flat"} sized at load cf [N]
        (``damper.upd_surface.build_surfaces``).
    H : int
        Highest harmonic.
    f0 : float, optional
        EO force amplitude [N] (default the config's).
    xtol : float
        Relative frequency tolerance of each peak.
    report : callable, optional
        ``report(cf, f, amplitude)`` after each frequency solved.
    on_load : callable, optional
        ``on_load(record)`` after each load's peak (the record :meth:`peak` returns).
    """

    def __init__(self, sector, surfaces_at, H: int, f0=None, xtol: float = PEAK_XTOL, report=None,
                 on_load=None):
        self.sector, self.surfaces_at, self.H, self.f0 = sector, surfaces_at, int(H), f0
        self.xtol, self.report, self.on_load = xtol, report, on_load
        self.built = []      # every model built (their evaluations are the walk's)
        self.solved = {}     # cf -> (omega, x) of its peak
        self.loads = []      # one record per load, in the order solved

    @property
    def evaluations(self) -> int:
        """Residual evaluations of every model built so far."""
        return sum(m.evaluations for m in self.built)

    def factory(self, cf: float):
        """``make(c)``: the model at load c [N] on the surfaces sized at ``cf`` (a path's
        loads share its target's faces, as ``damper upd frf``'s path does), and their node count."""
        surfaces = self.surfaces_at(cf)

        def make(c):
            self.built.append(CondensedSurfaceSectorHB(self.sector, surfaces, self.H, cf=c, f0=self.f0))
            return self.built[-1]
        return make, sum(s.n for s in surfaces.values())

    def peak(self, cf: float, f_guess: float | None = None) -> dict:
        """The peak at load ``cf`` [N] (cached): searched from the nearest solved load's peak
        frequency, or from ``f_guess`` [Hz] at the first load.

        Returns
        -------
        dict: cf, peak_hz, peak_amplitude_h1 [m], nodes, evaluations, cpu_s, start (how the
        first frequency was solved), points.
        """
        cf = float(cf)
        done = next((r for r in self.loads if r["cf"] == cf), None)
        if done is not None:
            return done
        p0, e0 = time.process_time(), self.evaluations
        make, nodes = self.factory(cf)
        hb = make(cf)
        start = {"how": None}
        first = self._first(make, hb, cf, start)
        if self.solved:
            f_guess = self.solved[self._nearest(cf)][0] / (2 * np.pi)
        if f_guess is None:
            raise ValueError("the first load's peak search needs a frequency guess f_guess [Hz]")
        report = None if self.report is None else (lambda f, a: self.report(cf, f, a))
        pk = surface_peak(hb, f_guess, self.xtol, first, report)
        self.solved[cf] = (2 * np.pi * pk["peak_hz"], pk["x"])
        rec = {"cf": cf, "peak_hz": pk["peak_hz"], "peak_amplitude_h1": pk["peak_amplitude_h1"],
               "nodes": nodes, "evaluations": self.evaluations - e0, "cpu_s": time.process_time() - p0,
               "start": start["how"], "points": pk["points"]}
        self.loads.append(rec)
        if self.on_load:
            self.on_load(rec)
        return rec

    def _nearest(self, cf: float) -> float:
        return min(self.solved, key=lambda c: abs(math.log(c / cf)))

    def _first(self, make, hb, cf: float, start: dict):
        """``first(omega)`` of the load's search: Newton from the nearest solved load's peak
        solution, else that load step halved, else (fewer than MIN_WALKED loads solved) the
        path from the open load."""
        def from_open_load(w):
            x, rec = load_path.first_point(make, w, cf)
            start["how"] = start["how"] or ("path from the open load" if len(rec["loads"]) > 1
                                            else "stuck start")
            return x

        def first(w):
            if not self.solved:
                return from_open_load(w)
            c0 = self._nearest(cf)
            x0 = self.solved[c0][1]
            try:
                x = solve_point(hb, w, x0, LOAD_STEP_ITER)
                start["how"] = start["how"] or f"warm from {c0:.4g} N"
                return x
            except NewtonError:
                pass
            try:
                x = load_path.warm_path(make, w, x0, c0, cf)
                start["how"] = start["how"] or f"warm from {c0:.4g} N, step halved"
                return x
            except SolverError:
                # with the walk under way the open load's path retraces the loads already
                # walked and fails where the halved steps did (UPD-24, 30 N: 17 of the
                # walk's 24 min CPU spent so): the failure stops the walk (_walk_down)
                if len(self.solved) >= MIN_WALKED:
                    raise
                return from_open_load(w)
        return first


def expected_evaluations(points: int, H: int) -> tuple[int, int]:
    """Residual evaluations expected at ``H`` harmonics: (the walk of ``points`` loads with the
    first load's path, the refinement's :data:`REFINE_LOADS` loads when the optimum is interior)
    (:data:`EVALUATIONS_BASE`, :data:`EVALUATIONS_PER_H`, :data:`PATH_SHARE`; measured at H 1 ... 7)."""
    per_load = EVALUATIONS_BASE + EVALUATIONS_PER_H * H
    return round(per_load * (points + PATH_SHARE)), per_load * REFINE_LOADS


def optimal_load_surface(sector, surfaces_at, cf_range, points: int, H: int, f0=None,
                         cf_xtol: float = SURFACE_CF_XTOL, estimate=None, report=None,
                         on_load=None) -> dict:
    """Peak amplitude against CF and the optimum CF with contact surfaces (module docstring).

    Parameters
    ----------
    sector : Sector
    surfaces_at : callable
        ``surfaces_at(cf)`` as :class:`SurfaceWalk`'s.
    cf_range : (2,) CF bounds [N], log-spaced ``points`` values walked from the largest down
    points, H : int
    f0 : float, optional
        EO force amplitude [N].
    cf_xtol : float
        Tolerance of the optimum in log CF.
    estimate : callable, optional
        ``estimate(walk, refine, seconds)`` before the walk: the evaluations expected of the
        walk and of the refinement (:func:`expected_evaluations`) and the measured CPU time
        [s] of one (with its Jacobian, at the first load's stuck start
        after its linear step: the first evaluation of a Newton solve).
    report, on_load : callable, optional
        As :class:`SurfaceWalk`'s.

    Returns
    -------
    dict with the keys of :func:`.optimize.optimal_load` (cf, peak_amplitude, peak_frequency_hz,
    optimum_cf, optimum_peak_amplitude, method, interior, ...) and ``surface_model``: model,
    evaluations, cpu_s, time_s, the first load's frequency guess, ``loads`` (per load solved:
    cf, peak_hz, peak_amplitude_h1, nodes, evaluations, cpu_s, start).
    """
    lo, hi = (float(v) for v in cf_range)
    if not (0 < lo < hi and np.isfinite(hi)) or points < 3:
        raise ValueError(f"--cf-range needs 0 < low < high and --points >= 3, got {cf_range}, {points}")
    t0, p0 = time.perf_counter(), time.process_time()
    cfs = np.geomspace(lo, hi, points)
    band = sector.cfg["load.band_hz"]
    walk = SurfaceWalk(sector, surfaces_at, H, f0, report=report, on_load=on_load)
    hb = walk.factory(hi)[0](hi)   # the largest load's faces first: a geometry refused before any solve
    # the first search's guess: the point model's peak at the largest load (seconds)
    w_guess, _ = peak_at(sector, hi, H, 2 * np.pi * np.linspace(band[0], band[1], 40), f0)
    if estimate is not None:
        x = hb.stuck_guess(w_guess)   # one evaluation at the prestress: every node stuck (cheap)
        c = time.process_time()
        hb(x, w_guess)                # Newton's first from the stuck start: nodes slip (typical)
        estimate(*expected_evaluations(points, H), time.process_time() - c)
    peaks, stopped = _walk_down(walk, cfs, w_guess / (2 * np.pi))
    cfs = cfs[cfs.size - len(peaks):]
    t_grid, c_search = time.perf_counter() - t0, time.process_time()
    amp = np.array([p["peak_amplitude_h1"] for p in peaks])
    out = {"cf": cfs.tolist(), "peak_amplitude": amp.tolist(),
           "peak_frequency_hz": [p["peak_hz"] for p in peaks], "harmonics": int(H)}
    out.update(_optimum(walk, cfs, amp, cf_xtol))
    if stopped:
        out["warning"] = (f"the walk stopped at {stopped[0]:.4g} N, whose peak did not solve ({stopped[1]}); "
                          f"the optimum is over the loads solved, {cfs[0]:.4g} ... {cfs[-1]:.4g} N: raise the "
                          "low end of --cf-range to walk that range in full")
    out["time_s"], out["time_grid_s"], out["workers"] = time.perf_counter() - t0, t_grid, 1
    out["cpu_chunks_s"], out["cpu_search_s"] = [c_search - p0], time.process_time() - c_search
    out["surface_model"] = {"model": "condensed", "evaluations": walk.evaluations,
                            "cpu_s": time.process_time() - p0, "time_s": out["time_s"],
                            "first_guess_hz": w_guess / (2 * np.pi),
                            "loads": [{k: v for k, v in r.items() if k != "points"} for r in walk.loads]}
    return out


def _walk_down(walk: SurfaceWalk, cfs, f_guess: float) -> tuple[list, tuple | None]:
    """The peaks of ``cfs`` (ascending) walked from the largest down, ascending; and (cf,
    message) of the load where a peak failed after MIN_WALKED loads solved (the walk stops
    there: the lowest loads, the damper near its floor, cost most and fail first; UPD-24 at
    30 N = F0 failed after ~7 min CPU at 0137a93), else None. A failure before that is raised."""
    peaks = []
    for c in cfs[::-1]:
        try:
            peaks.append(walk.peak(c, f_guess))
        except SolverError as err:
            if len(peaks) < MIN_WALKED:
                raise
            return peaks[::-1], (float(c), str(err))
    return peaks[::-1], None


def _optimum(walk: SurfaceWalk, cfs, amp, cf_xtol: float) -> dict:
    """The smallest walked peak, refined by Brent's bounded search in log CF between its
    neighbours where it is interior (as :func:`.optimize.optimal_load`)."""
    i = int(np.argmin(amp))
    if not 0 < i < cfs.size - 1:
        return {"optimum_cf": float(cfs[i]), "optimum_peak_amplitude": float(amp[i]),
                "method": "grid (minimum at the end of the range: widen --cf-range)", "interior": False}
    seen = {float(c): float(a) for c, a in zip(cfs[i - 1:i + 2], amp[i - 1:i + 2])}

    def objective(z):
        seen[float(np.exp(z))] = a = walk.peak(np.exp(z))["peak_amplitude_h1"]
        return a

    res = minimize_scalar(objective, bounds=(np.log(cfs[i - 1]), np.log(cfs[i + 1])),
                          method="bounded", options={"xatol": cf_xtol})
    best = min(seen, key=seen.get)   # the search's last point need not be its best
    return {"optimum_cf": best, "optimum_peak_amplitude": seen[best],
            "method": "bounded scalar search (Brent, log CF) on the surface peak", "interior": True,
            "search_evaluations": int(res.nfev), "optimum_band_cf": flat_band(seen, FLAT_BAND)}
