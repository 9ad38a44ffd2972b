"""Forced response of the mistuned ring: sparse Newton, frequency sweep, per-blade peaks.

Newton's method on (R1) of :mod:`.ring_hb` with a sparse LU (SuperLU, COLAMD column
order) of the block-banded Jacobian, an Armijo line search and a Levenberg-Marquardt
fallback (as :mod:`..newton`, whose dense algebra would cost O(N_b^3)).

Starts: the tuned cyclic sector's solution at the same frequency mapped onto the ring
(blade j = blade 0 advanced by j phi, the mean moved to the ring's own prestress
state); where Newton fails from it, a homotopy in the scatter (the pattern scaled
from 0 to 1, :meth:`.ring_hb.MistunedRingHB.set_scale`).

Sweep: from the grid point nearest the tuned peak (the dampers slip there and the
start converges) along both flanks with a secant predictor, a failed step bisected
(as the sector's :func:`.solve.sweep`), then tried once from the mapped tuned solution. At
low amplitude on a flank the contacts are stuck with their sliders grazing the slip
limit at single samples (the loop placement of the C core, :mod:`..contact`): the
residual is then only piecewise smooth in many contacts at once and Newton can stall;
such a flank ends there (reported), the curve keeps the solved part.

Grid: the given one (best no coarser than the narrowest half-power width of the tuned
ring's modes, :func:`resolving_points`), then bisected around every blade's local
maxima until the parabola through each predicts the cells' midpoints (:func:`resolve`):
a narrow, lightly damped resonance between two grid points is resolved there only.

Peaks: every blade's first-harmonic amplitude of its response DOF on the grid; each
blade's peak from the parabolas through each local maximum of its grid values and the
two neighbours (the largest vertex); the largest over blades and frequency refined by Brent's bounded search (each
evaluation a Newton solve), which gives the worst blade and the amplification factor.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import minimize_scalar
from scipy.sparse.linalg import splu

from ..newton import LM_ACCEPT, LM_MU_MAX, LM_TRIALS, STEP_RTOL, NewtonError, line_search
from .hb import SectorHB
from .ring_hb import MistunedRingHB
from .solve import PEAK_XTOL, TOL_REL, SolverError, StartError, start_point


@dataclass
class RingCurve:
    """Response curve of the ring (SI units; omega in rad/s).

    Attributes
    ----------
    omega : (n_f,) array          frequencies of the points
    amplitude : (n_f, N_b) array  first-harmonic |u| of every blade's response DOF [m]
    peak_per_blade : (N_b,) array peak amplitude of each blade [m]
    peak_omega_per_blade : (N_b,) array
    worst : int                   blade with the largest peak
    peak, peak_omega : float      its refined peak [m] and frequency
    peak_x : (size,) array        solution at that peak
    """

    omega: np.ndarray
    amplitude: np.ndarray
    x: list
    peak_per_blade: np.ndarray = None
    peak_omega_per_blade: np.ndarray = None
    worst: int = 0
    peak: float = float("nan")
    peak_omega: float = float("nan")
    peak_x: np.ndarray | None = None
    evaluations: int = 0
    newton_iterations: int = 0
    time_s: float = 0.0
    extra: dict = field(default_factory=dict)


def tolerance(ring: MistunedRingHB) -> float:
    """|R| tolerance: the sector's (TOL_REL max(F0, CF)) per blade, in the 2-norm."""
    return TOL_REL * max(ring.f0, ring.cf) * np.sqrt(ring.blades)


def newton_sparse(fun, x0: np.ndarray, tol: float, max_iter: int = 40, lm: bool = True):
    """Newton with a sparse LU, an Armijo line search and a Levenberg-Marquardt fallback;
    (x, iterations).

    ``fun(x) -> (R, J)`` with J scipy-sparse. As :func:`..newton.newton` with sparse
    algebra: where the line search stalls (a kink of the piecewise-smooth friction
    residual) Levenberg-Marquardt steps ``(J^T J + mu D) p = -J^T R`` (D the running
    maximum of J's squared column norms) decrease |R| until Newton takes over again.
    Stops at |R| <= tol or when the step is below STEP_RTOL |x| (round-off floor).
    ``lm=False``: fail at once where the line search stalls (a sweep step is then bisected,
    which is cheaper).

    Raises
    ------
    NewtonError : singular Jacobian, no decrease by either step, iterations.
    """
    x = np.array(x0, dtype=float)
    R, J = fun(x)
    nr = _norm(R, x)
    damped = _LM()
    for it in range(max_iter + 1):
        if nr <= tol:
            return x, it
        if it == max_iter:
            break
        try:
            dx = splu(J.tocsc(), permc_spec="COLAMD").solve(-R)
        except RuntimeError:
            raise NewtonError("singular Jacobian", x, it, nr) from None
        if not np.all(np.isfinite(dx)):
            raise NewtonError("singular or non-finite Jacobian", x, it, nr)
        if np.linalg.norm(dx) <= STEP_RTOL * np.linalg.norm(x):
            return x + dx, it + 1
        step = line_search(fun, x, dx, nr) or (lm and damped.step(fun, x, R, J, nr))
        if not step:
            raise NewtonError("no decrease, neither along Newton's direction nor by "
                              "Levenberg-Marquardt steps" if lm else "no decrease along "
                              "Newton's direction", x, it, nr)
        x, R, J, nr = step
    raise NewtonError(f"no convergence to {tol:.1e} within {max_iter} iterations", x, max_iter, nr)


class _LM:
    """Levenberg-Marquardt steps with Nielsen's damping update (:mod:`..newton`), sparse."""

    def __init__(self):
        self.mu, self.nu, self.d2 = 1e-3, 2.0, None

    def step(self, fun, x, R, J, nr):
        g = J.T @ R
        A = (J.T @ J).tocsc()
        d2 = A.diagonal()
        self.d2 = d2 if self.d2 is None else np.maximum(self.d2, d2)
        D = sp.diags(np.maximum(self.d2, 1e-300 * max(self.d2.max(), 1e-300)))
        for _ in range(LM_TRIALS):
            try:
                p = splu((A + self.mu * D).tocsc()).solve(-g)
            except RuntimeError:
                p = None
            if p is not None and np.all(np.isfinite(p)):
                Rt, Jt = fun(x + p)
                nt = np.linalg.norm(Rt) if np.all(np.isfinite(Rt)) else np.inf
                pred = -(p @ g) - 0.5 * (p @ (A @ p))
                rho = (0.5 * nr**2 - 0.5 * nt**2) / pred if pred > 0 else -1.0
                if rho > LM_ACCEPT:
                    self.mu *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                    self.nu = 2.0
                    return x + p, Rt, Jt, nt
            self.mu *= self.nu
            self.nu *= 2.0
            if self.mu > LM_MU_MAX:
                break
        self.mu, self.nu = 1e-3, 2.0
        return None


def _norm(R, x):
    if not np.all(np.isfinite(R)):
        raise NewtonError("non-finite residual at the initial guess", x, 0, np.inf)
    return float(np.linalg.norm(R))


#: Bisection levels of a failed sweep step (2^-4 of a grid step; each failed level costs
#: a Newton solve's iteration limit).
BISECT = 4
#: Newton iterations of a sweep step before it is bisected.
STEP_ITER = 15
#: Steps of the scatter homotopy from the tuned ring (:meth:`RingSolver.tuned_start`).
HOMOTOPY_STEPS = 4


class RingSolver:
    """Solves the ring at frequencies; keeps the tuned sector for starts.

    Parameters
    ----------
    ring : MistunedRingHB
    tuned : SectorHB, optional   the tuned sector with the same H, CF, F0, mu, n_t
        (built when None); its solutions map onto the ring as starts.
    """

    def __init__(self, ring: MistunedRingHB, tuned: SectorHB | None = None):
        self.ring = ring
        self.tuned = tuned or SectorHB(ring.sector, ring.H, cf=ring.cf, f0=ring.f0, mu=ring.mu,
                                       n_t=ring.basis.n_t)
        self.tol = tolerance(ring)
        self.iterations = 0

    def solve(self, omega: float, x0: np.ndarray, max_iter: int = 40, lm: bool = True) -> np.ndarray:
        """Newton solve at one frequency; raises NewtonError."""
        x, it = newton_sparse(lambda z: self.ring(z, omega)[:2], x0, self.tol, max_iter, lm)
        self.iterations += it
        return x

    def tuned_start(self, omega: float) -> np.ndarray:
        """Ring solution at omega from the tuned sector's: mapped onto the ring, then
        Newton; when that fails, a homotopy in the scatter (kappa(lam) = 1 + lam (kappa - 1),
        lam = 0 -> 1 in :data:`HOMOTOPY_STEPS` steps, each bisected on failure)."""
        x = self.tuned_start_shape(start_point(self.tuned, omega))
        try:
            return self.solve(omega, x, 80)
        except NewtonError:
            pass
        try:
            self.ring.set_scale(0.0)
            x, done = self.solve(omega, x, 80), 0.0
            for target in np.linspace(0.0, 1.0, HOMOTOPY_STEPS + 1)[1:]:
                x, done = self._ramp(omega, x, done, target), target
        finally:
            self.ring.set_scale(1.0)
        return x

    def _ramp(self, omega, x, a, b, depth=0):
        """Solution at scatter scale b from the one at a (bisection on failure)."""
        self.ring.set_scale(b)
        try:
            return self.solve(omega, x)
        except NewtonError:
            if depth >= BISECT:
                raise
        m = 0.5 * (a + b)
        xm = self._ramp(omega, x, a, m, depth + 1)
        return self._ramp(omega, xm, m, b, depth + 1)

    def tuned_start_shape(self, x_sector: np.ndarray) -> np.ndarray:
        """Ring unknowns of a tuned sector solution with the ring's own prestress mean."""
        ring = self.ring
        x = ring.from_sector(x_sector).reshape(ring.nb, ring.ndof)
        x[ring.basis.index(0)[0]] += ring.x_static - np.tile(self.tuned.x_static, ring.blades)
        return x.ravel()

    def start(self, omega: float) -> np.ndarray:
        """Solution at omega from the tuned start, else from the stuck linear guess."""
        try:
            return self.tuned_start(omega)
        except (NewtonError, SolverError):
            pass
        try:
            return self.solve(omega, self.ring.stuck_guess(omega), 80)
        except NewtonError as err:
            raise StartError(f"no ring solution at {omega / 2 / np.pi:.6g} Hz ({err}); start "
                             "the band further from resonance") from None

    def step(self, w_a, x_a, dxdw, w_b, depth=0):
        """Solution at w_b from (w_a, x_a) with slope dxdw; bisects on failure (at most
        :data:`BISECT` levels; Newton without Levenberg-Marquardt, :data:`STEP_ITER`
        iterations: a failing step costs little)."""
        try:
            return self.solve(w_b, x_a + (w_b - w_a) * dxdw, STEP_ITER, lm=False)
        except NewtonError:
            if depth >= BISECT:
                raise
        w_m = 0.5 * (w_a + w_b)
        x_m = self.step(w_a, x_a, dxdw, w_m, depth + 1)
        return self.step(w_m, x_m, (x_m - x_a) / (w_m - w_a), w_b, depth + 1)

    def flank(self, omegas, x0: np.ndarray):
        """Solutions from omegas[0] (solution x0) along the grid ``omegas`` until the end or
        the first point that fails; (solutions, None or the failure's message)."""
        xs, slope = [x0], np.zeros_like(x0)
        for k in range(1, len(omegas)):
            try:
                x = self.step(omegas[k - 1], xs[-1], slope, omegas[k])
            except NewtonError:
                try:  # a kink the bisection cannot pass: once from the mapped tuned solution
                    x = self.solve(omegas[k], self.tuned_start_shape(start_point(self.tuned, omegas[k])))
                except (NewtonError, SolverError) as err:
                    return xs, f"failed at {omegas[k] / 2 / np.pi:.6g} Hz ({err})"
            slope = (x - xs[-1]) / (omegas[k] - omegas[k - 1])
            xs.append(x)
        return xs, None

    def at(self, omega: float, omegas, xs) -> np.ndarray:
        """Solution at omega from the nearest grid solutions (secant start)."""
        i = int(np.clip(np.searchsorted(omegas, omega), 1, len(omegas) - 1))
        slope = (xs[i] - xs[i - 1]) / (omegas[i] - omegas[i - 1])
        try:
            return self.solve(omega, xs[i - 1] + (omega - omegas[i - 1]) * slope)
        except NewtonError:
            return self.step(omegas[i - 1], xs[i - 1], slope, omega)


def _vertex(w: np.ndarray, a: np.ndarray):
    """(frequency, value) of the parabola through three points (w, a) at a local maximum
    a[1], its vertex kept inside them and not below a[1]; None when it opens upwards."""
    c2, c1, c0 = np.polyfit(w - w[1], a, 2)
    if c2 >= 0:
        return None
    d = np.clip(-c1 / (2 * c2), w[0] - w[1], w[2] - w[1])
    return w[1] + d, max(c0 + c1 * d + c2 * d * d, a[1])


def _local_maxima(col: np.ndarray) -> np.ndarray:
    """Interior grid indices i with col[i] >= both neighbours."""
    return np.flatnonzero((col[1:-1] >= col[:-2]) & (col[1:-1] >= col[2:])) + 1


def parabola_peaks(omegas: np.ndarray, A: np.ndarray):
    """Per column of A (n_f, N_b): the largest vertex of the parabolas through each local
    maximum of the grid and its neighbours (kept inside them), or the grid maximum when
    that is larger (a mistuned blade has several close peaks; the grid's largest value
    need not be the highest peak); (peaks, omegas)."""
    nf, nb = A.shape
    pk, wk = A.max(axis=0).copy(), omegas[A.argmax(axis=0)].copy()
    for j in range(nb):
        col = A[:, j]
        for i in _local_maxima(col):
            v = _vertex(omegas[i - 1:i + 2], col[i - 1:i + 2])
            if v is not None and v[1] > pk[j]:
                wk[j], pk[j] = v
    return pk, wk


#: Relative accuracy to which :func:`resolve` resolves each blade's peaks: a local maximum
#: is resolved when the parabola through it and its two neighbours predicts the midpoints
#: of both cells to this fraction of its value (its vertex is then about as accurate).
RESOLVE_RTOL = 1e-4
#: Bisection levels of :func:`resolve` (cells down to 2^-6 of the grid step).
RESOLVE_LEVELS = 6
#: Local maxima of a blade below this fraction of its highest parabola estimate are not
#: resolved (they cannot be its peak): a parabola through a resonance sampled at its
#: half-power width is off by at most 25 % (Lorentzian shape), so 0.7 keeps every
#: candidate on a grid of that spacing.
RESOLVE_CANDIDATE = 0.7


def resolve(solver: RingSolver, omegas, xs: list, A: np.ndarray, rtol: float = RESOLVE_RTOL,
            levels: int = RESOLVE_LEVELS):
    """The solved grid refined where a blade's peak is not resolved (the per-blade peaks'
    accuracy of a reference).

    Each level bisects both cells beside every candidate local maximum of any blade
    (:data:`RESOLVE_CANDIDATE`) not yet resolved (:data:`RESOLVE_RTOL`); each midpoint is a
    Newton solve from its grid neighbours (:meth:`RingSolver.at`). A narrow resonance
    (a lightly damped mode the friction does not reach) that a grid step straddles is
    thus refined until its parabola estimate holds, while the flanks keep the grid.

    Returns
    -------
    omegas : (n_f',) array, xs : list of (size,) arrays, A : (n_f', N_b) array
        the refined grid, solutions and amplitudes [m]
    record : dict
        ``added`` (points solved), ``levels`` (used), ``unresolved`` (frequencies [rad/s]
        of local maxima still unresolved at the last level)
    """
    omegas, xs, A = np.asarray(omegas, float), list(xs), np.asarray(A, float)
    done, added, level, todo = [], 0, 0, []
    for level in range(levels + 1):
        todo = _unresolved(omegas, A, done)
        if not todo or level == levels:
            break
        cells = sorted({c for _, i in todo for c in (i - 1, i)})
        mids = 0.5 * (omegas[cells] + omegas[np.add(cells, 1)])
        try:
            new = [solver.at(w, omegas, xs) for w in mids]
        except (NewtonError, SolverError) as err:
            raise SolverError(f"grid refinement near {mids[0] / 2 / np.pi:.6g} Hz failed ({err}); "
                              "use more points") from None
        An = np.array([solver.ring.amplitudes(x) for x in new])
        done += _checked(omegas, A, todo, dict(zip(mids, An)), rtol)
        order = np.argsort(np.concatenate([omegas, mids]), kind="stable")
        omegas = np.concatenate([omegas, mids])[order]
        xs = [(xs + new)[k] for k in order]
        A = np.vstack([A, An])[order]
        added += len(new)
    return omegas, xs, A, {"added": added, "levels": level,
                           "unresolved": [float(omegas[i]) for _, i in todo]}


def _unresolved(omegas, A, done) -> list:
    """(blade, index) of every candidate local maximum not inside a resolved interval of
    that blade (``done``: (blade, lo, hi) [rad/s])."""
    todo = []
    best = parabola_peaks(omegas, A)[0]
    for j in range(A.shape[1]):
        col = A[:, j]
        for i in _local_maxima(col):
            v = _vertex(omegas[i - 1:i + 2], col[i - 1:i + 2])
            if max(col[i], v[1] if v else 0.0) < RESOLVE_CANDIDATE * best[j]:
                continue
            if not any(b == j and lo <= omegas[i] <= hi for b, lo, hi in done):
                todo.append((j, int(i)))
    return todo


def _checked(omegas, A, todo, at_mid: dict, rtol: float) -> list:
    """Resolved intervals (blade, lo, hi) among ``todo``: the parabola through the local
    maximum and its neighbours predicts the solved midpoints ``at_mid`` (frequency ->
    amplitudes (N_b,)) of both cells within ``rtol`` of the maximum."""
    out = []
    for j, i in todo:
        w, a = omegas[i - 1:i + 2], A[i - 1:i + 2, j]
        coef = np.polyfit(w - w[1], a, 2)
        err = max(abs(np.polyval(coef, m - w[1]) - at_mid[m][j])
                  for m in (0.5 * (w[0] + w[1]), 0.5 * (w[1] + w[2])))
        if err <= rtol * a[1]:
            out.append((j, float(w[0]), float(w[2])))
    return out


def ring_frf(ring: MistunedRingHB, omegas, tuned: SectorHB | None = None,
             start_omega: float | None = None, refine: bool = True,
             resolve_rtol: float | None = RESOLVE_RTOL) -> RingCurve:
    """Response curve of every blade on the grid ``omegas`` [rad/s] with per-blade peaks.

    Solved first at the grid point nearest ``start_omega`` (default: the band's middle;
    best the tuned peak, where the dampers slip and the start converges), then along
    both flanks. A flank that fails ends the curve there (``extra["truncated"]``);
    SolverError when the largest peak lies at such an end (not resolved). The grid is
    then refined around every blade's unresolved peaks (:func:`resolve`, to
    ``resolve_rtol``; None: the grid as given; ``extra["resolve"]`` its record): give a
    grid no coarser than the narrowest resonance's half-power width
    (:func:`resolving_points`), so that none is stepped over unseen.
    """
    t0 = time.perf_counter()
    e0 = ring.evaluations
    solver = RingSolver(ring, tuned)
    omegas = np.asarray(omegas, dtype=float)
    if omegas.size < 3 or np.any(np.diff(omegas) <= 0):
        raise ValueError("the frequency grid needs >= 3 increasing points")
    i0 = omegas.size // 2 if start_omega is None else int(np.argmin(np.abs(omegas - start_omega)))
    x0 = solver.start(omegas[i0])
    down, err_d = solver.flank(omegas[i0::-1], x0)
    up, err_u = solver.flank(omegas[i0:], x0)
    lo = i0 - len(down) + 1
    lam, xs = omegas[lo:i0 + len(up)], down[::-1] + up[1:]
    A = np.array([ring.amplitudes(x) for x in xs])
    g = A.max(axis=1)
    i = int(g.argmax())
    if (i == 0 and err_d) or (i == lam.size - 1 and err_u):
        raise SolverError(f"the largest blade peak lies at the end of the solved band "
                          f"{lam[0] / 2 / np.pi:.6g}-{lam[-1] / 2 / np.pi:.6g} Hz: the sweep "
                          f"{(err_d if i == 0 else err_u)}")
    record = None
    if resolve_rtol is not None:
        lam, xs, A, record = resolve(solver, lam, xs, A, resolve_rtol)
    c = RingCurve(lam, A, xs)
    c.extra["truncated"] = [e for e in (err_d, err_u) if e]
    c.extra["resolve"] = record
    c.peak_per_blade, c.peak_omega_per_blade = parabola_peaks(lam, A)
    g = A.max(axis=1)
    i = int(g.argmax())
    c.worst, c.peak, c.peak_omega, c.peak_x = int(A[i].argmax()), float(g[i]), float(lam[i]), xs[i]
    if refine:
        _refine(solver, c, A)
    c.evaluations, c.newton_iterations = ring.evaluations - e0, solver.iterations
    c.time_s = time.perf_counter() - t0
    return c


#: Grid points per narrowest half-power width (:func:`resolving_points`): one puts a point
#: within half a width of every resonance's peak, at >= 1/sqrt(2) of it, so each shows as
#: a local maximum (or a shoulder on a larger one) that :func:`resolve` then refines.
POINTS_PER_WIDTH = 1.0


def half_power_width(sector, lo: float, hi: float) -> float | None:
    """Narrowest half-power width [rad/s] of the tuned ring's modes with natural
    frequencies in [lo, hi] [rad/s], damper stuck and free (the linear limits that bound the
    friction-damped ring's damping from below); None when no mode lies there.

    For a mass-normalized mode phi_r the half-power width is 2 zeta_r omega_r =
    phi_r^T C phi_r (light damping, the modal damping of the ring's C). Dense eigenproblem
    of the tuned ring (n N_b unknowns, a few hundred).
    """
    from scipy.linalg import eigh

    from .mistuning import LinearRing

    widths = []
    for damper in ("stuck", "free"):
        r = LinearRing(sector, np.ones(sector.cfg.blades), damper)
        _, V = eigh(r.K.toarray(), r.M.toarray(), subset_by_value=(lo * lo, hi * hi))
        widths += list(np.einsum("ir,ij,jr->r", V, r.C.toarray(), V))
    return float(min(widths)) if widths else None


def resolving_points(sector, lo: float, hi: float, points: int) -> int:
    """Points of a uniform grid on [lo, hi] [rad/s]: at least ``points``, and no coarser
    than :data:`POINTS_PER_WIDTH` per narrowest half-power width (:func:`half_power_width`)."""
    width = half_power_width(sector, lo, hi)
    if width is None or width <= 0:
        return int(points)
    return max(int(points), int(np.ceil(POINTS_PER_WIDTH * (hi - lo) / width)) + 1)


def _refine(solver: RingSolver, c: RingCurve, A: np.ndarray) -> None:
    """Largest amplitude over blades and frequency, g(omega) = max_j a_j(omega), by Brent's
    search between the grid neighbours of the largest blade's parabola estimate; again
    around the estimate of any blade that still exceeds the refined peak. Per-blade peaks are
    then capped at the refined peak and raised to the exact values met on the way."""
    ring, nf, seen, met = solver.ring, c.omega.size, set(), {}

    def neg(w):
        x = solver.at(w, c.omega, c.x)
        met[w] = (x, ring.amplitudes(x))
        return -met[w][1].max()

    # the grid point nearest each blade's parabola vertex: its two cells hold the vertex
    cell = [int(np.argmin(np.abs(c.omega - w))) for w in c.peak_omega_per_blade]
    best = -np.inf
    while True:
        todo = [j for j in np.argsort(-c.peak_per_blade) if cell[j] not in seen]
        if not todo or (best > -np.inf and c.peak_per_blade[todo[0]] <= best):
            break
        i = cell[todo[0]]
        seen.add(i)
        if not 0 < i < nf - 1:
            w, val = c.omega[i], A[i].max()
            met.setdefault(w, (c.x[i], A[i]))
        else:
            try:
                res = minimize_scalar(neg, bounds=(c.omega[i - 1], c.omega[i + 1]), method="bounded",
                                      options={"xatol": PEAK_XTOL * c.omega[i]})
            except (NewtonError, SolverError) as err:
                raise SolverError(f"peak refinement near {c.omega[i] / 2 / np.pi:.6g} Hz failed "
                                  f"({err}); use more points") from None
            w, val = float(res.x), -float(res.fun)
            if w not in met:
                neg(w)
        if val > best:
            best = val
            c.peak_omega, c.peak_x = w, met[w][0]
            c.worst, c.peak = int(met[w][1].argmax()), float(met[w][1].max())
    c.peak_per_blade = np.minimum(c.peak_per_blade, c.peak)
    for w, (_, a) in met.items():
        up = a > c.peak_per_blade
        c.peak_per_blade[up], c.peak_omega_per_blade[up] = a[up], w
    c.peak_omega_per_blade[c.worst] = c.peak_omega
