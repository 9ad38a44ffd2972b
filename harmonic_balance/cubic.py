"""A cubic spring F = k3 u^3 (Duffing), with the periodic interface of the friction links.

Used to test the continuation and Hill's stability on a smooth nonlinearity with
a known unstable branch; plugs into :class:`aft.FrictionLink` as an element
(``periodic_jac(u, Eu) -> (F, dF/dU, None, W)``) between two DOFs or to the ground.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np


class CubicSpring:
    """Conservative cubic spring of coefficient k3 [N/m^3]: F(u) = k3 u^3, W = 0.

    ``k``/``k_res`` (zero) make its small-amplitude (linear) stiffness zero for the
    stuck starting guess of :mod:`residual`.
    """

    def __init__(self, k3: float):
        if not np.isfinite(k3):
            raise ValueError(f"cubic coefficient must be finite, got {k3}")
        self.k3 = float(k3)
        self.k = np.zeros(1)
        self.k_res = 0.0

    def periodic_jac(self, u, Eu, N=None, EN=None):
        """Force samples (n_t,), exact dF/dU (n_t, n_b), None, energy per cycle (0)."""
        u = np.asarray(u, dtype=float)
        return self.k3 * u**3, (3.0 * self.k3 * u**2)[:, None] * np.asarray(Eu), None, 0.0

    def initial_state(self, N=None):
        """Time-domain state (the spring has no history; ``W`` stays 0)."""
        return SimpleNamespace(W=0.0)

    def step(self, state, u, N=None):
        """Force at displacement u (state untouched: elastic)."""
        return SimpleNamespace(F=self.k3 * float(u) ** 3)
