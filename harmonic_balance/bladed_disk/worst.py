"""Worst mistuning pattern of the linear ring (damper free or stuck).

Among the stiffness factors kappa in the box [1 - b, 1 + b]^N_b, the pattern that
maximizes the largest blade peak (Petrov and Ewins 2003 for the search by sensitivities).
Every blade is equivalent -- rotating a pattern by one blade rotates the response and
advances its phase by phi -- so the search maximizes blade 0's peak, a smooth function
of kappa wherever its peak frequency is unique.

Peak of blade 0 (response DOF r, ring (M2) of :mod:`harmonic_balance.bladed_disk.mistuning`)::

    a(kappa) = max_omega |u_r(omega, kappa)|,   Z(omega, kappa) u = F,
    Z = K_tuned + sum_i (kappa_i - 1) K0_i - omega^2 M + i omega C

on the band's grid, then Brent's search between the neighbours of the grid maximum, both
on the ring's complex modes (one eigendecomposition per pattern).
Its gradient by the envelope theorem (omega* stationary) and one adjoint solve
(Z is complex symmetric: Z^T = Z)::

    da/dkappa_i = Re(conj(u_r) du_r/dkappa_i) / a,   du_r/dkappa_i = -lambda^T K0_i u,
    Z^T lambda = e_r                                                            (W1)

The search: L-BFGS-B (bounded quasi-Newton) from several starts, the best kept: all
factors 1 - b/2, all 1 + b/2 (a common shift moves the resonance, and with damping that
does not scale with kappa its peak), 1 +- b/2 alternating, and seeded uniform draws in
the box. The peak is multimodal in kappa (localisation on different blades' modes), so
the starts matter: on four blades 16 starts reach differential evolution's optimum.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize, minimize_scalar

from .mistuning import blade_stiffness, check_factors, ring_forcing, ring_linear
from .sector import Sector

#: Relative frequency tolerance of a peak search.
PEAK_XTOL = 1e-10
#: Gradient tolerance of L-BFGS-B, relative to the tuned peak [1].
GTOL = 1e-9


class LinearPeak:
    """Blade 0's peak of the linear mistuned ring and its gradient in the factors.

    Parameters
    ----------
    sector : Sector   (N_b = its config's blades)
    damper : 'free' or 'stuck'
    omegas : (n_f,) grid of the band [rad/s]
    f0 : float, optional   EO force amplitude [N]
    """

    def __init__(self, sector: Sector, damper: str, omegas, f0: float | None = None):
        if damper not in ("free", "stuck"):
            raise ValueError(f"the worst-pattern search takes --damper free or stuck, got {damper!r}")
        nb = sector.cfg.blades
        self.nb, self.omegas = nb, np.asarray(omegas, dtype=float)
        M, K, C = ring_linear(sector, np.ones(nb), damper)
        self.M, self.K, self.C = M.toarray(), K.toarray(), C.toarray()
        self.n = self.M.shape[0] // nb
        self.K0 = blade_stiffness(sector, nb, damper == "free").toarray()[:self.n, :self.n]
        f0 = sector.cfg.f0 if f0 is None else float(f0)
        self.F = ring_forcing(sector, nb, self.n, f0)
        self.r = sector.response
        self.evaluations = 0

    def _K(self, kappa) -> np.ndarray:
        K = self.K.copy()
        for i, k in enumerate(kappa):
            s = slice(self.n * i, self.n * (i + 1))
            K[s, s] += (k - 1.0) * self.K0
        return K

    def _Z(self, kappa, w):
        return self._K(kappa) - w * w * self.M + 1j * w * self.C

    def modal(self, kappa):
        """Poles lambda (2n,) and residues c (2n,) of u_r(omega) = sum_k c_k / (i omega -
        lambda_k): the first-order form A z' = B z + [F, 0], A = [[C, M], [M, 0]],
        B = [[-K, 0], [0, M]] (as :func:`.sector.modal_response`), one eigendecomposition
        per pattern, so a peak search costs no further solve."""
        n = self.M.shape[0]
        Z0 = np.zeros((n, n))
        A = np.block([[self.C, self.M], [self.M, Z0]])
        B = np.block([[-self._K(kappa), Z0], [Z0, self.M]])
        lam, V = np.linalg.eig(np.linalg.solve(A, B))
        g = np.linalg.solve(V, np.linalg.solve(A, np.concatenate([self.F, np.zeros(n)])))
        return lam, V[self.r] * g

    def peak(self, kappa) -> tuple[float, float]:
        """(a [m], omega* [rad/s]) of blade 0: the largest of the band's grid, then Brent's
        search between its neighbours, both on the modal form."""
        kappa = check_factors(kappa, self.nb)
        self.evaluations += 1
        lam, c = self.modal(kappa)

        def amp(w):
            return np.abs((c / (1j * np.asarray(w, dtype=float)[..., None] - lam)).sum(axis=-1))

        A = amp(self.omegas)
        i = int(A.argmax())
        if not 0 < i < A.size - 1:
            return float(A[i]), float(self.omegas[i])
        res = minimize_scalar(lambda w: -float(amp(w)),
                              bounds=(self.omegas[i - 1], self.omegas[i + 1]), method="bounded",
                              options={"xatol": PEAK_XTOL * self.omegas[i]})
        return (-float(res.fun), float(res.x)) if -res.fun > A[i] else (float(A[i]), float(self.omegas[i]))

    def value_and_grad(self, kappa) -> tuple[float, np.ndarray]:
        """a(kappa) [m] and da/dkappa (N_b,) [m] by (W1)."""
        a, w = self.peak(kappa)
        Z = self._Z(kappa, w)
        u = np.linalg.solve(Z, self.F)
        e = np.zeros(Z.shape[0])
        e[self.r] = 1.0
        lam = np.linalg.solve(Z.T, e)
        U, L = u.reshape(self.nb, self.n), lam.reshape(self.nb, self.n)
        du = -np.einsum("ij,jk,ik->i", L, self.K0, U)
        return a, np.real(np.conj(u[self.r]) * du) / abs(u[self.r])


def worst_pattern(peak: LinearPeak, bound: float, starts: int = 32, seed: int = 1) -> dict:
    """The factors in [1 - bound, 1 + bound]^N_b maximizing blade 0's peak.

    Returns
    -------
    dict: ``kappa`` (N_b,), ``peak`` [m], ``omega`` [rad/s] (of the best start),
    ``starts`` (each start's peak), ``converged`` (the best start's optimizer
    converged), ``message`` (its optimizer message), ``evaluations``.
    """
    if not (np.isfinite(bound) and 0.0 < bound < 1.0):
        raise ValueError(f"worst-pattern bound {bound}: give 0 < B < 1 (factors within 1 +- B)")
    nb = peak.nb
    rng = np.random.default_rng([int(seed), 31])
    alt = np.where(np.arange(nb) % 2 == 0, 1.0, -1.0)
    x0s = [np.full(nb, 1.0 - 0.5 * bound), np.full(nb, 1.0 + 0.5 * bound), 1.0 + 0.5 * bound * alt]
    x0s += [1.0 + bound * rng.uniform(-1.0, 1.0, nb) for _ in range(max(starts - 3, 0))]
    scale = peak.peak(np.ones(nb))[0]

    def fun(k):
        a, g = peak.value_and_grad(k)
        return -a / scale, -g / scale

    best, found = None, []
    for x0 in x0s:
        res = minimize(fun, x0, jac=True, method="L-BFGS-B", bounds=[(1 - bound, 1 + bound)] * nb,
                       options={"gtol": GTOL, "maxiter": 200})
        found.append(-res.fun * scale)
        if best is None or res.fun < best.fun:
            best = res
    a, w = peak.peak(best.x)
    return {"kappa": best.x, "peak": a, "omega": w, "starts": found,
            "converged": bool(best.success), "message": str(best.message),
            "evaluations": peak.evaluations}
