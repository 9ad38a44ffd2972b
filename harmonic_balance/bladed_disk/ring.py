"""Short full ring of N_r = N_b / gcd(N_b, EO) sectors closed periodically.

Blade j's DOFs are 7 j .. 7 j + 6 (sector ordering of :mod:`sector`); damper j touches
blade j and blade (j + 1) mod N_r. The EO force is F_j = F0 cos(omega t + j phi) on
u_a of blade j, phi = 2 pi EO / N_b = 2 pi EO_r / N_r. No cyclic-symmetry
assumption: the ring is the reference for the sector model (:class:`RingHB`, the
same AFT on the ring's own unknowns) and for the time integration (:mod:`timeint`).
"""
from __future__ import annotations

import numpy as np

from ..linear import LinearModel
from ..model import Model
from .hb import SectorHB, contact_elements, neighbour_map
from .sector import N_DOF, U_A, Y_D, Sector


def ring_model(sector: Sector, cf: float, f0: float, mu: float) -> Model:
    """The ring of N_r blades as a Model: matrices with the rim springs k_c between
    neighbours, C = beta K, one non-cyclic ContactElement per contact point."""
    nr = sector.cfg.ring_blades
    kc = float(sector.cfg["blade.k_c"])
    M = np.kron(np.eye(nr), sector.M)
    K = np.kron(np.eye(nr), sector.K_struct(0.0))
    for j in range(nr):  # rim spring k_c between blade j and j + 1
        a, c = N_DOF * j, N_DOF * ((j + 1) % nr)
        if a != c:
            K[np.ix_([a, c], [a, c])] += kc * np.array([[1.0, -1.0], [-1.0, 1.0]])
    els = []
    for j in range(nr):
        els += contact_elements(sector, mu, N_DOF * j, N_DOF * ((j + 1) % nr))
    f_static = np.zeros(N_DOF * nr)
    f_static[Y_D::N_DOF] = cf
    return Model(LinearModel(M=M, C=sector.beta * K, K=K), els, {0: f_static, 1: ring_forcing(sector, f0)},
                 U_A)


def ring_forcing(sector: Sector, f0: float) -> np.ndarray:
    """Complex EO force amplitudes F0 exp(i j phi) on u_a of every blade of the ring."""
    nr = sector.cfg.ring_blades
    f = np.zeros(N_DOF * nr, dtype=complex)
    f[U_A::N_DOF] = f0 * np.exp(1j * sector.cfg.phi * np.arange(nr))
    return f


class RingHB(SectorHB):
    """Harmonic balance of the whole ring (no cyclic reduction), same elements as the sector."""

    def __init__(self, sector: Sector, *args, **kw):
        self.blades = sector.cfg.ring_blades
        super().__init__(sector, *args, **kw)

    def _build_model(self) -> Model:
        return ring_model(self.sector, self.cf, self.f0, self.mu)

    def _eo_forcing(self) -> np.ndarray:
        return ring_forcing(self.sector, self.f0)

    def from_sector(self, x_sector: np.ndarray) -> np.ndarray:
        """Ring unknowns of a cyclic sector solution: blade j = rotation by j phi of blade 0."""
        X = x_sector.reshape(self.nb, N_DOF)
        phi = self.sector.cfg.phi
        return np.hstack([neighbour_map(self.basis, j * phi) @ X for j in range(self.blades)]).ravel()

    def blade(self, x: np.ndarray, j: int) -> np.ndarray:
        """Harmonics (n_b, 7) of blade j."""
        return x.reshape(self.nb, self.ndof)[:, N_DOF * j:N_DOF * (j + 1)]
