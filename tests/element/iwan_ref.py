"""Slow, readable test oracle: the extended Masing rules with reversal-point memory.

Independent of the slider (Iwan) formulation used by the C core: it only knows
the virgin curve g(u) (odd extension) and Masing's rules (Masing 1926; the
"extended" memory rules, e.g. Segalman & Starr):

1. virgin loading follows F = g(u), odd extension (thesis eq. 2.15);
2. after a reversal at (u_r, F_r) the branch is F = F_r + 2 g((u - u_r) / 2) (eq. 2.16);
3. when a branch reaches the reversal point where the previous branch started,
   that inner loop is closed and forgotten: the response continues on the
   branch that was interrupted (for the first loop, on the virgin curve at -u_r).

Constant normal load only, displacement samples joined by straight lines (a
reversal can only happen at a sample). Never used in production.
"""
from __future__ import annotations

import numpy as np


class MasingRef:
    """Extended-Masing response to a displacement history.

    Parameters
    ----------
    g : callable
        Virgin curve g(u) [N] for u >= 0 (odd extension applied here).
    """

    def __init__(self, g):
        self._g = g
        self.reversals: list[tuple[float, float]] = []   # (u_r, F_r), oldest first
        self.u = 0.0
        self.F = 0.0

    def virgin(self, u: float) -> float:
        return float(np.sign(u) * self._g(abs(u)))

    def _branch(self, u: float) -> float:
        if not self.reversals:
            return self.virgin(u)
        u_r, F_r = self.reversals[-1]
        return F_r + 2.0 * self.virgin((u - u_r) / 2.0)

    def _target(self) -> float:
        """Displacement where the current branch closes its loop."""
        if len(self.reversals) >= 2:
            return self.reversals[-2][0]
        return -self.reversals[0][0]

    def _heading(self) -> float:
        """Direction of the current branch (+1 / -1; 0 at the virgin origin)."""
        if not self.reversals:
            return float(np.sign(self.u))
        return float(np.sign(self._target() - self.reversals[-1][0]))

    def step(self, u_new: float) -> float:
        """Move to ``u_new`` along a straight line; return the force [N]."""
        d = np.sign(u_new - self.u)
        if d == 0.0:
            return self.F
        heading = self._heading()
        if heading != 0.0 and d != heading:                    # reversal at the last sample
            self.reversals.append((self.u, self.F))
        while self.reversals and d * (u_new - self._target()) > 0.0:
            # the branch passed its closure point: forget the inner loop (rule 3)
            del self.reversals[-2 if len(self.reversals) >= 2 else -1:]
        self.u = u_new
        self.F = self._branch(u_new)
        return self.F

    def series(self, u) -> np.ndarray:
        """Forces [N] at every sample of ``u`` (shape (n,))."""
        return np.array([self.step(float(x)) for x in u])


def table_curve(u_tab, T_tab):
    """Piecewise-linear virgin curve through a table, last slope extrapolated."""
    u_tab = np.asarray(u_tab, float)
    T_tab = np.asarray(T_tab, float)
    s_last = (T_tab[-1] - T_tab[-2]) / (u_tab[-1] - u_tab[-2])

    def g(u):
        if u <= u_tab[-1]:
            return float(np.interp(u, u_tab, T_tab))
        return float(T_tab[-1] + s_last * (u - u_tab[-1]))

    return g
