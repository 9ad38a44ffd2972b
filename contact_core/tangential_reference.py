"""Closed-form tangential references (``shared/notes/references.md``) and Masing's rule.

Cattaneo-Mindlin (sphere, constant N), 2D Cattaneo (cylinder, per unit length),
Mindlin-Deresiewicz loop energy; and Masing's loop built from a tabulated
virgin curve, used to compare with loops computed directly by the contact model.

Symbols: N normal force [N], mu friction coefficient, a contact radius [m],
b contact half-width [m], G* = 1 / ((2 - nu1)/G1 + (2 - nu2)/G2) [Pa],
T tangential force [N], u tangential displacement [m].
"""
from __future__ import annotations

import numpy as np


def shear_modulus_star(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """G* [Pa]: 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2, G = E / (2 (1 + nu))."""
    G1, G2 = E1 / (2 * (1 + nu1)), E2 / (2 * (1 + nu2))
    return 1.0 / ((2 - nu1) / G1 + (2 - nu2) / G2)


def mindlin_slip_displacement(N: float, mu: float, a: float, Gs: float) -> float:
    """u_s = 3 mu N / (16 G* a) [m]: displacement at gross slip."""
    return 3.0 * mu * N / (16.0 * Gs * a)


def mindlin_force(u, N: float, mu: float, a: float, Gs: float):
    """Virgin curve T(u) = mu N [1 - (1 - u/u_s)^(3/2)], mu N beyond u_s [N]."""
    x = np.clip(np.asarray(u, float) / mindlin_slip_displacement(N, mu, a, Gs), 0.0, 1.0)
    return mu * N * (1.0 - (1.0 - x) ** 1.5)


def mindlin_stick_radius(T, N: float, mu: float, a: float):
    """Stick radius c = a (1 - T/(mu N))^(1/3) [m]."""
    return a * np.cbrt(np.clip(1.0 - np.asarray(T, float) / (mu * N), 0.0, 1.0))


def mindlin_deresiewicz_energy(T_amp: float, N: float, mu: float, a: float, Gs: float) -> float:
    """Energy dissipated per cycle under force amplitude T* (Mindlin-Deresiewicz) [J]."""
    x = T_amp / (mu * N)
    return (9.0 * mu**2 * N**2 / (10.0 * a * Gs)) * (
        1.0 - (1.0 - x) ** (5.0 / 3.0) - (5.0 * x / 6.0) * (1.0 + (1.0 - x) ** (2.0 / 3.0)))


def cattaneo_2d_stick_halfwidth(Q: float, P: float, mu: float, b: float) -> float:
    """2D Cattaneo stick half-width c = b sqrt(1 - Q/(mu P)) [m] (per unit length loads)."""
    return b * np.sqrt(max(1.0 - Q / (mu * P), 0.0))


def cattaneo_2d_traction(x, Q: float, P: float, mu: float, b: float, p0: float):
    """2D Cattaneo traction q(x) [Pa]: mu p in the slip zone, minus the stick correction."""
    x = np.asarray(x, float)
    c = cattaneo_2d_stick_halfwidth(Q, P, mu, b)
    q = mu * p0 * np.sqrt(np.clip(1.0 - (x / b) ** 2, 0.0, None))
    if c > 0:
        q = q - mu * p0 * (c / b) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None))
    return q


def _interp_table(u_tab, T_tab):
    """Odd, piecewise-linear g(u) from a virgin table, constant beyond its end."""
    u_tab, T_tab = np.asarray(u_tab, float), np.asarray(T_tab, float)

    def g(u):
        u = np.asarray(u, float)
        return np.sign(u) * np.interp(np.abs(u), u_tab, T_tab)

    return g


def masing_branch(u, u_r: float, F_r: float, u_tab, T_tab):
    """Masing branch after a reversal at (u_r, F_r): F = F_r + 2 g((u - u_r)/2) [N]."""
    g = _interp_table(u_tab, T_tab)
    return F_r + 2.0 * g((np.asarray(u, float) - u_r) / 2.0)


def masing_loop_energy(amplitude: float, u_tab, T_tab) -> float:
    """Loop energy W(a) = 8 int_0^a g - 4 a g(a) of the piecewise-linear table [J]."""
    u_tab, T_tab = np.asarray(u_tab, float), np.asarray(T_tab, float)
    a = float(amplitude)
    ga = float(np.interp(a, u_tab, T_tab))
    inside = u_tab < a
    us = np.concatenate([u_tab[inside], [a]])
    Ts = np.concatenate([T_tab[inside], [ga]])
    if a > u_tab[-1]:  # constant g beyond the table's end
        us, Ts = np.concatenate([u_tab, [a]]), np.concatenate([T_tab, [T_tab[-1]]])
    return 8.0 * float(np.trapezoid(Ts, us)) - 4.0 * a * ga
