"""Fast forced response of the mistuned ring: adaptive continuation, reused factors, Hermite peaks.

The same residual (R1) of :mod:`.ring_hb` and the same tolerance as :mod:`.ring_solve`
(the reference, ``--solver full``), solved with fewer and cheaper Newton steps:

* **Factorizations.** Each Newton step factors its Jacobian (:mod:`.ring_lu`: block
  elimination over the blades with LAPACK on each blade's dense block, single-precision
  factors refined in double, ~6 ms a factorization at 24 blades, H = 7, against ~22 ms
  for SuperLU); the tangent at a
  converged point reuses the last step's factors with iterative refinement instead of
  a factorization of its own.
* **Adaptive continuation in frequency** instead of a fixed grid plus bisection: from
  the tuned peak along both flanks, each step predicted by the parabola through the
  last point with its tangent dx/domega = -J^-1 dR/domega (one more solve at the
  converged point, on the factors of the last Newton step refined iteratively) and
  through the point before (5-10 % fewer Newton iterations than the tangent alone),
  its length set from the predictor's error (the amplitudes' change beyond the
  tangent, :data:`PREDICTOR_ERR`: steps of a fraction of a peak's width where the
  amplitudes bend, long steps on the flanks) and from Newton's iterations.
* **Convergence.** Newton ends at |R| <= tol, as the reference. Between stick-slip
  events the residual is piecewise linear in x and its Jacobian exact, so once the
  events have settled Newton's next step lands below the tolerance at once (from
  ~1e5-1e7 times it). A step short enough to be that last one (:data:`LAND_RTOL`) is
  judged by the residual alone at its end; when it lands, the Jacobian there is the
  one the step was solved with (the step stayed on its linear piece), and the tangent
  is solved on its factors: no evaluation of the Jacobian at the converged point.
* **Per-blade peaks by cubic Hermite interpolation** of every blade's amplitude a_j and
  its exact slope da_j/domega (from the tangent) between the continuation points:
  O(h^4) accurate, with no further solve. The largest of them (the worst blade, the
  amplification) is then polished by a bracketed secant method (Illinois) on
  da_j/domega = 0, each iterate a converged solve, to :data:`~.solve.PEAK_XTOL`
  (the slope is only piecewise smooth -- friction -- so the root stays bracketed);
  every blade's value met on the way raises its peak where larger, a blade whose
  Hermite peak still exceeds the polished one by :data:`HERMITE_RTOL` is polished
  too, the others are capped at it (as the reference's refinement does).

A flank whose step fails at the smallest step length is retried once from the mapped
tuned solution and else ends there (``extra["truncated"]``), with the same rule as the
reference: SolverError when the largest peak lies at such an end.

Symbols: omega [rad/s]; a_j the first-harmonic magnitude of blade j's response DOF [m].
"""
from __future__ import annotations

import time

import numpy as np

from ..newton import STEP_RTOL, NewtonError, line_search
from .hb import SectorHB
from .ring_hb import MistunedRingHB
from .ring_lu import make_factor
from .ring_solve import RingCurve, RingSolver
from .solve import PEAK_XTOL, SolverError, StartError, start_point

#: Iterative refinement of a tangent with the last Newton step's factors (that of a
#: Jacobian one step away): steps, and the relative residual that ends it (else J is
#: factored afresh).
REFINE_STEPS, REFINE_RTOL = 3, 1e-10
#: A Newton step no longer than this (relative to |x|) is expected to land below the
#: tolerance: its end is judged by the residual alone (no Jacobian) and taken when it
#: does (:meth:`FastRingSolver._landed`). On UPD-24 the last steps measured 4e-7 to
#: 3.4e-4 |x|, the steps before them mostly above: ~3 of 4 such guesses land, a miss
#: costs the residual (~40 % of an evaluation with its Jacobian).
LAND_RTOL = 4e-4
#: Newton iterations of a continuation step before the step is shortened.
STEP_ITER = 8
#: Target of the tangent predictor's error, relative to the largest amplitude: the
#: step length h follows from err ~ h^2 a''/2. 0.01 gives steps of ~0.15 of a peak's
#: half-power half-width, where cubic Hermite interpolation is accurate to ~1e-5.
PREDICTOR_ERR = 0.01
#: Initial step and its bounds, as fractions of the band.
STEP_START, STEP_MIN, STEP_MAX = 1.0 / 40, 1.0 / 2000, 1.0 / 8
#: Largest growth of the step from one point to the next.
STEP_GROW = 2.0
#: A blade's Hermite peak above the polished largest by more than this is polished too
#: (else capped at it): Hermite's error at the continuation's steps is ~1e-5.
HERMITE_RTOL = 1e-4
#: Secant iterations of the peak polish.
POLISH_ITER = 8
#: The polish also ends when two successive iterates' amplitudes agree to this
#: (relative): the peak is flat there, its value known to far better than the 1e-3
#: the study needs, and the remaining iterates (each a converged solve) only move the
#: frequency.
POLISH_RTOL = 1e-7


class Factor:
    """Factors of the latest Jacobian (:mod:`.ring_lu`: the pattern's analysis reused).

    Attributes
    ----------
    factorizations, refinements : int   numerical LUs and refinement steps spent
    """

    def __init__(self, backend: str | None = None, blocks: tuple | None = None):
        self.lu = make_factor(backend, blocks)
        self.factorizations = self.refinements = 0
        self.fresh = False

    def solve(self, J, b: np.ndarray) -> np.ndarray:
        """x with J x = b, J factored now; RuntimeError if J is singular."""
        self.lu.factor(J)
        self.factorizations += 1
        return self.lu.solve(b)

    def solve_near(self, J, b: np.ndarray) -> np.ndarray:
        """x with J x = b by iterative refinement on the factors of a nearby Jacobian
        (:data:`REFINE_STEPS`, :data:`REFINE_RTOL`), else J factored."""
        if self.factorizations:
            x = self.lu.solve(b)
            nb = np.linalg.norm(b)
            for _ in range(REFINE_STEPS):
                r = b - J @ x
                if np.linalg.norm(r) <= REFINE_RTOL * nb:
                    return x
                self.refinements += 1
                x = x + self.lu.solve(r)
        return self.solve(J, b)


class FastRingSolver:
    """Newton with reused factors and the tangent of the ring's solution branch.

    Parameters
    ----------
    ring : MistunedRingHB
    tuned : SectorHB, optional   the tuned sector (starts), as :class:`.ring_solve.RingSolver`
    """

    def __init__(self, ring: MistunedRingHB, tuned: SectorHB | None = None):
        self.ring = ring
        self.ref = RingSolver(ring, tuned)   # starts (tuned map, scatter homotopy), tolerance
        self.tol = self.ref.tol
        self.factor = Factor(blocks=(ring.blades, ring.sector.n_dof, ring.nb))
        self.iterations = self.landed = self.missed = 0

    def solve(self, omega: float, x0: np.ndarray, max_iter: int = STEP_ITER):
        """(x, dx/domega) at omega from x0; raises NewtonError."""
        last = {}

        def fun(z):
            R, J, Rw = self.ring(z, omega)
            last.update(J=J, Rw=Rw)
            return R, J

        x = np.array(x0, dtype=float)
        R, J = fun(x)
        nr = _finite_norm(R, x)
        for it in range(max_iter + 1):
            if nr <= self.tol:
                self.iterations += it
                return x, self.tangent(last["J"], last["Rw"])
            if it == max_iter:
                break
            dx = self._step(J, -R, x, it, nr)
            if np.linalg.norm(dx) <= LAND_RTOL * np.linalg.norm(x):
                landed = self._landed(x + dx, omega)
                if landed is not None:
                    self.iterations += it + 1
                    return landed
            if np.linalg.norm(dx) <= STEP_RTOL * np.linalg.norm(x):
                x = x + dx
                R, J = fun(x)
                self.iterations += it + 1
                return x, self.tangent(last["J"], last["Rw"])
            step = line_search(fun, x, dx, nr)
            if step is None:
                raise NewtonError("no decrease along Newton's direction", x, it, nr)
            x, R, J, nr = step
        raise NewtonError(f"no convergence to {self.tol:.1e} within {max_iter} iterations",
                          x, max_iter, nr)

    def _landed(self, x, omega):
        """(x, dx/domega) when x, a Newton step's end, solves the residual to tolerance
        (judged by the residual alone, without its Jacobian), else None.

        The tangent is solved on the factors of the Jacobian the step came from: a step
        that lands below the tolerance from far above it (a small step, |dx| <=
        :data:`LAND_RTOL` |x|, after which the residual fell by about 1e5 or more) moved
        on the linear piece of the residual where that Jacobian is the exact derivative,
        so it is the converged point's Jacobian (module docstring, Convergence)."""
        R, Rw = self.ring(x, omega, jac=False, rate=True)
        if not (np.all(np.isfinite(R)) and np.linalg.norm(R) <= self.tol):
            self.missed += 1
            return None
        self.landed += 1
        return x, self.factor.lu.solve(-Rw)

    def _step(self, J, b, x, it, nr):
        try:
            dx = self.factor.solve(J, b)
        except RuntimeError:
            raise NewtonError("singular Jacobian", x, it, nr) from None
        if not np.all(np.isfinite(dx)):
            raise NewtonError("singular or non-finite Jacobian", x, it, nr)
        return dx

    def tangent(self, J, Rw) -> np.ndarray:
        """dx/domega = -J^-1 dR/domega at a converged point."""
        return self.factor.solve_near(J, -Rw)

    def start(self, omega: float):
        """(x, dx/domega) at omega from the mapped tuned solution, else from the
        reference's start (scatter homotopy, stuck guess)."""
        try:
            return self.restart(omega)
        except (NewtonError, SolverError):
            return self.solve(omega, self.ref.start(omega), 40)

    def restart(self, omega: float):
        """(x, dx/domega) at omega from the mapped tuned solution (past a kink)."""
        x = self.ref.tuned_start_shape(start_point(self.ref.tuned, omega))
        return self.solve(omega, x, 40)


def _finite_norm(R, x):
    if not np.all(np.isfinite(R)):
        raise NewtonError("non-finite residual at the initial guess", x, 0, np.inf)
    return float(np.linalg.norm(R))


class Branch:
    """Converged points of one sweep: omega, x, dx/domega, amplitudes and their slopes."""

    def __init__(self, ring: MistunedRingHB):
        n = ring.sector.n_dof
        self.cols = ring.sector.response + n * np.arange(ring.blades)
        self.ic, self.isn = ring.basis.index(1)
        self.nb, self.ndof = ring.nb, ring.ndof
        self.w, self.x, self.xp, self.a, self.da = [], [], [], [], []

    def amplitude(self, x, xp=None):
        """a (N_b,) and, with xp, da/domega (N_b,)."""
        X = x.reshape(self.nb, self.ndof)
        c, s = X[self.ic, self.cols], X[self.isn, self.cols]
        a = np.hypot(c, s)
        if xp is None:
            return a
        P = xp.reshape(self.nb, self.ndof)
        return a, (c * P[self.ic, self.cols] + s * P[self.isn, self.cols]) / np.maximum(a, 1e-300)

    def add(self, w, x, xp):
        a, da = self.amplitude(x, xp)
        self.w.append(w)
        self.x.append(x)
        self.xp.append(xp)
        self.a.append(a)
        self.da.append(da)
        return a, da


def sweep(solver: FastRingSolver, lo: float, hi: float, w0: float, x0, xp0):
    """Branch of solutions from w0 (x0, xp0) to ``lo`` and to ``hi`` [rad/s];
    (omegas, xs, tangents, a (n, N_b), da (n, N_b), truncation messages)."""
    parts, errors = [], []
    for end in (lo, hi):
        br = Branch(solver.ring)
        br.add(w0, x0, xp0)
        err = _flank(solver, br, end, hi - lo)
        parts.append(br)
        if err:
            errors.append(err)
    down, up = parts
    order = list(range(len(down.w) - 1, -1, -1))
    w = np.array([down.w[i] for i in order] + up.w[1:])
    xs = [down.x[i] for i in order] + up.x[1:]
    xps = [down.xp[i] for i in order] + up.xp[1:]
    a = np.array([down.a[i] for i in order] + up.a[1:])
    da = np.array([down.da[i] for i in order] + up.da[1:])
    return w, xs, xps, a, da, errors


def _flank(solver: FastRingSolver, br: Branch, end: float, band: float) -> str | None:
    """Continue the branch from its last point to ``end``; None or the failure's message."""
    h = STEP_START * band
    sgn = np.sign(end - br.w[-1])
    while sgn * (end - br.w[-1]) > 1e-12 * abs(end):
        w, x, xp = br.w[-1], br.x[-1], br.xp[-1]
        wn = end if sgn * (end - w) <= 1.05 * h else w + sgn * h
        if len(br.w) >= 2:  # Hermite extrapolation: tangent here, value at the previous point
            d = br.w[-2] - w
            c2 = (br.x[-2] - x - d * xp) / (d * d)
            pred = x + (wn - w) * xp + (wn - w) ** 2 * c2
        else:
            pred = x + (wn - w) * xp
        try:
            xn, xpn = solver.solve(wn, pred)
        except NewtonError:
            if h > STEP_MIN * band:
                h *= 0.5
                continue
            try:
                xn, xpn = solver.restart(wn)
            except (NewtonError, SolverError) as err:
                return f"failed at {wn / 2 / np.pi:.6g} Hz ({err})"
        a_pred = br.amplitude(x + (wn - w) * xp)
        a, _ = br.add(wn, xn, xpn)
        err = np.abs(a - a_pred).max() / max(a.max(), 1e-300)
        grow = min(STEP_GROW, 0.9 * np.sqrt(PREDICTOR_ERR / max(err, 1e-12)))
        h = float(np.clip(abs(wn - w) * grow, STEP_MIN * band, STEP_MAX * band))
    return None


def hermite_peaks(w: np.ndarray, a: np.ndarray, da: np.ndarray):
    """Per column of a (n, N_b): the largest value of the piecewise cubic Hermite
    interpolant of (w, a, da) and where; (peaks (N_b,), omegas (N_b,))."""
    h = np.diff(w)[:, None]
    a0, a1, d0, d1 = a[:-1], a[1:], da[:-1] * h, da[1:] * h
    # p(t) = a0 + d0 t + c2 t^2 + c3 t^3 on t in [0, 1]
    c2 = 3 * (a1 - a0) - 2 * d0 - d1
    c3 = 2 * (a0 - a1) + d0 + d1
    best, where = a.max(axis=0).copy(), w[a.argmax(axis=0)].astype(float).copy()
    # roots of p'(t) = d0 + 2 c2 t + 3 c3 t^2
    A, B, C = 3 * c3, 2 * c2, d0
    disc = B * B - 4 * A * C
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        lin = -C / B
        roots = [np.where(np.abs(A) > 1e-14 * (np.abs(B) + np.abs(C)), (-B + s * sq) / (2 * A), lin)
                 for s in (-1.0, 1.0)]
    for t in roots:
        ok = (disc >= 0) & (t > 0) & (t < 1) & np.isfinite(t)
        t = np.where(ok, t, 0.0)
        p = a0 + d0 * t + c2 * t * t + c3 * t ** 3
        p = np.where(ok, p, -np.inf)
        i = p.argmax(axis=0)
        cols = np.arange(a.shape[1])
        up = p[i, cols] > best
        best[up] = p[i, cols][up]
        where[up] = (w[:-1][i] + t[i, cols] * h[i, 0])[up]
    return best, where


def fast_ring_frf(ring: MistunedRingHB, band, tuned: SectorHB | None = None,
                  start_omega: float | None = None, polish: bool = True) -> RingCurve:
    """Response of every blade on the band [lo, hi] [rad/s] and per-blade peaks.

    As :func:`.ring_solve.ring_frf` (same residual, tolerance, start and failure rules)
    with the continuation and peaks of the module docstring. ``omega`` of the result
    are the continuation's points (not a fixed grid).
    """
    t0 = time.perf_counter()
    e0 = ring.evaluations
    lo, hi = float(band[0]), float(band[-1])
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"band {lo} {hi}: give 0 < lo < hi [rad/s]")
    solver = FastRingSolver(ring, tuned)
    w0 = float(np.clip(0.5 * (lo + hi) if start_omega is None else start_omega, lo, hi))
    try:
        x0, xp0 = solver.start(w0)
    except NewtonError as err:
        raise StartError(f"no ring solution at {w0 / 2 / np.pi:.6g} Hz ({err}); start the "
                         "band further from resonance") from None
    w, xs, xps, A, dA, errors = sweep(solver, lo, hi, w0, x0, xp0)
    c = RingCurve(w, A, xs)
    c.extra["tangents"] = xps
    c.extra["truncated"] = errors
    c.peak_per_blade, c.peak_omega_per_blade = hermite_peaks(w, A, dA)
    j = int(c.peak_per_blade.argmax())
    c.worst, c.peak, c.peak_omega = j, float(c.peak_per_blade[j]), float(c.peak_omega_per_blade[j])
    ends = (errors and w[0] > lo and c.peak_omega <= w[0]) or (errors and w[-1] < hi and c.peak_omega >= w[-1])
    if ends:
        raise SolverError(f"the largest blade peak lies at the end of the solved band "
                          f"{w[0] / 2 / np.pi:.6g}-{w[-1] / 2 / np.pi:.6g} Hz: the sweep "
                          f"{'; '.join(errors)}")
    if polish:
        _polish_largest(solver, c, dA)
    c.evaluations, c.newton_iterations = ring.evaluations - e0, solver.iterations
    c.extra |= {"factorizations": solver.factor.factorizations,
                "refinements": solver.factor.refinements, "landed": solver.landed,
                "fallbacks": getattr(solver.factor.lu, "fallbacks", 0),
                "missed": solver.missed,
                "points": int(w.size)}
    c.time_s = time.perf_counter() - t0
    return c


def _polish_largest(solver: FastRingSolver, c: RingCurve, dA: np.ndarray) -> None:
    """Polish the largest Hermite peak; again any other blade's that still exceeds the
    polished largest by more than :data:`HERMITE_RTOL`; the others are capped at it
    (an interpolant's overshoot), as the reference caps its parabolas."""
    done, best = set(), -np.inf
    while True:
        rest = [j for j in np.argsort(-c.peak_per_blade) if j not in done]
        if not rest or (done and c.peak_per_blade[rest[0]] <= best * (1 + HERMITE_RTOL)):
            break
        c.worst = int(rest[0])
        c.peak, c.peak_omega = float(c.peak_per_blade[c.worst]), float(c.peak_omega_per_blade[c.worst])
        val, wk, xk = _polish(solver, c, dA)
        done.add(c.worst)
        if val > best:
            best, w_best, x_best, j_best = val, wk, xk, c.worst
    c.peak_per_blade = np.minimum(c.peak_per_blade, best)
    # the polished blade, not the first of those capped to its value: their frequencies
    # are the Hermite interpolants', known less well than the values on a flat top
    c.worst = j_best
    c.peak, c.peak_omega, c.peak_x = float(best), w_best, x_best


def _polish(solver: FastRingSolver, c: RingCurve, dA: np.ndarray):
    """Blade ``c.worst``'s peak by a bracketed secant method on da_j/domega = 0 from its
    Hermite estimate (module docstring); values met raise the per-blade peaks.
    Returns the polished (peak [m], omega, x)."""
    w, j = c.omega, c.worst
    if c.peak_omega <= w[0] or c.peak_omega >= w[-1]:
        k = int(np.argmin(np.abs(w - c.peak_omega)))
        return float(c.amplitude[k, j]), float(w[k]), c.x[k]
    br = Branch(solver.ring)
    i = int(np.clip(np.searchsorted(w, c.peak_omega), 1, w.size - 1))
    (lo, glo), (hi, ghi) = (w[i - 1], dA[i - 1, j]), (w[i], dA[i, j])
    wk, met, side = c.peak_omega, [], 0
    for _ in range(POLISH_ITER):
        k = int(np.argmin(np.abs(w - wk)))
        try:
            x, xp = solver.solve(wk, c.x[k] + (wk - w[k]) * c.extra["tangents"][k], 40)
        except NewtonError as err:
            raise SolverError(f"peak refinement near {wk / 2 / np.pi:.6g} Hz failed ({err}); "
                              "use a finer continuation") from None
        a, da = br.amplitude(x, xp)
        met.append((wk, x, a))
        g = da[j]
        # Illinois (bracketed secant) on da_j/domega = 0: keep g(lo) > 0 > g(hi)
        if g > 0:
            lo, glo = wk, g
            ghi, side = (0.5 * ghi if side == 1 else ghi), 1
        else:
            hi, ghi = wk, g
            glo, side = (0.5 * glo if side == -1 else glo), -1
        if hi - lo <= PEAK_XTOL * wk or not (glo > 0 > ghi):
            break
        if len(met) >= 2 and abs(a[j] - met[-2][2][j]) <= POLISH_RTOL * a[j]:
            break
        wk = lo + (hi - lo) * glo / (glo - ghi)
    wk, xk, ak = max(met, key=lambda m: m[2][j])
    c.peak_per_blade[j], c.peak_omega_per_blade[j] = float(ak[j]), wk
    for wm, _, am in met:
        up = am > c.peak_per_blade
        c.peak_per_blade[up], c.peak_omega_per_blade[up] = am[up], wm
    return float(ak[j]), wk, xk
