"""Readable reference of the 2D Masing/Iwan element (``fmu_src/core/iwan2d.h``), tests only.

Written from the physics, not from the C formulas: the stick phase of a slider ends
at the root of |e0 + s d| = r(s) (found by ``brentq``); in the slip phase the angle
theta of the stretch to d follows tan(theta/2) = tan(theta*/2) exp(-|d| tau(s)) with
tau(s) = int_{s*}^{s} ds'/r(s') (the tractrix; by ``atan``/``tan``); the friction work
is the integral of the slider's power k r (|d| cos theta - dr) by ``scipy.integrate.quad``.
Lift-off (N <= 0) and re-contact follow iwan2d.h: the path to N = 0, then the
element released at the end point; re-contact virgin where N crosses zero.

Symbols: e = u - z slider stretch [m], d path increment [m], r slip radius [m].
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar

#: Relative accuracy asked of quad and brentq (the reference is meant to be exact
#: to ~1e-12, far below any tolerance it is compared with).
QUAD_RTOL = 1e-13


def slider_path(e0, d, r0: float, r1: float):
    """One slider along the straight path e0 + s d, radius r0 -> r1.

    Returns (e1 (2,), work / k [m^2], s_star or None if it stuck throughout).
    """
    e0, d = np.asarray(e0, float), np.asarray(d, float)
    rho0 = math.hypot(*e0)
    if rho0 > r0:  # outside only by round-off
        e0 = e0 * (r0 / rho0) if r0 > 0 else np.zeros(2)
    dr = r1 - r0

    def r(s):
        return r0 + s * dr

    if math.hypot(*(e0 + d)) <= r1:
        return e0 + d, 0.0, None
    gap = lambda s: math.hypot(*(e0 + s * d)) - r(s)  # noqa: E731  (<= 0 while stuck)
    # gap is convex: the slider leaves the circle after the minimum of gap (at s = 0 if
    # it is on the circle there and moving out; a growing circle may first take it in)
    s_min = minimize_scalar(gap, bounds=(0.0, 1.0), method="bounded",
                            options={"xatol": 1e-14}).x
    s_min = 0.0 if gap(0.0) <= gap(s_min) else s_min
    s_star = s_min if gap(s_min) >= 0.0 else brentq(gap, s_min, 1.0, xtol=1e-300, rtol=1e-15)
    es, rs = e0 + s_star * d, r(s_star)
    D = math.hypot(*d)
    if D == 0.0:  # radius shrinking at rest: the slider follows radially
        return r1 * es / math.hypot(*es), 0.5 * (rs * rs - r1 * r1), s_star
    phi_d = math.atan2(d[1], d[0])
    theta_star = (math.atan2(es[1], es[0]) - phi_d) if rs > 0 else 0.0
    theta_star = math.atan2(math.sin(theta_star), math.cos(theta_star))

    def tau(s):
        if rs == 0.0 or r(s) == 0.0:
            return math.inf if s > s_star else 0.0
        return (s - s_star) / rs if dr == 0.0 else math.log(r(s) / rs) / dr

    def theta(s):
        return 2.0 * math.atan(math.tan(0.5 * theta_star) * math.exp(-D * tau(s)))

    e1 = r1 * np.array([math.cos(phi_d + theta(1.0)), math.sin(phi_d + theta(1.0))])
    power = lambda s: r(s) * (D * math.cos(theta(s)) - dr)  # noqa: E731
    work = quad(power, s_star, 1.0, epsabs=0.0, epsrel=QUAD_RTOL, limit=200)[0]
    return e1, work, s_star


class RefIwan2D:
    """Reference 2D element: sliders (k_j, fs_j at n_ref), residual spring, scale.

    Attributes after each :meth:`step`: u (2,), N, z (n, 2), u_c (2,), W, in_contact,
    and ``s_star`` (the stick-slip switch of each slider in the last step, None when
    it stuck; in the last contact part of the step).
    """

    def __init__(self, k, fs, k_res: float = 0.0, n_ref: float = 1.0, scale: float = 1.0,
                 N: float | None = None):
        self.k, self.fs = np.asarray(k, float), np.asarray(fs, float)
        self.k_res, self.n_ref, self.scale = float(k_res), float(n_ref), float(scale)
        self.N = self.n_ref if N is None else float(N)
        self.u, self.u_c = np.zeros(2), np.zeros(2)
        self.z = np.zeros((self.k.size, 2))
        self.W, self.in_contact = 0.0, self.N > 0
        self.s_star: list = []

    @classmethod
    def of(cls, element, N: float | None = None) -> RefIwan2D:
        """The reference of an ``IwanElement`` / ``IwanElement2D`` model."""
        el = getattr(element, "element", element)
        return cls(el.k, el.fs, el.k_res, el.N_ref, el.scale, N)

    def radii(self, N: float) -> np.ndarray:
        return self.fs / self.k * self.scale * (N / self.n_ref)

    def _path(self, u0, d, N0, N1):
        r0, r1 = self.radii(N0), self.radii(N1)
        self.s_star = []
        for j in range(self.k.size):
            e1, w, s = slider_path(u0 - self.z[j], d, r0[j], r1[j])
            self.z[j] = u0 + d - e1
            self.W += self.k[j] * w
            self.s_star.append(s)

    def step(self, u1, N1: float):
        """Advance along the straight path to (u1, N1)."""
        u0, u1, N0 = self.u.copy(), np.asarray(u1, float), self.N
        d = u1 - u0
        if N0 > 0 and N1 > 0:
            self._path(u0, d, N0, N1)
        elif N0 > 0:  # lift-off where N = 0, released at the end
            sl = N0 / (N0 - N1)
            self._path(u0, sl * d, N0, 0.0)
            self.z[:], self.u_c, self.in_contact = u1, u1.copy(), False
        elif N1 > 0:  # re-contact: virgin where N = 0
            sc = -N0 / (N1 - N0)
            uc = u0 + sc * d
            self.z[:], self.u_c, self.in_contact = uc, uc.copy(), True
            self._path(uc, u1 - uc, 0.0, N1)
        else:
            self.z[:], self.u_c = u1, u1.copy()
        self.u, self.N = u1.copy(), float(N1)

    def force(self) -> np.ndarray:
        if not self.in_contact:
            return np.zeros(2)
        return self.k_res * (self.u - self.u_c) + (self.k[:, None] * (self.u - self.z)).sum(0)

    def energy(self) -> float:
        if not self.in_contact:
            return 0.0
        e2 = ((self.u - self.z) ** 2).sum(1)
        return 0.5 * (self.k_res * float(((self.u - self.u_c) ** 2).sum()) + float(self.k @ e2))
