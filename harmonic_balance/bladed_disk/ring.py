"""Short full ring of N_r = N_b / gcd(N_b, EO) sectors closed periodically.

Blade j's DOFs are 7 j .. 7 j + 6 (sector ordering of :mod:`sector`); damper j touches
blade j and blade (j + 1) mod N_r. The EO force is F_j = F0 cos(omega t + j phi) on
u_a of blade j, phi = 2 pi EO / N_b = 2 pi EO_r / N_r. No cyclic-symmetry
assumption: the ring is the reference for the sector model (:class:`RingHB`, the
same AFT on the ring's own unknowns) and for the time integration (:mod:`timeint`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fmu_src.element import IwanElement

from .hb import SectorHB, neighbour_map, prestress, sector_basis
from .sector import N_DOF, U_A, Y_D, Sector


@dataclass
class RingMatrices:
    """Ring matrices (n = 7 N_r DOFs): M, K (structure), C (beta K + contact dashpots),
    Q (2 n_c, n) rows of p and s of every contact point, k (2 n_c,), points."""

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    k: np.ndarray
    points: list
    n_blades: int


def ring_matrices(sector: Sector) -> RingMatrices:
    """Assemble the ring of ``sector.cfg.ring_blades`` blades."""
    nr = sector.cfg.ring_blades
    n = N_DOF * nr
    b = sector.cfg.data["blade"]
    K0 = sector.K_struct(0.0)  # blade without the rim-to-rim springs
    M = np.kron(np.eye(nr), sector.M)
    K = np.kron(np.eye(nr), K0)
    for j in range(nr):  # rim spring k_c between blade j and j + 1
        a, c = N_DOF * j, N_DOF * ((j + 1) % nr)
        if a == c:
            continue
        K[a, a] += b["k_c"]
        K[c, c] += b["k_c"]
        K[a, c] -= b["k_c"]
        K[c, a] -= b["k_c"]
    rows = []
    for j in range(nr):
        cols = np.r_[N_DOF * j + np.arange(N_DOF), N_DOF * ((j + 1) % nr) + np.array([1, 2])]
        Qj = np.zeros((sector.Q.shape[0], n))
        np.add.at(Qj, (slice(None), cols), sector.Q)
        rows.append(Qj)
    Q = np.vstack(rows)
    k = np.tile(sector.k, nr)
    C = sector.beta * K + sector.beta_c * Q.T @ (k[:, None] * Q)
    return RingMatrices(M, K, C, Q, k, list(sector.points) * nr, nr)


class RingHB(SectorHB):
    """Harmonic balance of the whole ring (no cyclic reduction), same AFT as the sector."""

    def __init__(self, sector: Sector, H: int = 7, cf=None, f0=None, mu=None, n_t: int = 0):
        cfg = sector.cfg
        self.sector, self.H = sector, int(H)
        self.cf = cfg.cf if cf is None else float(cf)
        self.f0 = cfg.f0 if f0 is None else float(f0)
        self.mu = cfg.mu if mu is None else float(mu)
        self.ring = r = ring_matrices(sector)
        self.nr = r.n_blades
        self.basis = b = sector_basis(sector, self.H, n_t)
        self.static = prestress(sector, self.cf)
        self.nb, self.m, self.ndof = b.nb, r.Q.shape[0], r.M.shape[0]
        self.size = self.nb * self.ndof
        self.points = r.points
        self.elements = [IwanElement.jenkins(c.kt, self.mu) for c in self.points]
        self.s_static = np.tile(self.static["s"], self.nr)
        self.L = np.kron(np.eye(self.nb), r.Q)
        self.A0 = np.kron(np.eye(self.nb), r.K)
        self.A2 = np.kron(np.diag(b.order.astype(float) ** 2), r.M)
        self.C_contact = np.kron(b.dtheta, r.C - sector.beta * r.K)
        self.A1 = np.kron(b.dtheta, sector.beta * r.K) + self.C_contact
        self.Fext = np.zeros(self.size)
        self.set_f0(self.f0)
        F = self.Fext.reshape(self.nb, self.ndof)
        F[b.index(0)[0], Y_D::N_DOF] = self.cf
        self.evaluations = 0

    def set_f0(self, f0: float) -> None:
        self.f0 = float(f0)
        F = self.Fext.reshape(self.nb, self.ndof)
        ic, isn = self.basis.index(1)
        j = np.arange(self.nr)
        phi = self.sector.cfg.phi
        F[ic, U_A::N_DOF] = self.f0 * np.cos(j * phi)   # F0 cos(theta + j phi)
        F[isn, U_A::N_DOF] = -self.f0 * np.sin(j * phi)

    def from_sector(self, x_sector: np.ndarray) -> np.ndarray:
        """Ring unknowns of a cyclic sector solution: blade j = rotation by j phi of blade 0."""
        X = x_sector.reshape(self.nb, N_DOF)
        phi = self.sector.cfg.phi
        return np.hstack([neighbour_map(self.basis, j * phi) @ X for j in range(self.nr)]).ravel()

    def blade(self, x: np.ndarray, j: int) -> np.ndarray:
        """Harmonics (n_b, 7) of blade j."""
        return x.reshape(self.nb, self.ndof)[:, N_DOF * j:N_DOF * (j + 1)]

    def response(self, x: np.ndarray, dof: int = U_A) -> np.ndarray:
        return x.reshape(self.nb, self.ndof)[:, dof]

    def static_guess(self) -> np.ndarray:
        x = np.zeros((self.nb, self.ndof))
        x[self.basis.index(0)[0]] = np.tile(self.static["q"], self.nr)
        return x.ravel()

    def stuck_guess(self, omega: float) -> np.ndarray:
        return self.from_sector(SectorHB.stuck_guess(self._sector_hb(), omega))

    def _sector_hb(self):
        return SectorHB(self.sector, self.H, self.cf, self.f0, self.mu, self.basis.n_t)
