"""Forced response of the UPD sector: frequency sweep, peak refinement, energy balance.

The sweep walks a fixed frequency grid with Newton's method (line search,
:mod:`..newton`) from a secant predictor; when Newton fails at a grid point the
interval is bisected (down to :data:`MAX_BISECT` levels) so stick-slip kinks are
passed in small steps. The peak is refined by Brent's bounded search on the
first-harmonic amplitude between the grid neighbours of the largest grid value,
each evaluation a Newton solve from the nearest converged point. Where the grid
sweep fails (a fold of the curve: two amplitudes at one frequency, which a frequency
grid cannot follow) the band is followed by pseudo-arclength continuation instead
(:func:`follow`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from ..contact import ContactElement
from ..continuation import ContinuationError, continuation, refine_max
from ..forces import harmonic_work
from ..newton import NewtonError, newton
from ..residual import energy_per_cycle
from .hb import SectorHB

#: Newton tolerance on |R| relative to max(F0, CF) [-]: far below the 1e-6 energy
#: balance asked for (measured balance ~1e-11 at this tolerance).
TOL_REL = 1e-10
#: Bisection depth of a failed sweep step (2^-6 of a grid step).
MAX_BISECT = 6
#: Halvings of F0 at the start of the start-point homotopy.
HOMOTOPY_LEVELS = 6
#: Relative frequency tolerance of the peak search.
PEAK_XTOL = 1e-6


class SolverError(RuntimeError):
    """The harmonic balance did not converge; message says where and what to change."""


class StartError(SolverError):
    """No solution at the band's first frequency (no curve to follow from)."""


@dataclass
class Curve:
    """A computed response curve (SI units; omega in rad/s)."""

    omega: np.ndarray
    x: list
    amplitude: np.ndarray          # first harmonic |u_a| [m]
    amplitude_max: np.ndarray      # max |u_a(t) - mean| [m]
    peak_omega: float = float("nan")
    peak_amplitude: float = float("nan")
    peak_x: np.ndarray | None = None
    evaluations: int = 0
    time_s: float = 0.0
    extra: dict = field(default_factory=dict)


def _tol(hb: SectorHB) -> float:
    return TOL_REL * max(hb.f0, hb.cf)


def solve_point(hb: SectorHB, omega: float, x0: np.ndarray, max_iter: int = 40) -> np.ndarray:
    """Newton solve at one frequency; raises NewtonError."""
    return newton(lambda z: hb(z, omega)[:2], x0, _tol(hb), max_iter).x


def start_point(hb: SectorHB, omega: float) -> np.ndarray:
    """First solution of a sweep: Newton from the stuck linear guess, else a homotopy.

    The homotopy raises the EO force from F0 / 2^HOMOTOPY_LEVELS (nearly stuck, where
    the stuck guess converges) to F0 in halving steps, bisected on failure.
    """
    try:
        return solve_point(hb, omega, hb.stuck_guess(omega), max_iter=80)
    except NewtonError:
        pass
    f0 = hb.f0
    lam = [2.0 ** -k for k in range(HOMOTOPY_LEVELS, -1, -1)]
    try:
        hb.set_f0(f0 * lam[0])
        x = solve_point(hb, omega, hb.stuck_guess(omega), max_iter=80)
        done = lam[0]
        for target in lam[1:]:
            x, done = _ramp(hb, omega, x, f0, done, target), target
    finally:
        hb.set_f0(f0)
    return solve_point(hb, omega, x)


def _ramp(hb, omega, x, f0, a, b, depth=0):
    """Solution at force scale b from the one at scale a (bisection on failure)."""
    hb.set_f0(f0 * b)
    try:
        return solve_point(hb, omega, x * 1.0)
    except NewtonError:
        if depth >= MAX_BISECT:
            raise
    m = 0.5 * (a + b)
    xm = _ramp(hb, omega, x, f0, a, m, depth + 1)
    return _ramp(hb, omega, xm, f0, m, b, depth + 1)


def _step(hb, w_a, x_a, dxdw, w_b, depth=0):
    """Solution at w_b from (w_a, x_a) with slope dxdw; bisects on failure."""
    try:
        return solve_point(hb, w_b, x_a + (w_b - w_a) * dxdw)
    except NewtonError:
        if depth >= MAX_BISECT:
            raise
    w_m = 0.5 * (w_a + w_b)
    x_m = _step(hb, w_a, x_a, dxdw, w_m, depth + 1)
    return _step(hb, w_m, x_m, (x_m - x_a) / (w_m - w_a), w_b, depth + 1)


def _start(hb: SectorHB, omega: float, x0: np.ndarray | None = None) -> np.ndarray:
    """Solution at the band's first frequency (from x0, else :func:`start_point`)."""
    try:
        return start_point(hb, omega) if x0 is None else solve_point(hb, omega, x0, 80)
    except NewtonError as err:
        raise StartError(f"no solution at the start frequency {omega / 2 / np.pi:.6g} Hz "
                         f"({err}); start the band further from resonance") from None


def sweep(hb: SectorHB, omegas, x0: np.ndarray | None = None) -> list:
    """Solutions at every frequency of the grid (increasing or decreasing) [rad/s]."""
    omegas = np.asarray(omegas, dtype=float)
    x = _start(hb, omegas[0], x0)
    xs, slope = [x], np.zeros_like(x)
    for k in range(1, len(omegas)):
        try:
            x = _step(hb, omegas[k - 1], xs[-1], slope, omegas[k])
        except NewtonError as err:
            raise SolverError(f"harmonic balance failed near {omegas[k] / 2 / np.pi:.6g} Hz "
                              f"({err})") from None
        slope = (x - xs[-1]) / (omegas[k] - omegas[k - 1])
        xs.append(x)
    return xs


def refine_peak(hb: SectorHB, omegas, xs) -> tuple[float, float, np.ndarray]:
    """Peak (omega, first-harmonic amplitude, solution) by Brent's search between grid points."""
    amp = np.array([hb.amplitude_h1(x) for x in xs])
    i = int(np.argmax(amp))
    if i == 0 or i == len(xs) - 1:
        return float(omegas[i]), float(amp[i]), xs[i]
    cache = {}

    def neg_amp(w):
        j = int(np.argmin(np.abs(omegas - w)))
        try:
            x = solve_point(hb, w, xs[j] + 0.0)
        except NewtonError:
            x = _step(hb, omegas[j], xs[j], np.zeros_like(xs[j]), w)
        cache[w] = x
        return -hb.amplitude_h1(x)

    res = minimize_scalar(neg_amp, bounds=(omegas[i - 1], omegas[i + 1]), method="bounded",
                          options={"xatol": PEAK_XTOL * omegas[i]})
    if res.x not in cache:
        neg_amp(res.x)
    return float(res.x), float(-res.fun), cache[res.x]


def follow(hb: SectorHB, omegas, reason: str = "", x0: np.ndarray | None = None) -> Curve:
    """Response curve by pseudo-arclength continuation in omega over the band of ``omegas``.

    The fallback of :func:`frf` when the fixed-grid sweep fails: where the curve folds
    (two stable amplitudes at one frequency, e.g. high CF/F0) a frequency grid cannot
    follow it, the arclength can (:mod:`harmonic_balance.continuation`). The points are
    the branch's own (omega may go back and forth); the peak is refined on the branch
    (``continuation.refine_max``).
    """
    omegas = np.asarray(omegas, dtype=float)
    fun = hb.__call__
    x0 = _start(hb, omegas[0], x0)
    try:
        # ds_max: at least ~2 x the grid's point count on a flat branch
        branch = continuation(fun, x0, omegas[0], omegas[-1], _tol(hb),
                              ds_max=min(0.02, 1.0 / max(len(omegas), 2)), max_points=20000)
    except ContinuationError as err:
        w = err.branch.lam[-1] / 2 / np.pi if err.branch.lam else omegas[0] / 2 / np.pi
        raise SolverError(f"{reason}; the arclength continuation then stopped at {w:.6g} Hz "
                          f"({err}); try fewer harmonics or a narrower --band") from None
    xs, lam = branch.x, np.array(branch.lam)
    c = Curve(lam, xs, np.array([hb.amplitude_h1(x) for x in xs]),
              np.array([hb.amplitude_max(x) for x in xs]))
    i = int(np.argmax(c.amplitude))
    if 0 < i < len(xs) - 1:
        x, w, a, _ = refine_max(fun, branch, i, lambda x, lam: hb.amplitude_h1(x), _tol(hb),
                                PEAK_XTOL * lam[i])
        c.peak_omega, c.peak_amplitude, c.peak_x = w, a, x
    else:
        c.peak_omega, c.peak_amplitude, c.peak_x = float(lam[i]), float(c.amplitude[i]), xs[i]
    c.extra["method"] = f"arclength continuation ({reason})"
    return c


def frf(hb: SectorHB, omegas, refine: bool = True) -> Curve:
    """Response curve on the frequency grid ``omegas`` [rad/s], peak refined.

    The fixed-grid sweep first (fast, the points on the user's grid); where it fails
    (a fold of the curve, a kink Newton cannot pass in 2^-MAX_BISECT of a step) the
    whole band is followed by arclength continuation instead (:func:`follow`,
    ``Curve.extra["method"]`` says so).
    """
    t0 = time.perf_counter()
    e0 = hb.evaluations
    x_start = _start(hb, omegas[0])  # StartError: nothing to follow either
    try:
        xs = sweep(hb, omegas, x_start)
    except SolverError as err:
        c = follow(hb, omegas, f"the frequency-grid sweep failed: {err}", x_start)
        c.evaluations = hb.evaluations - e0
        c.time_s = time.perf_counter() - t0
        return c
    c = Curve(np.asarray(omegas, float), xs, np.array([hb.amplitude_h1(x) for x in xs]),
              np.array([hb.amplitude_max(x) for x in xs]))
    c.extra["method"] = "frequency grid"
    if refine:
        try:
            c.peak_omega, c.peak_amplitude, c.peak_x = refine_peak(hb, c.omega, xs)
        except NewtonError as err:
            raise SolverError(f"peak refinement failed ({err}); use more frequency points") from None
    else:
        i = int(np.argmax(c.amplitude))
        c.peak_omega, c.peak_amplitude, c.peak_x = float(c.omega[i]), float(c.amplitude[i]), xs[i]
    c.evaluations = hb.evaluations - e0
    c.time_s = time.perf_counter() - t0
    return c


def energy_balance(hb: SectorHB, x: np.ndarray, omega: float) -> dict:
    """Work per cycle [J] of the excitation and every dissipation, from the harmonics.

    W_ext = W_struct + W_dashpot + W_friction holds exactly at a solution (Galerkin
    projection; ``forces.harmonic_work``): W_struct = beta K_struct (the linear C and the
    rim element's dashpot), W_dashpot the contact dashpots (exact in harmonics), and
    W_friction the contacts' remaining harmonic work (friction, plus the normal springs'
    AFT sampling error). W_friction_loops is the C core's area of the sampled friction
    loops: it differs from W_friction by the AFT quadrature, O(n_t^-2).
    """
    b, res = hb.basis, hb.residual
    X = x.reshape(hb.nb, hb.ndof)
    e = energy_per_cycle(hb.model, b, X, omega)
    lfs = res.evaluate(x, omega, jac=False)
    w_struct, w_dash, w_fric, w_loops = e["W_visc"], 0.0, 0.0, 0.0
    for el, lf in zip(res.elements, lfs):
        U = (el.kinematics.operators(b, res.dofs)[0] @ x).reshape(b.nb, el.m)
        w = harmonic_work(U, lf.F, b)
        if isinstance(el, ContactElement):
            w_dash += lf.W_viscous
            w_fric += w - lf.W_viscous
            w_loops += lf.W - lf.W_viscous
        else:
            w_struct += w
    total = w_struct + w_dash + w_fric
    return {"W_ext": e["W_ext"], "W_struct": w_struct, "W_dashpot": w_dash, "W_friction": w_fric,
            "W_friction_loops": w_loops, "imbalance": (e["W_ext"] - total) / e["W_ext"]}
