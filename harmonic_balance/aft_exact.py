"""Exact Fourier coefficients of a friction link's loop: no AFT sampling error.

The sampled AFT (:mod:`aft`) runs the element on n_t samples of u(theta): the reversals
sit on samples, and every sample where a slider sticks or slips adds or removes a
stiffness k / n_t to the harmonic Jacobian. On a stiff contact (1e6 k, a stick episode
shorter than a sample) the residual is then a staircase of such kinks as the
solution's phase slides over the grid, and the reversal value is off by up to
k u'' dtheta^2 / 2 (0.3 N against f_s = 0.5 N at 8192 samples): the corrector
spends its evaluations on the kinks.

Here the input's true extrema are located (u is a trigonometric polynomial: the zeros
of u' by a sign scan on the basis grid and safeguarded Newton), the C core gives the
loop between them exactly as piecewise-linear branches F = c_i + s_i u
(``IwanElement.periodic_branches``: the play operator itself, the same law), each
branch end is located in theta (u is monotone between extrema), and the Fourier
integrals of F(theta) = c_i + s_i u(theta) are taken in closed form. The Jacobian is
exact and continuous wherever the branch structure is: a knot moving in theta adds
no boundary term (F is continuous there) and an extremum moving adds none (u' = 0
there), so dF_h/dU = sum_i w_h int (s_i phi_m + dc_i/dU_m) psi_h with
dc_i/dU = -sum_e A[i, e] phi(theta_e).

Only for constant normal load (FrictionLink); a contact with a varying normal load
keeps the sampled AFT. Symbols: phi_m the basis functions (cos h theta, sin h theta,
1), w_h = 1/(2 pi) for the mean, 1/pi otherwise (the continuous D).
"""
from __future__ import annotations

import numpy as np

from .fourier import FourierBasis

#: Newton / bisection iterations for a root of u' or of u - target in its bracket.
ROOT_ITER = 60
#: Root tolerance in theta [rad] (round-off of theta ~ 2 pi eps).
THETA_TOL = 1e-14


class ExactAFT:
    """Per-basis constants of the closed-form integrals (built once per basis)."""

    def __init__(self, basis: FourierBasis):
        self.basis = basis
        o = np.asarray(basis.order)
        kind = np.zeros(basis.nb, dtype=int)            # 0: cos (or the mean), 1: sin
        kind[(2 if basis.harmonics[0] == 0 else 1)::2] = 1
        self.order, self.kind = o, kind
        self.w = np.where(o == 0, 1.0 / (2.0 * np.pi), 1.0 / np.pi)
        # psi_h phi_m = 1/2 [a cos(d) + b cos(s) + g sin(d) + q sin(s)] (theta omitted),
        # d = o_h - o_m, s = o_h + o_m
        kh, km = kind[:, None], kind[None, :]
        self.d = o[:, None] - o[None, :]
        self.s = o[:, None] + o[None, :]
        cc, ss = (kh == 0) & (km == 0), (kh == 1) & (km == 1)
        sc, cs = (kh == 1) & (km == 0), (kh == 0) & (km == 1)
        self.a = np.where(cc | ss, 1.0, 0.0)
        self.b = np.where(cc, 1.0, np.where(ss, -1.0, 0.0))
        self.g = np.where(sc, 1.0, np.where(cs, -1.0, 0.0))   # sin(h-m) terms
        self.q = np.where(sc | cs, 1.0, 0.0)                  # sin(h+m) terms

    # ------------------------------------------------------------ interval integrals
    @staticmethod
    def _jcos(k, m, hw):
        """int_{m-hw}^{m+hw} cos(k t) dt = 2 cos(k m) sin(k hw) / k (2 hw for k = 0): the
        half-width form, without the cancellation of sin(k b) - sin(k a) (an antiderivative
        difference loses eps |theta| absolutely, 1e-15 that a 1e6 N/m stick window turns
        into 1e-10 N of residual noise)."""
        kk = np.where(k == 0, 1.0, k)
        return np.where(k == 0, 2.0 * hw, 2.0 * np.cos(k * m) * np.sin(k * hw) / kk)

    @staticmethod
    def _jsin(k, m, hw):
        """int_{m-hw}^{m+hw} sin(k t) dt = 2 sin(k m) sin(k hw) / k (0 for k = 0)."""
        kk = np.where(k == 0, 1.0, k)
        return np.where(k == 0, 0.0, 2.0 * np.sin(k * m) * np.sin(k * hw) / kk)

    def d1(self, a, b):
        """int_a^b psi_h per interval, shape (len(a), n_b)."""
        m, hw = (0.5 * (a + b))[:, None], (0.5 * (b - a))[:, None]
        return np.where(self.kind == 0, self._jcos(self.order, m, hw),
                        self._jsin(self.order, m, hw))

    def d2(self, a, b):
        """int_a^b psi_h phi_m per interval, shape (len(a), n_b, n_b)."""
        m, hw = (0.5 * (a + b))[:, None, None], (0.5 * (b - a))[:, None, None]
        return 0.5 * (self.a * self._jcos(self.d, m, hw) + self.b * self._jcos(self.s, m, hw)
                      + self.g * self._jsin(self.d, m, hw) + self.q * self._jsin(self.s, m, hw))

    def phi(self, th):
        """Basis functions at theta, shape (len(th), n_b)."""
        arg = np.outer(np.asarray(th), self.order)
        return np.where(self.kind == 0, np.cos(arg), np.sin(arg))

    # ------------------------------------------------------------ the loop
    def extrema(self, U):
        """Theta (k,) of the local extrema of u = phi U in [0, 2 pi), k even, sorted."""
        b = self.basis
        dU = b.dtheta @ U
        g = b.E @ dU                                   # u' on the basis grid
        n = g.size
        th = 2.0 * np.pi * np.arange(n) / n
        nxt = np.roll(g, -1)
        idx = np.flatnonzero((g > 0) & (nxt <= 0) | (g < 0) & (nxt >= 0))
        if idx.size == 0:
            return np.zeros(0)
        lo = th[idx]
        hi = lo + 2.0 * np.pi / n
        roots = self._roots(dU, b.dtheta @ dU, lo, hi, np.zeros(idx.size))
        roots = np.mod(roots, 2.0 * np.pi)
        order = np.argsort(roots)
        roots = roots[order]
        # a zero of u' exactly on a grid point can be found from both of its brackets
        keep = np.ones(roots.size, dtype=bool)
        keep[1:] = np.diff(roots) > 1e-12
        if roots.size > 1 and roots[0] + 2.0 * np.pi - roots[-1] <= 1e-12:
            keep[-1] = False
        roots = roots[keep]
        return roots if roots.size % 2 == 0 else np.zeros(0)

    def _roots(self, C, dC, lo, hi, target):
        """theta in [lo, hi] with phi(theta) C = target (the function changes sign over
        the bracket): Newton with bisection safeguard, vectorised over brackets."""
        f_lo = self.phi(lo) @ C - target
        x = 0.5 * (lo + hi)
        lo, hi = lo.copy(), hi.copy()
        # |f| below the round-off of evaluating phi C: nothing left to gain
        f_tol = 8.0 * np.finfo(float).eps * (np.abs(C).sum() + np.abs(target)) * np.ones(x.size)
        active = np.ones(x.size, dtype=bool)
        for _ in range(ROOT_ITER):
            i = np.flatnonzero(active)
            P = self.phi(x[i])
            f = P @ C - target[i]
            df = P @ dC
            left = np.sign(f) == np.sign(f_lo[i])
            lo[i] = np.where(left, x[i], lo[i])
            f_lo[i] = np.where(left, f, f_lo[i])
            hi[i] = np.where(left, hi[i], x[i])
            with np.errstate(divide="ignore", invalid="ignore"):
                xn = x[i] - f / df
            bad = ~np.isfinite(xn) | (xn <= lo[i]) | (xn >= hi[i])
            xn = np.where(bad, 0.5 * (lo[i] + hi[i]), xn)
            done = ((np.abs(xn - x[i]) <= THETA_TOL) | (np.abs(f) <= f_tol[i])
                    | (hi[i] - lo[i] <= THETA_TOL))
            x[i] = np.where(np.abs(f) <= f_tol[i], x[i], xn)
            active[i[done]] = False
            if not active.any():
                break
        return x

    def link(self, element, U, k0: float):
        """Harmonics (n_b,) of the link force, dF/dU (n_b, n_b), W [J] and the force at
        the basis grid (n_t,) (for plots and energy checks)."""
        b = self.basis
        U = np.asarray(U, dtype=float)
        th_e = self.extrema(U)
        if th_e.size < 2:      # u constant: the stuck line (aft's convention)
            u = b.E @ U
            return k0 * U, k0 * np.eye(b.nb), 0.0, k0 * u
        u_e = self.phi(th_e) @ U
        br = element.periodic_branches(u_e)
        seg, s, c, A = br["seg"], br["slope"], br["icpt"], br["A"]
        ne = th_e.size
        t0 = th_e[seg]
        t1 = np.where(seg + 1 < ne, th_e[np.minimum(seg + 1, ne - 1)], th_e[0] + 2.0 * np.pi)
        u0, u1 = u_e[seg], u_e[(seg + 1) % ne]
        # each knot located once and shared by the two intervals it joins (two searches
        # of a flat stretch could land apart: a gap or overlap of the integrals)
        t_lo = self._locate(U, br["u_lo"], t0, t1, u0, u1)
        same = np.append(seg[1:] == seg[:-1], False)
        t_hi = np.where(same, np.append(t_lo[1:], 0.0), t1)
        d1 = self.d1(t_lo, t_hi)                                # (m, n_b)
        d2 = self.d2(t_lo, t_hi)                                # (m, n_b, n_b)
        S2 = np.einsum("i,ihm->hm", s, d2)
        Phi_e = self.phi(th_e)                                  # (ne, n_b)
        dc = -(A @ Phi_e)                                       # (m, n_b)
        Fh = self.w * (c @ d1 + S2 @ U)
        dFh = self.w[:, None] * (S2 + d1.T @ dc)
        # force at the grid: the interval that holds each grid angle
        u_grid = b.E @ U
        th_g = 2.0 * np.pi * np.arange(b.n_t) / b.n_t
        th_g = np.where(th_g < th_e[0], th_g + 2.0 * np.pi, th_g)
        order = np.argsort(t_lo)
        pos = np.clip(np.searchsorted(t_lo[order], th_g, side="right") - 1, 0, len(order) - 1)
        i = order[pos]
        F = c[i] + s[i] * u_grid
        return Fh, dFh, float(br["W"]), F

    def _locate(self, U, target, t0, t1, u0, u1):
        """theta in [t0, t1] (a monotone stretch of u from u0 to u1, the extrema's values)
        where u(theta) = target; the ends themselves where target is an extremum's value
        (exactly: the C core passes them through, and a root search there would meet
        u' = 0; phi(t + 2 pi) is not phi(t) in floating point, so no recomputation)."""
        out = np.empty(target.size)
        at0, at1 = target == u0, target == u1
        out[at0], out[at1] = t0[at0], t1[at1]
        rest = ~(at0 | at1)
        if np.any(rest):
            dU = self.basis.dtheta @ U
            out[rest] = self._roots(U, dU, t0[rest], t1[rest], target[rest])
        return out
