"""Forced response of the UPD sector: continuation over the band, peak refinement, energy balance.

A curve is traced by the package's continuation (:mod:`..continuation`: pseudo-arclength,
steps sized by the curve's shape to UPD_TOL, at most LAM_STEP of the band in
frequency, correctors at fixed frequency past a kink), the same step control as
``compute_frf``'s curves, from a first point found by Newton or, failing that, by a
continuation in the EO force level (:func:`start_point`). Where the branch is single-
valued in frequency the curve is reported on the caller's frequency grid, each value
from the branch between its two neighbouring points (cubic Hermite interpolation of the
unknowns with the branch's tangents), then corrected by Newton where its residual exceeds
the solve's tolerance (:func:`_correct_grid`); where it folds (two
amplitudes at one frequency, e.g. high CF/F0) the branch's own points are reported. The
peak (first-harmonic amplitude) is refined on the branch
(:func:`..continuation.refine_max`); a refinement that fails keeps the highest point
and says so. :func:`sweep` (Newton on a frequency grid from a secant predictor, bisected
on failure) remains for grids of solutions.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..contact import ContactElement
from ..continuation import LAM_STEP, ContinuationError, continuation, refine_max
from ..forces import harmonic_work
from ..newton import NewtonError, newton
from ..residual import energy_per_cycle
from .hb import SectorHB

#: Newton tolerance on |R| relative to max(F0, CF) [-]: far below the 1e-6 energy
#: balance asked for (measured balance ~1e-11 at this tolerance).
TOL_REL = 1e-10
#: Bisection depth of a failed sweep step (2^-6 of a grid step).
MAX_BISECT = 6
#: Halvings of F0 tried for the first level of the start-point homotopy.
HOMOTOPY_LEVELS = 8
#: Largest continuation step of a curve (scaled arclength; the curve tolerance sizes them).
DS_MAX = 0.5
#: Curve tolerance of the continuation (:mod:`..continuation`): the grid values are
#: interpolated on the branch with its tangents, far more accurately than the polyline
#: the tolerance bounds. Measured on UPD-24 (H = 7, 400-500 Hz, 200-point grid) against
#: Newton solves at the grid points: tolerance 1e-2: 237 branch points, first harmonic
#: within 1.4e-4 (median 4e-6); 3e-2: 93 points, 1.7e-4 (median 1.7e-5), below the AFT
#: sampling error of the contacts (from 256 to 1024 samples the peak moves by 7e-5 in
#: amplitude, 1.6e-4 in frequency).
UPD_TOL = 3e-2
#: Point limit of a curve's continuation.
MAX_POINTS = 20000
#: Relative frequency tolerance of the peak search.
PEAK_XTOL = 1e-6
#: Newton iterations correcting an interpolated grid value (:func:`_correct_grid`): from a
#: start that close, one or two land (the residual is piecewise linear between stick-slip
#: events); more means the interpolation crossed events, and the value is kept with a warning.
GRID_MAX_ITER = 10


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


#: Harmonics of the coarse start (:func:`start_point`): Newton from the stuck guess costs
#: the same iterations at any H (measured on UPD-24 at CF 120 N, F0 30 N, 400 Hz: 31
#: evaluations at H = 21, 0.21 s CPU), so they are spent at H = 5 (17 evaluations) and the
#: padded solution is corrected at H in 2 (0.017 s in all; the same solution to 2e-14).
START_H = 5


def start_point(hb: SectorHB, omega: float) -> np.ndarray:
    """First solution of a curve: the solution at START_H harmonics padded and corrected
    (:func:`coarse_start`), else Newton from the stuck linear guess, else a continuation
    in the EO force level (the same continuation as the curves', no curve tolerance: it
    only has to arrive) from the first of F0 2^-k (k = 1 .. HOMOTOPY_LEVELS) where Newton
    converges from the stuck guess at that level, with the CF at its full value
    throughout: R(x; lam) = R(x) + (1 - lam) F_eo. (Newton at halved levels of F0 instead
    stalls at |R| = 0.14 at 400 Hz on the geometry contacts at CF 40 N.)

    Raises
    ------
    NewtonError from the last attempt when no level starts, or the continuation's
    ContinuationError (a RuntimeError).
    """
    x = coarse_start(hb, omega)
    if x is not None:
        return x
    try:
        return solve_point(hb, omega, hb.stuck_guess(omega), max_iter=80)
    except NewtonError as err:
        last = err
    x_static = hb.static_guess()
    x_full = hb.stuck_guess(omega)
    f_eo = np.zeros((hb.nb, hb.ndof))
    f_eo[hb.basis.index(1)[0], hb.sector.forced] = hb.f0
    f_eo = f_eo.ravel()

    def level(x, lam):
        R, J, _ = hb(x, omega)
        return R + (1.0 - lam) * f_eo, J, -f_eo
    for k in range(1, HOMOTOPY_LEVELS + 1):
        lam0 = 2.0 ** -k
        try:
            x0 = newton(lambda z, lam0=lam0: level(z, lam0)[:2], x_static + lam0 * (x_full - x_static),
                        _tol(hb), 80).x
        except NewtonError as err:
            last = err
            continue
        scale = float(np.sqrt(np.mean(np.square(x_full))))
        br = continuation(level, x0, lam0, 1.0, _tol(hb), ds=0.1, ds_max=1.0, x_scale=scale,
                          tolerance=None, max_points=400)
        return br.x[-1]
    raise last


def coarse_start(hb: SectorHB, omega: float) -> np.ndarray | None:
    """Solution at ``omega`` [rad/s] by Newton from the stuck guess at START_H harmonics
    (the same sector and loads: ``hb.with_harmonics``), padded with zeros to ``hb``'s
    harmonics and corrected there; None when ``hb`` has START_H harmonics or fewer, or a
    solve fails (then :func:`start_point` starts at ``hb``'s own H)."""
    from ..accuracy import pad

    if hb.H <= START_H or not hasattr(hb, "with_harmonics"):
        return None
    low = hb.with_harmonics(START_H)
    try:
        x = solve_point(low, omega, low.stuck_guess(omega), max_iter=80)
        return solve_point(hb, omega, pad(x, low.basis, hb.basis), max_iter=80)
    except NewtonError:
        return None


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
    except (NewtonError, ContinuationError) as err:
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


def _trace(hb: SectorHB, x0, w0: float, w1: float, lam_step: float):
    """Branch from (x0, w0) to w1 [rad/s] by continuation (module docstring), or SolverError."""
    try:
        return continuation(hb, x0, w0, w1, _tol(hb), ds_max=DS_MAX,
                            tolerance=UPD_TOL, lam_step=lam_step, rtol=TOL_REL,
                            max_points=MAX_POINTS)
    except ContinuationError as err:
        w = err.branch.lam[-1] if err.branch.lam else w0
        raise SolverError(f"the continuation stopped at {w / 2 / np.pi:.6g} Hz ({err}); try "
                          "fewer harmonics or a narrower --band") from None


def on_grid(branch, omegas) -> list | None:
    """Solutions at the frequencies ``omegas`` [rad/s] interpolated on a branch that is
    single-valued in frequency (cubic Hermite in omega through the two neighbouring points,
    slopes dx/domega from their tangents; linear where a tangent is missing or has no
    frequency component), or None where the branch folds (omega not monotone)."""
    lam = np.asarray(branch.lam)
    step = np.diff(lam)
    if not (np.all(step > 0) or np.all(step < 0)):
        return None
    order = np.argsort(lam)
    lam, xs = lam[order], [branch.x[i] for i in order]
    slopes = []
    for i in order:
        t = branch.tangent[i] if i < len(branch.tangent) else None
        slopes.append(t[:-1] / t[-1] if t is not None and abs(t[-1]) > 1e-12 else None)
    out = []
    for w in np.asarray(omegas, dtype=float):
        k = int(np.clip(np.searchsorted(lam, w) - 1, 0, lam.size - 2))
        h = lam[k + 1] - lam[k]
        s = float(np.clip((w - lam[k]) / h, 0.0, 1.0))
        x = (1 - s) * xs[k] + s * xs[k + 1]
        if slopes[k] is not None and slopes[k + 1] is not None:
            # Hermite basis minus the linear part: h10, h11 (and h00, h01 as above plus
            # a cubic correction): x = h00 x_k + h10 h m_k + h01 x_k1 + h11 h m_k1
            h00, h01 = 2 * s**3 - 3 * s**2 + 1, -2 * s**3 + 3 * s**2
            h10, h11 = s**3 - 2 * s**2 + s, s**3 - s**2
            x = h00 * xs[k] + h01 * xs[k + 1] + h * (h10 * slopes[k] + h11 * slopes[k + 1])
        out.append(x)
    return out


def _refine(hb, branch, curve) -> None:
    """The curve's peak (first-harmonic amplitude) refined on the branch, in place;
    the highest branch point where it is at an end or the refinement fails."""
    amp = np.array([hb.amplitude_h1(x) for x in branch.x])
    i = int(np.argmax(amp))
    curve.peak_omega, curve.peak_amplitude, curve.peak_x = float(branch.lam[i]), float(amp[i]), branch.x[i]
    curve.extra["peak_refined"] = True
    if not 0 < i < len(branch.x) - 1:
        return
    try:
        x, w, a, _ = refine_max(hb, branch, i, lambda x, lam: hb.amplitude_h1(x),
                                _tol(hb), PEAK_XTOL * branch.lam[i])
    except RuntimeError as err:
        curve.extra["peak_refined"] = False
        _warn(curve, f"peak refinement near {branch.lam[i] / 2 / np.pi:.6g} Hz failed ({err}); the "
                     "curve's highest point is reported")
        return
    curve.peak_omega, curve.peak_amplitude, curve.peak_x = w, a, x


def frf(hb: SectorHB, omegas, refine: bool = True, x0: np.ndarray | None = None) -> Curve:
    """Response curve over the band of the frequency grid ``omegas`` [rad/s], peak refined.

    Traced by continuation (module docstring) with steps of at most the larger of
    LAM_STEP and the grid's spacing; reported on ``omegas`` where the branch is single-
    valued in frequency, else at the branch's points (``extra["method"]`` says which).
    ``x0``: a first guess at omegas[0] (default: :func:`start_point`).

    Raises
    ------
    StartError (no first point), SolverError (the continuation stopped).
    """
    t0 = time.perf_counter()
    e0 = hb.evaluations
    omegas = np.asarray(omegas, dtype=float)
    x_start = _start(hb, omegas[0], x0)
    lam_step = max(LAM_STEP, 1.0 / max(len(omegas) - 1, 1))
    branch = _trace(hb, x_start, omegas[0], omegas[-1], lam_step)
    xs = on_grid(branch, omegas)
    n, missed = len(branch.lam), []
    if xs is None:
        om, xs = np.asarray(branch.lam), branch.x
        method = f"continuation, {n} points (the branch folds: its own points)"
    else:
        om = omegas
        xs, corrected, missed = _correct_grid(hb, omegas, xs)
        method = (f"continuation, {n} points, interpolated on the {len(omegas)}-point grid, "
                  f"{corrected} corrected by Newton")
    c = Curve(om, xs, np.array([hb.amplitude_h1(x) for x in xs]),
              np.array([hb.amplitude_max(x) for x in xs]))
    c.extra.update(method=method, branch_points=n)
    if missed:
        _warn(c, f"{len(missed)} grid point(s) kept their interpolated value (Newton from it failed), "
                 f"first at {missed[0] / 2 / np.pi:.6g} Hz: refine the grid (--points)")
    if refine:
        _refine(hb, branch, c)
    else:
        i = int(np.argmax(c.amplitude))
        c.peak_omega, c.peak_amplitude, c.peak_x = float(c.omega[i]), float(c.amplitude[i]), xs[i]
    c.evaluations = hb.evaluations - e0
    c.time_s = time.perf_counter() - t0
    return c


def _warn(curve: Curve, text: str) -> None:
    """Add ``text`` to the curve's warning (one line, parts joined by '; ')."""
    old = curve.extra.get("warning")
    curve.extra["warning"] = text if old is None else f"{old}; {text}"


def _correct_grid(hb: SectorHB, omegas, xs) -> tuple[list, int, list]:
    """The interpolated grid values (:func:`on_grid`) whose residual exceeds the solve's
    tolerance, corrected by Newton from themselves (at most GRID_MAX_ITER iterations).

    The interpolation is within 5e-4 where the branch's points are close (near a
    resonance), but a lightly damped stuck flank lets the continuation take steps of a
    grid spacing, and the cubic between them was 0.45 % low there (UPD-24, CF 1e6 N,
    480-560 Hz, 5 points). One residual per grid point checks it; where it already meets
    the tolerance nothing changes. Returns the values, how many were corrected, and the
    frequencies [rad/s] whose Newton failed (kept interpolated)."""
    tol, out, corrected, missed = _tol(hb), [], 0, []
    for w, x in zip(omegas, xs):
        if np.linalg.norm(hb.value(x, w)) <= tol:
            out.append(x)
            continue
        try:
            out.append(solve_point(hb, w, x, GRID_MAX_ITER))
            corrected += 1
        except NewtonError:
            out.append(x)
            missed.append(float(w))
    return out, corrected, missed


def energy_balance(hb: SectorHB, x: np.ndarray, omega: float) -> dict:
    """Work per cycle [J] of the excitation and every dissipation, from the harmonics.

    W_ext = W_struct + W_dashpot + W_friction holds exactly at a solution (Galerkin
    projection; ``forces.harmonic_work``): W_struct = beta K_struct (the linear C and the
    rim element's dashpot), W_dashpot the contact dashpots (exact in harmonics), and
    W_friction the contacts' remaining harmonic work (friction, plus the normal springs'
    AFT sampling error; a condensed surface's nodes likewise, from its marched resultants).
    W_friction_loops is the C core's area of the sampled friction loops (a condensed
    surface's: of its nodes' marched loops): it differs from W_friction by the AFT
    quadrature, O(n_t^-2).
    """
    b, res = hb.basis, hb.residual
    X = x.reshape(hb.nb, hb.ndof)
    e = energy_per_cycle(hb.model, b, X, omega)
    lfs = res.evaluate(x, omega, jac=False)
    w_struct, w_dash, w_fric, w_loops = e["W_visc"], 0.0, 0.0, 0.0
    from ..surface_condensed import CondensedSurface

    for el, lf in zip(res.elements, lfs):
        U = (el.kinematics.operators(b, res.dofs)[0] @ x).reshape(b.nb, el.m)
        w = harmonic_work(U, lf.F, b)
        if isinstance(el, (ContactElement, CondensedSurface)):   # a condensed face: its nodes' friction
            w_dash += lf.W_viscous
            w_fric += w - lf.W_viscous
            w_loops += lf.W - lf.W_viscous
        else:
            w_struct += w
    total = w_struct + w_dash + w_fric
    return {"W_ext": e["W_ext"], "W_struct": w_struct, "W_dashpot": w_dash, "W_friction": w_fric,
            "W_friction_loops": w_loops, "imbalance": (e["W_ext"] - total) / e["W_ext"]}
