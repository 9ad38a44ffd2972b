"""Exact steady state of an oscillator with rigid Coulomb and viscous friction (Den Hartog 1931).

A test oracle, independent of the harmonic balance: the periodic response of ::

    m x'' + c x' + k x + F_s sgn(x') = P cos(omega t + phi)

(J. P. Den Hartog, "Forced vibrations with combined Coulomb and viscous friction",
Trans. ASME APM-53-9, 1931). The steady motion is antisymmetric over a half period
T/2 = pi / omega: x(t + T/2) = -x(t). Between two velocity reversals the equation
is linear (x' > 0: friction -F_s), so a half period is a boundary-value problem for
a linear ODE with constant coefficients, solved here exactly with the state
transition matrix Phi(t) = expm(A t), A = [[0, 1], [-k/m, -c/m]], and the
particular solution of the harmonic and the constant load.

Two kinds of motion (Den Hartog's "without stops" and "with one stop per half
cycle"):

* continuous: x' > 0 for 0 < t < T/2 from x(0) = -A, x'(0) = 0 to x(T/2) = A,
  x'(T/2) = 0. With z = (x, x'), the particular parts z_p(0) = h + s and
  z_p(T/2) = -h + s (h harmonic, s = (-F_s / k, 0)), the conditions give
  ``(I + Phi) a = -(I + Phi) h + (I - Phi) s`` for a = (A, 0): the velocity row fixes
  the phase, the displacement row the amplitude. Valid when x' >= 0 on the whole
  half period and the mass does start to slide at t = 0 (m x''(0+) >= 0).
* with stops: slip starts at t = 0 when the applied force reaches the slip limit,
  ``P cos(phi) + k A = F_s``, and ends at the first zero t_r < T/2 of x' with
  x(t_r) = A; the mass then sticks until T/2 (checked: |P cos - k A| <= F_s). One
  equation in phi (A follows from the onset condition), solved by bracketing.

Units: SI (m [kg], c [N s/m], k [N/m], F_s and P [N], omega [rad/s], x [m]).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq

#: Samples per half period for the velocity-sign and stick-force checks.
CHECK_SAMPLES = 2000
#: Relative slack of those checks (round-off of the exact solution).
CHECK_RTOL = 1e-9


@dataclass
class DenHartogResult:
    """Steady state: amplitude A [m] (= max |x|), phase phi [rad] of the forcing at the
    reversal x = -A, kind 'continuous', 'stops' or 'stuck', and the slip time t_r [s]
    of a half period (T/2 for continuous motion)."""

    amplitude: float
    phi: float
    kind: str
    t_slip: float


class _HalfPeriod:
    """Slip phase x' > 0 from (x, x') = (-A, 0) under P cos(omega t + phi) - F_s."""

    def __init__(self, m, c, k, fs, P, omega):
        self.m, self.c, self.k, self.fs, self.P, self.w = m, c, k, fs, P, omega
        self.A = np.array([[0.0, 1.0], [-k / m, -c / m]])
        self.X = P / (k - m * omega**2 + 1j * c * omega)  # harmonic response amplitude
        # expm(A t) = V diag(exp(lam t)) V^-1, vectorised over t (distinct eigenvalues
        # unless c^2 = 4 k m exactly, where expm is used point by point)
        self.lam, self.V = np.linalg.eig(self.A.astype(complex))
        self.diag = abs(self.lam[0] - self.lam[1]) > 1e-8 * abs(self.lam).max()
        if self.diag:
            self.Vi = np.linalg.inv(self.V)

    def particular(self, t, phi):
        """z_p (2, len(t)) of the harmonic + constant load."""
        e = self.X * np.exp(1j * (self.w * np.asarray(t) + phi))
        return np.array([e.real - self.fs / self.k, (1j * self.w * e).real])

    def state(self, t, phi, amp):
        """z(t) (2, len(t)) from z(0) = (-amp, 0)."""
        t = np.atleast_1d(t)
        z0 = np.array([-amp, 0.0]) - self.particular([0.0], phi)[:, 0]
        if self.diag:
            hom = (self.V @ (np.exp(np.outer(self.lam, t)) * (self.Vi @ z0)[:, None])).real
        else:
            hom = np.array([sla.expm(self.A * ti) @ z0 for ti in t]).T
        return self.particular(t, phi) + hom


def den_hartog(m, c, k, fs, P, omega) -> DenHartogResult:
    """Steady-state amplitude of the rigid-Coulomb + viscous oscillator (module docstring).

    Raises
    ------
    ValueError for non-positive m, k, omega or negative c, fs, P;
    RuntimeError when neither kind of motion satisfies its checks (more than one
    stop per half period, outside this oracle's scope).
    """
    if min(m, k, omega) <= 0 or min(c, fs, P) < 0:
        raise ValueError("den_hartog needs m, k, omega > 0 and c, fs, P >= 0")
    if P <= fs:
        return DenHartogResult(0.0, 0.0, "stuck", 0.0)  # never breaks loose (Den Hartog)
    hp = _HalfPeriod(m, c, k, fs, P, omega)
    res = _continuous(hp)
    if res is not None:
        return res
    res = _with_stops(hp)
    if res is not None:
        return res
    raise RuntimeError(f"no one-stop steady state at omega = {omega:g} rad/s")


def _continuous(hp: _HalfPeriod):
    Th = np.pi / hp.w
    Phi = sla.expm(hp.A * Th)
    I2 = np.eye(2)
    q = np.linalg.solve(I2 + Phi, (I2 - Phi) @ np.array([-hp.fs / hp.k, 0.0]))
    # velocity row: Re(i w X e^{i phi}) = -w |X| sin(phi + psi) = q_v
    s = -q[1] / (hp.w * abs(hp.X))
    if abs(s) > 1.0:
        return None
    psi = np.angle(hp.X)
    phi = np.arcsin(s) - psi
    if np.cos(phi + psi) > 0:
        phi = np.pi - np.arcsin(s) - psi  # the root with cos(phi + psi) < 0: A > 0
    amp = -abs(hp.X) * np.cos(phi + psi) + q[0]
    t = np.linspace(0.0, Th, CHECK_SAMPLES)
    z = hp.state(t, phi, amp)
    scale = hp.w * amp
    starts = hp.P * np.cos(phi) + hp.k * amp - hp.fs >= -CHECK_RTOL * hp.P
    if amp <= 0 or z[1].min() < -CHECK_RTOL * scale or not starts:
        return None
    return DenHartogResult(float(amp), float(phi), "continuous", float(Th))


def _with_stops(hp: _HalfPeriod):
    """Phase phi with slip onset P cos(phi) + k A = F_s and x(t_r) = A at the velocity zero."""
    Th = np.pi / hp.w
    t = np.linspace(0.0, Th, CHECK_SAMPLES)

    def reversal(phi):
        amp = (hp.fs - hp.P * np.cos(phi)) / hp.k
        if amp <= 0:
            return None
        z = hp.state(t, phi, amp)
        if z[1][1] <= 0:  # the applied force is falling at the onset: no slip starts
            return None
        neg = np.flatnonzero(z[1][1:] < 0)
        if neg.size == 0:
            return None
        j = neg[0] + 1
        tr = brentq(lambda s: hp.state(s, phi, amp)[1, 0], t[j - 1], t[j], xtol=1e-15)
        return amp, tr, hp.state(tr, phi, amp)[0, 0] - amp

    phis = np.linspace(-np.pi, np.pi, 721)
    vals = [reversal(p) for p in phis]
    for i in range(len(phis) - 1):
        a, b = vals[i], vals[i + 1]
        if a is None or b is None or np.sign(a[2]) == np.sign(b[2]):
            continue
        phi = brentq(lambda p: reversal(p)[2], phis[i], phis[i + 1], xtol=1e-14)
        amp, tr, _ = reversal(phi)
        if _stick_holds(hp, phi, amp, tr, Th):
            return DenHartogResult(float(amp), float(phi), "stops", float(tr))
    return None


def _stick_holds(hp, phi, amp, tr, Th) -> bool:
    """During the stop at x = A (t_r..T/2) the applied force stays within the slip limit."""
    ts = np.linspace(tr, Th, 200)
    f = hp.P * np.cos(hp.w * ts + phi) - hp.k * amp
    return bool(np.all(np.abs(f) <= hp.fs * (1 + 1e-6)))
