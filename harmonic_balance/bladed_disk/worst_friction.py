"""Worst mistuning pattern of the ring with its friction dampers (harmonic balance).

Among the stiffness factors kappa in the box [1 - b, 1 + b]^N_b, the pattern that
maximizes the largest blade peak of the friction-damped ring (R1) of
:mod:`.ring_hb` (Petrov and Ewins 2003 search the worst pattern by the same
sensitivities). The objective is the amplification's numerator::

    a(kappa) = max_j max_omega a_j(x(omega, kappa)),   R(x, omega, kappa) = 0,
    a_j = |first harmonic of blade j's response DOF|

from one ring curve per pattern (:func:`.ring_fast.fast_ring_frf`, or the reference
:func:`.ring_solve.ring_frf`), whose largest peak is refined to the solver's frequency
tolerance: the worst blade j*, its frequency omega* and the solution x*. Its gradient
by the envelope theorem (da_j*/domega = 0 at the refined peak) and one adjoint solve
with the Jacobian J = dR/dx at (x*, omega*)::

    da/dkappa_i = -lambda^T dR/dkappa_i,   J^T lambda = da_j*/dx,
    dR/dkappa_i = P_i (I (x) K0) x*                                             (WF1)

P_i keeping blade i's rows (in (R1) the pattern enters only through the scaled
blockdiag(K0), :mod:`harmonic_balance.bladed_disk.mistuning` (M1)). (WF1) is the derivative wherever the worst
blade and its peak are unique and the contacts' stick-slip pattern does not switch:
the residual is only piecewise smooth in x (friction), so the objective is too, and a
line search may stop on a kink.

The search: L-BFGS-B (bounded quasi-Newton) on a / a_ref from given starts (the
linear limits' worst patterns, :mod:`.worst`, and seeded uniform draws), each
limited to ``max_evaluations`` ring curves. Every evaluated pattern is kept: the best
one found is the result even where the optimizer stops without converging (a kink, a
failed ring solve in its line search); a start whose first pattern does not solve is
skipped with its message.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize
from scipy.sparse.linalg import splu

from ..newton import NewtonError
from .hb import SectorHB
from .mistuning import check_factors
from .ring_hb import MistunedRingHB
from .sector import Sector
from .solve import SolverError

#: Gradient tolerance of L-BFGS-B, relative to the reference peak [1] (the ring's
#: Newton tolerance leaves ~1e-9 noise in a peak).
GTOL = 1e-7
#: Ring curves per start at most (one curve: ~1 s CPU at 4 blades, ~5 s at 24, H = 7).
MAX_EVALUATIONS = 25


class _Unsolved(RuntimeError):
    """A pattern whose ring curve failed (its message)."""


class FrictionPeak:
    """The largest blade peak of the friction-damped ring and its gradient (WF1).

    Parameters
    ----------
    sector : Sector   (N_b = its config's blades)
    band : (lo, hi) [rad/s]  the band of every ring curve
    H : int   highest harmonic
    cf, f0 : float, optional   centrifugal load and EO force amplitude [N] (config)
    start_omega : float, optional   where each curve starts [rad/s] (best: the tuned peak)
    solver : 'fast' or 'full'   :func:`.ring_fast.fast_ring_frf` or :func:`.ring_solve.ring_frf`
    points : int   the full solver's grid points
    """

    def __init__(self, sector: Sector, band, H: int = 7, cf=None, f0=None,
                 start_omega: float | None = None, solver: str = "fast", points: int = 41):
        if solver not in ("fast", "full"):
            raise ValueError(f"solver must be 'fast' or 'full', got {solver!r}")
        self.sector, self.H, self.cf, self.f0 = sector, int(H), cf, f0
        self.band = (float(band[0]), float(band[-1]))
        self.start_omega, self.solver, self.points = start_omega, solver, int(points)
        self.nb = sector.cfg.blades
        self.tuned: SectorHB | None = None
        self.evaluations = 0
        self.best: dict | None = None      # the largest peak met so far (any start)

    def curve(self, kappa):
        """(ring, RingCurve) of the pattern; _Unsolved when its solve fails."""
        from .ring_fast import fast_ring_frf
        from .ring_solve import ring_frf

        kappa = check_factors(kappa, self.nb)
        self.evaluations += 1
        ring = MistunedRingHB(self.sector, kappa, self.H, cf=self.cf, f0=self.f0)
        if self.tuned is None:   # as RingSolver builds it: the ring's H, loads, mu, time grid
            self.tuned = SectorHB(self.sector, ring.H, cf=ring.cf, f0=ring.f0, mu=ring.mu,
                                  n_t=ring.basis.n_t)
        try:
            if self.solver == "fast":
                c = fast_ring_frf(ring, self.band, self.tuned, start_omega=self.start_omega)
            else:
                c = ring_frf(ring, np.linspace(*self.band, self.points), self.tuned,
                             start_omega=self.start_omega)
        except (NewtonError, SolverError, ValueError, ArithmeticError) as err:
            raise _Unsolved(f"{type(err).__name__}: {err}") from None
        if min(c.peak_omega - self.band[0], self.band[1] - c.peak_omega) <= 1e-9 * self.band[1]:
            raise _Unsolved(f"the largest blade peak lies at the band's end "
                            f"{c.peak_omega / 2 / np.pi:.6g} Hz (outside the band)")
        return ring, c

    def value_and_grad(self, kappa) -> tuple[float, np.ndarray]:
        """a(kappa) [m] and da/dkappa (N_b,) [m] by (WF1); _Unsolved on a failed curve."""
        ring, c = self.curve(kappa)
        x, w, j = c.peak_x, c.peak_omega, c.worst
        _, J, _ = ring(x, w)
        n, ndof = ring.sector.n_dof, ring.ndof
        ic, isn = ring.basis.index(1)
        col = ring.sector.response + n * j
        g = np.zeros(ring.size)       # d a_j / dx
        g[ic * ndof + col], g[isn * ndof + col] = x[ic * ndof + col], x[isn * ndof + col]
        g /= max(np.hypot(g[ic * ndof + col], g[isn * ndof + col]), 1e-300)
        try:
            lam = splu(J.T.tocsc(), permc_spec="COLAMD").solve(g)
        except RuntimeError:
            raise _Unsolved("singular Jacobian at the peak (no adjoint)") from None
        blade_of_row = (np.arange(ring.size) % ndof) // n
        grad = -np.bincount(blade_of_row, weights=lam * (ring._K0 @ x), minlength=self.nb)
        a = float(c.peak)
        if self.best is None or a > self.best["peak"]:
            self.best = {"kappa": ring.kappa.copy(), "peak": a, "omega": float(w), "blade": int(j),
                         "peak_per_blade": c.peak_per_blade.copy()}
        return a, grad


def worst_friction_pattern(peak: FrictionPeak, bound: float, starts, scale: float,
                           max_evaluations: int = MAX_EVALUATIONS) -> dict:
    """The factors in [1 - bound, 1 + bound]^N_b maximizing the largest blade peak.

    Parameters
    ----------
    peak : FrictionPeak
    bound : float   the box's half-width (0 < bound < 1)
    starts : list of (label, (N_b,) factors)   the search's starts (clipped to the box)
    scale : float   the reference peak [m] (the objective is a / scale)
    max_evaluations : int   ring curves per start at most

    Returns
    -------
    dict: ``kappa`` (N_b,), ``peak`` [m], ``omega`` [rad/s], ``blade`` (the worst),
    ``peak_per_blade`` (N_b,), the best pattern met by any start; ``starts`` (per start:
    ``label``, ``peak`` (its best, None if its first pattern did not solve), ``converged``,
    ``message``, ``evaluations``), ``converged`` (the start that found the best converged),
    ``message``, ``evaluations``, ``failures`` (patterns whose ring curve failed, with
    messages). RuntimeError when no pattern solved.
    """
    if not (np.isfinite(bound) and 0.0 < bound < 1.0):
        raise ValueError(f"worst-pattern bound {bound}: give 0 < B < 1 (factors within 1 +- B)")
    nb, failures, found = peak.nb, [], []
    box = [(1.0 - bound, 1.0 + bound)] * nb
    for label, x0 in starts:
        x0 = np.clip(np.asarray(x0, dtype=float), 1.0 - bound, 1.0 + bound)
        found.append({"label": label} | _climb(peak, x0, box, scale, max_evaluations, failures))
    if peak.best is None:
        raise RuntimeError("no pattern of the worst-pattern search solved; the first failure: "
                           + (failures[0]["error"] if failures else "none"))
    winner = max((r for r in found if r["peak"] is not None), key=lambda r: r["peak"])
    return peak.best | {"starts": found, "converged": winner["converged"],
                        "message": winner["message"], "evaluations": peak.evaluations,
                        "failures": failures}



def _climb(peak: FrictionPeak, x0, box, scale: float, max_evaluations: int, failures: list) -> dict:
    """One start's L-BFGS-B; its best peak (None if none solved), whether it converged,
    the optimizer's message (or why it stopped), its evaluations. A failed ring curve
    stops the start (appended to ``failures``)."""
    e0, best = peak.evaluations, [-np.inf]

    def fun(k):
        try:
            a, g = peak.value_and_grad(k)
        except _Unsolved as err:
            failures.append({"factors": np.asarray(k).tolist(), "error": str(err)})
            raise
        best[0] = max(best[0], a)
        return -a / scale, -g / scale

    rec = {"converged": False}
    try:
        res = minimize(fun, x0, jac=True, method="L-BFGS-B", bounds=box,
                       options={"gtol": GTOL, "maxfun": max_evaluations, "maxiter": max_evaluations})
        rec |= {"converged": bool(res.success), "message": str(res.message)}
    except _Unsolved as err:
        rec["message"] = f"stopped: a ring curve of its search failed ({err})"
    return rec | {"peak": None if best[0] == -np.inf else float(best[0]),
                  "evaluations": peak.evaluations - e0}

#: Harmonics of the check's second HB solve at the worst peak's frequency (four blades,
#: CF/F0 = 4: the ring's HB within 1 % of its time integration at H = 15, 4 % at H = 7:
#: the truncation; :mod:`tests.upd.test_upd_mistuning`).
CHECK_HARMONICS = 15


def timeint_check(sector: Sector, kappa, omega: float, blade: int, hb_amplitude: float,
                  cf=None, f0=None, check_harmonics: int = CHECK_HARMONICS,
                  max_periods: int = 3000, tol: float = 1e-5) -> dict:
    """The worst pattern's peak against the ring's time integration at its frequency.

    :func:`.timeint.march_ring` of the whole ring with the pattern ``kappa`` at ``omega``
    [rad/s] until settled to ``tol``; its first harmonic of blade ``blade``'s response DOF
    against the HB amplitude ``hb_amplitude`` [m] (the search's H), and against one HB
    solve at ``check_harmonics`` at the same frequency (from the mapped tuned solution,
    :meth:`.ring_solve.RingSolver.tuned_start`), which separates the harmonic truncation
    from any other difference.

    Returns
    -------
    dict: ``timeint_amplitude`` [m], ``rel_diff`` ((timeint - hb) / hb), ``check_harmonics``,
    ``hb_check_amplitude`` [m] (None if that solve failed, ``hb_check_error``),
    ``rel_diff_check``, ``periods``, ``steps_per_period``, ``settled``, ``settle_error``.
    """
    from .ring_solve import RingSolver
    from .timeint import march_ring

    ti = march_ring(sector, [omega], cf=cf, f0=f0, max_periods=max_periods, tol=tol, kappa=kappa)
    a_ti = float(ti["amplitude_blades"][0, blade])
    out = {"timeint_amplitude": a_ti, "rel_diff": a_ti / hb_amplitude - 1.0,
           "periods": int(ti["periods"]), "steps_per_period": int(ti["steps_per_period"]),
           "settled": bool(ti["converged"][0]), "settle_error": float(ti["settle_error"][0]),
           "check_harmonics": int(check_harmonics), "hb_check_amplitude": None,
           "rel_diff_check": None, "hb_check_error": None}
    try:
        ring = MistunedRingHB(sector, kappa, check_harmonics, cf=cf, f0=f0)
        a = float(ring.amplitudes(RingSolver(ring).tuned_start(omega))[blade])
        out |= {"hb_check_amplitude": a, "rel_diff_check": a_ti / a - 1.0}
    except (NewtonError, SolverError) as err:
        out["hb_check_error"] = f"{type(err).__name__}: {err}"
    return out
