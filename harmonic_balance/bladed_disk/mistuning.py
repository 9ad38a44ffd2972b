"""Mistuning patterns of a bladed disk and the linear mistuned ring.

Symbols (and those of :mod:`.config`, :mod:`.blade`): N_b blades, blade j = 0..N_b-1;
kappa_j > 0 the stiffness factor of blade j, f_j = sqrt(kappa_j) its frequency factor;
K0 = K(0) = K + K_next + K_next^T the blade's stiffness with its neighbours moving with
it (the coupling idle).

Mistuned ring (blade j's DOFs at n j .. n (j + 1) - 1)::

    K_ring(kappa) = K_ring,tuned + blockdiag_j((kappa_j - 1) K0)                 (M1)

so blade j alone (neighbours in phase, damper removed) has its natural frequencies
multiplied by f_j exactly; the coupling to the neighbours (UPD-24: the rim springs
k_c), the masses, the damping (C = beta K of the *tuned* blade) and the contacts are
not mistuned. UPD-24: K0 holds k_g, k_rp, k_v and k_pa.

Random patterns: sample ``index`` of a study with ``seed`` draws from its own stream
``numpy.random.default_rng([seed, index])``, so a sample does not depend on how many
samples the study has or in which order they run (a resumed or extended study draws
the same patterns). ``kind = "stiffness"``: kappa_j = 1 + std z_j; ``"frequency"``:
f_j = 1 + std z_j, kappa_j = f_j^2; z_j standard normal, or uniform on
[-sqrt(3), sqrt(3)] (the same standard deviation). A drawn factor outside the range of
:func:`check_factors` is refused, not truncated (truncating would change the
distribution the study claims to sample): the std is too large for the distribution.

Linear limits of the ring (damper ``free``: removed; ``stuck``: contacts stuck;
``sliding``: normal springs only), sparse::

    (K_ring - omega^2 M_ring + i omega C_ring) U = F,   F_j = F0 exp(i j phi)   (M2)

on blade j's forced DOF, phi = 2 pi EO / N_b.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.optimize import minimize_scalar
from scipy.sparse.linalg import splu

from .sector import Sector

#: Pattern kinds and distributions.
KINDS = ("stiffness", "frequency")
DISTRIBUTIONS = ("normal", "uniform")
#: Relative frequency tolerance of a linear peak search.
PEAK_XTOL = 1e-9
#: Range of a stiffness factor kappa (frequency factor 0.5 ... 2): a blade whose natural
#: frequencies move by a factor of two is no longer a mistuned copy of the design but
#: another blade (manufacturing scatter is a few per cent), and far outside it the ring's
#: solve loses its meaning (kappa = 1e-300: a blade without stiffness, a peak at
#: -1e-124 Hz; kappa = 1e308: a singular matrix).
KAPPA_MIN, KAPPA_MAX = 0.25, 4.0


def check_factors(kappa, n_blades: int, what: str = "mistuning pattern",
                  kind: str = "stiffness") -> np.ndarray:
    """Stiffness factors (N_b,) as floats; ValueError naming the first bad entry.

    ``kind``: whether ``kappa`` holds stiffness factors or frequency factors (kappa =
    f^2); the message names the factor as given. Each must lie in
    [:data:`KAPPA_MIN`, :data:`KAPPA_MAX`] as a stiffness factor.
    """
    try:
        k = np.asarray(kappa, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: factors must be numbers, got {kappa!r}") from None
    if k.size != n_blades:
        raise ValueError(f"{what}: {k.size} factors for {n_blades} blades (give one per blade)")
    lo, hi = (KAPPA_MIN, KAPPA_MAX) if kind == "stiffness" else (KAPPA_MIN ** 0.5, KAPPA_MAX ** 0.5)
    for j, v in enumerate(k):
        if not np.isfinite(v) or v <= 0.0:
            raise ValueError(f"{what}: blade {j} factor {v} must be finite and > 0 "
                             "(a factor multiplies the blade's stiffness)")
        if not lo <= v <= hi:
            raise ValueError(f"{what}: blade {j} {kind} factor {v:.6g} is outside [{lo:g}, {hi:g}] "
                             "(the blade's frequencies would move by more than a factor of two: "
                             "another blade, not a mistuned one)")
    return k if kind == "stiffness" else k * k


def draw_factors(n_blades: int, std: float, seed: int, index: int, kind: str = "stiffness",
                 distribution: str = "normal") -> np.ndarray:
    """Stiffness factors kappa (N_b,) of sample ``index`` (module docstring).

    Raises
    ------
    ValueError
        std not finite or negative, an unknown kind or distribution, or a drawn
        blade whose stiffness (or frequency) factor is not positive (std too large).
    """
    if not (np.isfinite(std) and std >= 0.0):
        raise ValueError(f"mistuning std = {std} must be finite and >= 0")
    if kind not in KINDS or distribution not in DISTRIBUTIONS:
        raise ValueError(f"mistuning kind {kind!r} / distribution {distribution!r}: "
                         f"kinds {KINDS}, distributions {DISTRIBUTIONS}")
    rng = np.random.default_rng([int(seed), int(index)])
    z = (rng.standard_normal(n_blades) if distribution == "normal"
         else rng.uniform(-np.sqrt(3.0), np.sqrt(3.0), n_blades))
    f = 1.0 + std * z
    lo, hi = (KAPPA_MIN, KAPPA_MAX) if kind == "stiffness" else (KAPPA_MIN ** 0.5, KAPPA_MAX ** 0.5)
    bad = np.flatnonzero((f < lo) | (f > hi))
    if bad.size:
        raise ValueError(f"mistuning sample {index}: blade {bad[0]} gets a {kind} factor "
                         f"{f[bad[0]]:.4g} outside [{lo:g}, {hi:g}] (std {std} is too large for a "
                         f"{distribution} scatter; use a smaller std"
                         + (" or the uniform distribution)" if distribution == "normal" else ")"))
    return f if kind == "stiffness" else f * f


def frequency_factors(kappa) -> np.ndarray:
    """Frequency factors f_j = sqrt(kappa_j) of the blades alone."""
    return np.sqrt(np.asarray(kappa, dtype=float))


# ------------------------------------------------------------------ ring assembly
def ring_blocks(n_blades: int, n: int, diag, nxt=None) -> sp.csr_matrix:
    """Sparse ring matrix (n N_b, n N_b): ``diag[j]`` (n, n) on blade j's block, ``nxt``
    (n, n) at (j, j+1) and its transpose at (j+1, j), closed periodically."""
    rows, cols, vals = [], [], []
    for j in range(n_blades):
        a, c = n * j, n * ((j + 1) % n_blades)
        blocks = [(a, a, diag[j])]
        if nxt is not None:
            blocks += [(a, c, nxt), (c, a, nxt.T)]
        for r0, c0, B in blocks:
            i, k = np.nonzero(B)
            rows.append(r0 + i)
            cols.append(c0 + k)
            vals.append(B[i, k])
    size = n * n_blades
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(size, size))


def scatter_local(size: int, dofs_list, blocks) -> sp.csr_matrix:
    """Sparse (size, size) sum of dense ``blocks[e]`` on the DOFs ``dofs_list[e]``."""
    rows, cols, vals = [], [], []
    for d, B in zip(dofs_list, blocks):
        d = np.asarray(d)
        rows.append(np.repeat(d, d.size))
        cols.append(np.tile(d, d.size))
        vals.append(np.asarray(B, dtype=float).ravel())
    if not rows:
        return sp.csr_matrix((size, size))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(size, size))


def damper_dofs(sector: Sector, n_blades: int) -> list:
    """Per damper j: ring DOFs of the extended sector vector ``[q_j, right point of j+1]``
    (the columns of ``Sector.Q``)."""
    n = sector.n_dof
    right = np.asarray(sector.blade.right)
    return [np.r_[n * j + np.arange(n), n * ((j + 1) % n_blades) + right] for j in range(n_blades)]


def ring_structure(sector: Sector, kappa, free: bool = False):
    """Sparse (M, K, C) of the mistuned ring's blades (M1), no contacts.

    ``free``: the blades' own n DOFs per blade (damper removed); otherwise the sector's
    n_dof per blade (the damper's DOFs carry its mass, no stiffness).
    """
    b, nb = sector.blade, len(kappa)
    C_own, C_next = b.damping_parts(sector.beta)
    pad, n = ((lambda A: A), b.n) if free else (sector._pad, sector.n_dof)
    nxt = None if b.K_next is None else pad(b.K_next)
    M = ring_blocks(nb, n, [b.M if free else sector.M] * nb)
    K = ring_blocks(nb, n, [pad(b.K)] * nb, nxt)
    K = K + sp.diags(np.repeat(np.asarray(kappa, float) - 1.0, n)) @ blade_stiffness(sector, nb, free)
    C = ring_blocks(nb, n, [pad(C_own)] * nb, None if C_next is None else pad(C_next))
    return M, K.tocsr(), C


def blade_stiffness(sector: Sector, n_blades: int, free: bool = False) -> sp.csr_matrix:
    """blockdiag_j(K0) (sparse): the part of the ring's stiffness that (M1) scales."""
    K0 = sector.blade.stiffness(0.0).real
    return ring_blocks(n_blades, K0.shape[0] if free else sector.n_dof,
                       [K0 if free else sector._pad(K0)] * n_blades)


def ring_linear(sector: Sector, kappa, damper: str):
    """Sparse (M, K, C) of the mistuned ring (M1) in a linear damper state.

    Parameters
    ----------
    sector : Sector
    kappa : (N_b,) stiffness factors
    damper : 'free' (removed: n_blade DOFs per blade), 'stuck' or 'sliding' (n_dof per
        blade; :meth:`Sector.matrices`)

    Returns
    -------
    M, K, C : csr (n N_b, n N_b), n the DOFs per blade
    """
    if damper not in ("free", "stuck", "sliding"):
        raise ValueError(f"damper must be 'free', 'stuck' or 'sliding', got {damper!r}")
    M, K, C = ring_structure(sector, kappa, damper == "free")
    if damper != "free":
        nb, size = len(kappa), M.shape[0]
        QtQ = lambda k: sector.Q.T @ (k[:, None] * sector.Q)  # noqa: E731
        kn_only = sector.k.copy()  # keep the normal row (the first of each point)
        kn_only[np.arange(kn_only.size) % sector.rows_per_point != 0] = 0.0
        dofs = damper_dofs(sector, nb)
        K = K + scatter_local(size, dofs, [QtQ(sector.k if damper == "stuck" else kn_only)] * nb)
        C = C + sector.beta_c * scatter_local(size, dofs, [QtQ(sector.k)] * nb)
    return M.tocsr(), K.tocsr(), C.tocsr()


def ring_forcing(sector: Sector, n_blades: int, n: int, f0: float) -> np.ndarray:
    """Complex EO force amplitudes (n N_b,): F0 exp(i j phi) on blade j's forced DOF."""
    f = np.zeros(n * n_blades, dtype=complex)
    f[sector.forced::n] = f0 * np.exp(1j * sector.cfg.phi * np.arange(n_blades))
    return f


class LinearRing:
    """Linear mistuned ring (M2): per-blade response amplitudes and peaks.

    Parameters
    ----------
    sector : Sector
    kappa : (N_b,) stiffness factors (N_b = the config's blades)
    damper : 'free', 'stuck' or 'sliding'
    f0 : float, optional  EO force amplitude [N] (default: config)
    """

    def __init__(self, sector: Sector, kappa, damper: str, f0: float | None = None):
        self.sector, self.damper = sector, damper
        self.kappa = check_factors(kappa, sector.cfg.blades)
        self.M, self.K, self.C = ring_linear(sector, self.kappa, damper)
        self.n = sector.n_blade if damper == "free" else sector.n_dof
        self.f0 = sector.cfg.f0 if f0 is None else float(f0)
        self.F = ring_forcing(sector, self.kappa.size, self.n, self.f0)
        self.out = np.arange(self.kappa.size) * self.n + sector.response
        self.solves = 0

    def response(self, omega: float) -> np.ndarray:
        """Complex first-harmonic amplitudes (N_b,) of every blade's response DOF."""
        Z = (self.K - omega * omega * self.M + 1j * omega * self.C).tocsc()
        self.solves += 1
        return splu(Z).solve(self.F)[self.out]

    def natural_frequencies(self) -> np.ndarray:
        """Undamped natural angular frequencies of the ring (K - omega^2 M) phi = 0 [rad/s],
        ascending (dense: n N_b is a few hundred)."""
        from scipy.linalg import eigh

        lam = eigh(self.K.toarray(), self.M.toarray(), eigvals_only=True)
        return np.sqrt(np.clip(lam, 0.0, None))

    def peaks(self, omegas) -> tuple[np.ndarray, np.ndarray]:
        """Peak amplitude [m] and its frequency [rad/s] of every blade, shape (N_b,) each.

        Every local maximum of a blade's amplitude is refined, not only the largest (a
        mistuned blade has several close peaks, and the grid's largest value need not be
        the highest: 12 % lower measured on UPD-24, std 0.02): the local maxima on the
        grid ``omegas`` and on that grid completed by the ring's natural frequencies
        inside it (near which the peaks of a lightly damped ring lie: a peak on the flank
        of another, no local maximum of the grid alone, becomes one). Each is refined by
        Brent's bounded search on each of the two grid cells beside it separately (two
        peaks may share a bracket of two cells, where one search would find either), to
        :data:`PEAK_XTOL` relative. The largest of the refined values is the peak.
        """
        grid = np.asarray(omegas, dtype=float)
        w_n = self.natural_frequencies()
        full = np.union1d(grid, w_n[(w_n > grid[0]) & (w_n < grid[-1])])
        A = np.abs(np.array([self.response(w) for w in full]))  # (n_f, N_b)
        on_grid = np.isin(full, grid)
        amp, wpk = A.max(axis=0), full[A.argmax(axis=0)]
        for j in range(self.kappa.size):
            cells = set()
            for w, a in ((grid, A[on_grid, j]), (full, A[:, j])):
                for i in np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1:
                    cells |= {(w[i - 1], w[i]), (w[i], w[i + 1])}
            for lo, hi in sorted(cells):
                res = minimize_scalar(lambda x, j=j: -abs(self.response(x)[j]), bounds=(lo, hi),
                                      method="bounded", options={"xatol": PEAK_XTOL * hi})
                if -res.fun > amp[j]:
                    amp[j], wpk[j] = -res.fun, res.x
        return amp, wpk


def tuned_linear_peak(sector: Sector, omegas, damper: str, f0: float | None = None):
    """(omega [rad/s], amplitude [m]) of the tuned sector's linear peak on the band of
    ``omegas`` (:func:`.sector.peak_of` on the sector's direct solve)."""
    from .sector import linear_response, peak_of

    r = sector.response
    omegas = np.asarray(omegas, dtype=float)
    return peak_of(lambda w: abs(linear_response(sector, [w], damper, f0)[0, r]),
                   omegas[0], omegas[-1], omegas.size)


def whitehead_bound(n_blades: int) -> float:
    """Whitehead's (1966) largest forced-response amplification of a mistuned disk,
    (1 + sqrt(N_b)) / 2."""
    return 0.5 * (1.0 + np.sqrt(n_blades))


class LinearRingFamily:
    """The linear rings (M2) of one sector and damper state, for any pattern: the tuned
    ring's matrices and blockdiag(K0) built once on one sparsity pattern (their union), so
    a pattern's stiffness (M1) and each frequency's dynamic stiffness
    K - omega^2 M + i omega C are sums of data arrays, not sparse-matrix algebra (which
    took ~70 % of a 24-blade linear sample). For a batch of patterns (a Monte Carlo chunk).

    Parameters
    ----------
    sector : Sector
    damper : 'free', 'stuck' or 'sliding'
    f0 : float, optional  EO force amplitude [N] (default: config)
    """

    def __init__(self, sector: Sector, damper: str, f0: float | None = None):
        nb = sector.cfg.blades
        self.tuned = LinearRing(sector, np.ones(nb), damper, f0)
        t = self.tuned
        B = blade_stiffness(sector, nb, damper == "free")
        P = (abs(t.K) + abs(t.M) + abs(t.C) + abs(B)).tocsc()
        P.sort_indices()
        self.indices, self.indptr, self.shape = P.indices, P.indptr, P.shape
        cols = np.repeat(np.arange(P.shape[1]), np.diff(P.indptr))
        self._keys = cols * P.shape[0] + P.indices          # sorted: column-major positions
        self.K0, self.M, self.C, self.B = (self._on_pattern(A) for A in (t.K, t.M, t.C, B))
        self.rows = P.indices
        # one complex matrix on the pattern whose data each solve overwrites (building a
        # csc_matrix checks its format: a third of a solve at 24 blades)
        self.Z = sp.csc_matrix((np.zeros(self._keys.size, complex), P.indices, P.indptr), shape=P.shape)

    def _on_pattern(self, A) -> np.ndarray:
        """The entries of sparse ``A`` as a data array on the union pattern."""
        A = A.tocoo()
        pos = np.searchsorted(self._keys, A.col * self.shape[0] + A.row)
        d = np.zeros(self._keys.size, dtype=A.dtype)
        np.add.at(d, pos, A.data)
        return d

    def ring(self, kappa) -> LinearRing:
        """The LinearRing of the stiffness factors ``kappa`` (N_b,), equal to
        ``LinearRing(sector, kappa, damper, f0)`` to round-off."""
        return _FamilyRing(self, check_factors(kappa, self.tuned.kappa.size))


class _FamilyRing(LinearRing):
    """A LinearRing of a :class:`LinearRingFamily` (its data arrays on the shared pattern)."""

    def __init__(self, family: LinearRingFamily, kappa: np.ndarray):
        self.__dict__.update(family.tuned.__dict__)
        self.family, self.kappa, self.solves = family, kappa, 0
        self.k_data = family.K0 + np.repeat(kappa - 1.0, self.n)[family.rows] * family.B   # (M1)
        self.K = sp.csc_matrix((self.k_data, family.indices, family.indptr), shape=family.shape)

    def response(self, omega: float) -> np.ndarray:
        f = self.family
        f.Z.data[:] = self.k_data - omega * omega * f.M + 1j * omega * f.C
        self.solves += 1
        return splu(f.Z).solve(self.F)[self.out]
