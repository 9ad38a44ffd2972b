"""Readable, slow Jenkins element: a TEST ORACLE only (the law lives in the C core).

A Jenkins element (spring k in series with a Coulomb slider of strength Fs) is a
play operator on the slider position z:  z_i = clip(z_(i-1), u_i - Fs/k, u_i + Fs/k),
force F_i = k (u_i - z_i). Starting the periodic sweep at the maximum of u with the
slider saturated there gives the exact periodic loop in one pass (performance.md).

Mirrors the ``periodic_jac`` entry point of ``fmu_src.element.IwanElement`` so the
harmonic-balance code can be tested independently of the C build.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np


class JenkinsRef:
    """Jenkins element oracle with the ``IwanElement`` periodic interface."""

    def __init__(self, k: float, fs: float):
        self.k, self.fs = float(k), float(fs)
        self.k_res = 0.0  # IwanElement's attributes (k as a scalar sums the same)

    def periodic_jac(self, u, Eu, N=None, EN=None):
        """Periodic loop F (n,), exact dF/dX (n, nb), None, dissipated energy per cycle."""
        u = np.asarray(u, dtype=float)
        Eu = np.asarray(Eu, dtype=float)
        n = u.size
        d = self.fs / self.k
        i0 = int(np.argmax(u))
        z = u[i0] - d
        dz = Eu[i0].copy()  # the slider hangs on the reversal point u[i0]
        F = np.empty(n)
        dF = np.empty_like(Eu)
        W = 0.0
        for step in range(1, n + 1):
            i = (i0 + step) % n
            lo, hi = u[i] - d, u[i] + d
            if z < lo:
                W += self.fs * (lo - z)
                z, dz = lo, Eu[i].copy()
            elif z > hi:
                W += self.fs * (z - hi)
                z, dz = hi, Eu[i].copy()
            F[i] = self.k * (u[i] - z)
            dF[i] = self.k * (Eu[i] - dz)
        return F, dF, None, W

    def series(self, u, N=None, state=None):
        """Whole history from ``state`` (slider position z, virgin 0): F, final state."""
        z = 0.0 if state is None else state
        d = self.fs / self.k
        F = np.empty(len(u))
        for i, ui in enumerate(u):
            z = min(max(z, ui - d), ui + d)
            F[i] = self.k * (ui - z)
        return SimpleNamespace(F=F, state=z)

    def initial_state(self, N=None):
        return SimpleNamespace(z=0.0)

    def step(self, state, u, N=None):
        """Advance ``state`` in place to displacement u; returns .F."""
        d = self.fs / self.k
        state.z = min(max(state.z, u - d), u + d)
        return SimpleNamespace(F=self.k * (u - state.z))

    def periodic(self, u, N=None, max_periods=100, tol=1e-12):
        u = np.asarray(u, dtype=float)
        F, _, _, W = self.periodic_jac(u, np.zeros((u.size, 1)))
        return SimpleNamespace(F=F, W_cycle=W)


def describing_function(k, fs, a):
    """Jenkins first-harmonic coefficients (a1, b1) under x = a cos(theta) (references.md)."""
    if a <= fs / k:
        return k * a, 0.0
    th = np.arccos(1.0 - 2.0 * fs / (k * a))
    a1 = k * a / np.pi * (th - np.sin(2.0 * th) / 2.0)
    b1 = -k * a / np.pi * np.sin(th) ** 2
    return a1, b1
