"""Short full ring of N_r = N_b / gcd(N_b, EO) sectors closed periodically.

Blade j's DOFs are n_dof j .. n_dof (j + 1) - 1 (sector ordering of :mod:`sector`, n_dof
= 7 for UPD-24); damper j touches blade j and blade (j + 1) mod N_r. The structure has
the blade's K on the diagonal blocks and K_next at (j, j+1), K_next^T at (j+1, j)
(:mod:`.blade` (B1)), damping likewise. The EO force is F_j = F0 cos(omega t + j phi) on
the forced DOF (u_a) of blade j, phi = 2 pi EO / N_b = 2 pi EO_r / N_r. No cyclic-symmetry
assumption: the ring is the reference for the sector model (:class:`RingHB`, the
same AFT on the ring's own unknowns) and for the time integration (:mod:`timeint`).
"""
from __future__ import annotations

import numpy as np

from ..linear import LinearModel
from ..model import Model
from .hb import SectorHB, contact_elements, neighbour_map
from .sector import Sector


def ring_matrices(sector: Sector, A: np.ndarray, A_next: np.ndarray | None) -> np.ndarray:
    """Ring matrix (n_dof N_r, n_dof N_r): blade blocks A (n, n) on the diagonal, A_next at
    (j, j+1) and A_next^T at (j+1, j), blades closed periodically (N_r = 1, 2 included)."""
    nr, n, nb = sector.cfg.ring_blades, sector.n_dof, sector.n_blade
    out = np.zeros((n * nr, n * nr))
    for j in range(nr):
        a, c = n * j, n * ((j + 1) % nr)
        out[a:a + nb, a:a + nb] += A
        if A_next is not None:
            out[a:a + nb, c:c + nb] += A_next
            out[c:c + nb, a:a + nb] += A_next.T
    return out


def ring_model(sector: Sector, cf: float, f0: float, mu: float) -> Model:
    """The ring of N_r blades as a Model: the blade matrices with their coupling to the
    neighbours (UPD-24: the rim springs k_c), one non-cyclic ContactElement per contact point."""
    nr, n, b = sector.cfg.ring_blades, sector.n_dof, sector.blade
    M = np.kron(np.eye(nr), sector.M)
    K = ring_matrices(sector, b.K, b.K_next)
    C = ring_matrices(sector, *b.damping_parts(sector.beta))
    els = []
    for j in range(nr):
        els += contact_elements(sector, mu, n * j, n * ((j + 1) % nr))
    f_static = np.zeros(n * nr)
    f_static[sector.y_d::n] = cf
    return Model(LinearModel(M=M, C=C, K=K), els, {0: f_static, 1: ring_forcing(sector, f0)},
                 sector.response)


def ring_forcing(sector: Sector, f0: float) -> np.ndarray:
    """Complex EO force amplitudes F0 exp(i j phi) on the forced DOF of every blade of the ring."""
    nr, n = sector.cfg.ring_blades, sector.n_dof
    f = np.zeros(n * nr, dtype=complex)
    f[sector.forced::n] = f0 * np.exp(1j * sector.cfg.phi * np.arange(nr))
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
        X = x_sector.reshape(self.nb, self.sector.n_dof)
        phi = self.sector.cfg.phi
        return np.hstack([neighbour_map(self.basis, j * phi) @ X for j in range(self.blades)]).ravel()

    def blade(self, x: np.ndarray, j: int) -> np.ndarray:
        """Harmonics (n_b, n_dof) of blade j."""
        n = self.sector.n_dof
        return x.reshape(self.nb, self.ndof)[:, n * j:n * (j + 1)]
