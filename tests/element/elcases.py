"""Curves and histories shared by the element tests (SI units)."""
from __future__ import annotations

import numpy as np

#: Seed of every random draw in the element tests (written out, as the guide asks).
SEED = 20261122

# Steel sphere (R = 10 mm) on a steel plane, references.md: E* = 109.9 GPa, G* = 22.6 GPa.
E_MOD, NU, RADIUS = 200e9, 0.3, 10e-3
G_MOD = E_MOD / (2.0 * (1.0 + NU))
E_STAR = 1.0 / (2.0 * (1.0 - NU**2) / E_MOD)
G_STAR = 1.0 / (2.0 * (2.0 - NU) / G_MOD)
N_SPHERE, MU = 100.0, 0.5


def hertz_radius(N: float = N_SPHERE) -> float:
    """Hertz contact radius a [m] of the sphere: (3 N R / (4 E*))^(1/3)."""
    return (3.0 * N * RADIUS / (4.0 * E_STAR)) ** (1.0 / 3.0)


def cattaneo_slip_displacement(N: float = N_SPHERE) -> float:
    """u_s = 3 mu N / (16 G* a) [m]: displacement at gross slip (Cattaneo-Mindlin)."""
    return 3.0 * MU * N / (16.0 * G_STAR * hertz_radius(N))


def cattaneo_table(m: int, N: float = N_SPHERE):
    """Cattaneo-Mindlin virgin curve, m segments up to gross slip plus a flat tail.

    Points are uniform in T (T_i = mu N i / m), u(T) = u_s [1 - (1 - T/(mu N))^(2/3)],
    so the chords of this concave curve form a concave table. Returns u, T shape (m+2,).
    """
    u_s = cattaneo_slip_displacement(N)
    T = MU * N * np.arange(m + 1) / m
    u = u_s * (1.0 - (1.0 - T / (MU * N)) ** (2.0 / 3.0))
    return np.append(u, 2.0 * u_s), np.append(T, MU * N)


def mindlin_deresiewicz_energy(T_amp: float, N: float = N_SPHERE) -> float:
    """Energy per cycle [J] of the sphere under tangential force amplitude T_amp (references.md)."""
    x = T_amp / (MU * N)
    a = hertz_radius(N)
    return (9.0 * MU**2 * N**2 / (10.0 * a * G_STAR)) * (
        1.0 - (1.0 - x) ** (5.0 / 3.0) - (5.0 * x / 6.0) * (1.0 + (1.0 - x) ** (2.0 / 3.0)))


def tanh_table(m: int, F0: float = 40.0, u0: float = 2e-6, u_max: float = 1e-5):
    """Smooth concave curve g(u) = F0 tanh(u / u0), m uniform segments on [0, u_max]."""
    u = np.linspace(0.0, u_max, m + 1)
    return u, F0 * np.tanh(u / u0)


def random_reversal_history(rng, n_rev: int, amp: float, pts_per_leg: int = 3):
    """Random walk of n_rev legs with random reversal points in [-amp, amp], shape (n,)."""
    ends = rng.uniform(-amp, amp, size=n_rev)
    u, last = [0.0], 0.0
    for e in ends:
        u.extend(np.linspace(last, e, pts_per_leg + 1)[1:])
        last = e
    return np.array(u)
