"""Nonlinear harmonic balance of the full mistuned ring of N_b sectors, sparse.

No cyclic symmetry: every blade and every damper has its own unknowns. The ring is a
standard :class:`~harmonic_balance.model.Model` (blades of :mod:`~harmonic_balance.bladed_disk.mistuning` (M1),
dampers j between blade j and blade j + 1 mod N_b with the sector's
:class:`~harmonic_balance.contact.ContactElement` points, :func:`.hb.contact_elements`;
CF on every damper's y_d mean, F_j = F0 exp(i j phi) on blade j's forced DOF), with the
residual of :class:`~harmonic_balance.residual.FullResidual`::

    R = A(omega) x + T F(Q x) - F_ext,
    A(omega) = I (x) K - omega^2 diag(h^2) (x) M + omega D_theta (x) C          (R1)

Unknowns x: the ring's harmonics, coefficient-major (coefficient c of ring DOF i at
``c n_ring + i``, as ``FullResidual``, which evaluates the same residual densely and is
the reference of the tests). Here A is sparse and each contact point's Jacobian block
``T_e dF_e/dU_e Q_e`` is dense on its own few DOFs' harmonics (n_b d_e, d_e = 5 for
UPD-24), so the Jacobian has O(N_b) non-zeros: blade blocks coupled to their
neighbours only. Its sparsity pattern is fixed: the assembly is one ``bincount`` of
the element blocks and A's entries into that pattern (no COO -> CSC conversion per
evaluation), and the Newton steps use a sparse LU (:mod:`.ring_solve`). Where the
compiled kernel is built (:mod:`.ring_lu_c`) A's values are summed in the pattern
and the contact blocks projected and added there in one C call, in the bincount's
order (the same sums; the projections' products to round-off).

The sliders start at the ring's own frictionless prestress state (as :mod:`.hb`).
Time samples: n_t a multiple of N_r = N_b / gcd(N_b, EO) (:func:`.hb.sector_basis`), so
each blade's tuned travelling-wave history is blade 0's shifted by a whole number of
samples and the tuned ring reproduces the cyclic sector to round-off.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..contact import frictionless_statics
from ..contact_many import LineContacts, evaluate_many, is_line_contact
from ..linear import LinearModel
from ..model import Model
from ..residual import FullResidual
from . import ring_lu_c
from .hb import contact_elements, loads, neighbour_map, sector_basis
from .mistuning import LinearRing, blade_stiffness, check_factors, ring_forcing, ring_structure
from .sector import Sector


class MistunedRingHB:
    """HB residual (R1) of the mistuned ring with its sparse exact Jacobian.

    Parameters
    ----------
    sector : Sector
    kappa : (N_b,) stiffness factors (:mod:`~harmonic_balance.bladed_disk.mistuning`; ones: the tuned ring)
    H : int            highest harmonic (0..H retained)
    cf, f0 : float     centrifugal load and EO force amplitude [N] (default: config)
    mu : float         friction coefficient (default: config)
    n_t : int          AFT samples (rounded up to a multiple of N_r)

    Attributes
    ----------
    blades, ndof : int        N_b and the ring's DOFs n_dof N_b
    nb, size : int            coefficients per DOF and unknowns n_b ndof
    model : Model             the ring as a dense Model (statics, time integration, tests)
    x_static : (ndof,) array  frictionless prestress state [m]
    """

    def __init__(self, sector: Sector, kappa, H: int = 7, cf=None, f0=None, mu=None,
                 n_t: int = 0):
        cfg = sector.cfg
        self.sector, self.H = sector, int(H)
        self.cf, self.f0, self.mu = loads(cfg, cf, f0, mu)
        self.kappa = check_factors(kappa, cfg.blades)
        self.blades = nbl = cfg.blades
        self.basis = sector_basis(sector, self.H, n_t)
        n = sector.n_dof
        self.ndof, self.nb = n * nbl, self.basis.nb
        self.size = self.nb * self.ndof
        M, K, C = ring_structure(sector, self.kappa)
        els = []
        for j in range(nbl):
            els += contact_elements(sector, self.mu, n * j, n * ((j + 1) % nbl))
        f_static = np.zeros(self.ndof)
        f_static[sector.y_d::n] = self.cf
        self.model = Model(LinearModel(M=M.toarray(), C=C.toarray(), K=K.toarray()), els,
                           {0: f_static, 1: ring_forcing(sector, nbl, n, self.f0)},
                           sector.response)
        self.x_static, _ = frictionless_statics(self.model, apply=True)
        self.points = els
        self._linear_operators(M, ring_structure(sector, np.ones(nbl))[1], C,
                               blade_stiffness(sector, nbl))
        self.set_scale(1.0)
        self._element_operators()
        self._pattern()
        self.Fext = self.model.forcing_coeffs(self.basis).ravel()
        self.evaluations = 0

    # ------------------------------------------------------------ assembly
    def _linear_operators(self, M, K_tuned, C, K0) -> None:
        b = self.basis
        h2 = sp.diags(b.order.astype(float) ** 2)
        I = sp.eye(b.nb)
        self._K = sp.kron(I, K_tuned, format="csr")
        self._K0 = sp.kron(I, K0, format="csr")  # scaled row-wise by kappa - 1 (M1)
        self._M = sp.kron(h2, M, format="csr")
        self._C = sp.kron(sp.csr_matrix(b.dtheta), C, format="csr")

    def set_scale(self, lam: float) -> None:
        """Residual of the pattern scaled to kappa(lam) = 1 + lam (kappa - 1) (lam = 1: the
        pattern; 0: tuned blades): a homotopy from the tuned ring. The prestress state,
        the sliders' reference and :attr:`model` stay those of lam = 1."""
        self.lam = float(lam)
        c = np.repeat(self.lam * (self.kappa - 1.0), self.sector.n_dof)
        self._c = np.tile(c, self.nb)

    def _element_operators(self) -> None:
        """Per element: global indices (n_b d,) of its DOFs' harmonics and its Q (m, d),
        stacked by shape (one batched product per group). The harmonics' operator is
        Q_b = I (x) Q, applied as Q per harmonic (not as the dense (n_b m, n_b d) Q_b:
        15 times fewer flops at H = 7)."""
        nb, groups = self.nb, {}
        for e, el in enumerate(self.points):
            kin = el.kinematics
            d = np.asarray(kin.dofs)
            gidx = (np.arange(nb)[:, None] * self.ndof + d[None, :]).ravel()
            groups.setdefault((el.m, d.size), []).append((e, gidx, np.asarray(kin.Q, dtype=float)))
        self._groups = [([e for e, _, _ in g], np.array([i for _, i, _ in g]),
                         np.array([q for _, _, q in g])) for g in groups.values()]
        # each group's contacts for evaluate_many, their constants read once (the sliders'
        # reference s_0 is set above, by the prestress state, and never changes)
        self._contacts = []
        for idx, _, _ in self._groups:
            els = [self.points[e] for e in idx]
            self._contacts.append(LineContacts(els, self.basis)
                                  if all(is_line_contact(el) for el in els) else els)

    def _pattern(self) -> None:
        """Fixed CSC pattern of the Jacobian and each contribution's place in it."""
        rows, cols = [], []
        coo = [A.tocoo() for A in (self._K, self._K0, self._M, self._C)]
        for c in coo:
            rows.append(c.row)
            cols.append(c.col)
        self._lin_data = [c.data for c in coo]
        self._K0_rows = coo[1].row
        for _, G, _ in self._groups:
            k = G.shape[1]
            rows.append(np.repeat(G, k, axis=1).ravel())
            cols.append(np.tile(G, (1, k)).ravel())
        key = np.concatenate(cols).astype(np.int64) * self.size + np.concatenate(rows)
        uniq, self._inv = np.unique(key, return_inverse=True)
        self._nnz = uniq.size
        self._indices = (uniq % self.size).astype(np.int32)
        self._indptr = np.searchsorted(uniq // self.size, np.arange(self.size + 1)).astype(np.int32)
        # the compiled assembly: A's four parts on the pattern, each block entry's place
        ends = np.cumsum([0] + [c.data.size for c in coo])
        self._lin_nnz = [np.bincount(self._inv[a:b], weights=d, minlength=self._nnz)
                         for a, b, d in zip(ends[:-1], ends[1:], self._lin_data)]
        self._blk_pos, at = [], ends[-1]
        for _, G, _ in self._groups:
            n = G.shape[0] * G.shape[1] ** 2
            k = G.shape[1]   # each block's places column by column (ring_assemble.c)
            pos = self._inv[at:at + n].astype(np.int32).reshape(-1, k, k).transpose(0, 2, 1)
            self._blk_pos.append(np.ascontiguousarray(pos))
            at += n
        self._cK0 = (None, None)
        self._lin_w = (None, None, None)

    def _linear_values(self, w: float) -> np.ndarray:
        """A(omega)'s values on the Jacobian's pattern (nnz,), summed as the bincount of
        :meth:`__call__` sums them (K, the scaled K0, M, C in turn; an absent part adds 0).
        A new array each call (the caller adds the contacts' blocks into it); the sums
        are kept for the last (omega, lam): Newton's iterations at one frequency copy them."""
        if self._lin_w[:2] != (w, self.lam):
            if self._cK0[0] != self.lam:
                self._cK0 = (self.lam, self._c[self._indices] * self._lin_nnz[1])
            K, _, M, C = self._lin_nnz
            self._lin_w = (w, self.lam, K + self._cK0[1] + -w * w * M + w * C)
        return self._lin_w[2].copy()

    # ------------------------------------------------------------ residual
    def __call__(self, x: np.ndarray, omega: float, jac: bool = True, rate: bool = False):
        """R (size,), and with ``jac`` dR/dx (size, size) sparse CSC and dR/domega (size,);
        with ``rate`` and not ``jac``: (R, dR/domega), no Jacobian (~40 % of its cost)."""
        self.evaluations += 1
        x = np.asarray(x, dtype=float)
        w = float(omega)
        Mx, Cx = self._M @ x, self._C @ x
        R = self._K @ x + self._c * (self._K0 @ x) - w * w * Mx + w * Cx - self.Fext
        Rw = -2.0 * w * Mx + Cx
        blocks, nb = [], self.nb
        compiled = jac and ring_lu_c.lib is not None
        data = self._linear_values(w) if compiled else None
        for (_, G, Q), pos, els in zip(self._groups, self._blk_pos, self._contacts):
            n_e, m, d = Q.shape
            # U_e = (I (x) Q) x_e: local harmonics (n_e, n_b, m)
            U = np.einsum("eja,eca->ecj", Q, x[G].reshape(n_e, nb, d))
            F, dF, dw = evaluate_many(els, U, self.basis, w, jac)
            np.add.at(R, G, _back(Q, F))
            if (jac or rate) and dw is not None:
                np.add.at(Rw, G, _back(Q, dw))
            if compiled:
                ring_lu_c.add_blocks(Q, dF, pos, data)
            elif jac:
                # (I (x) Q)^T dF (I (x) Q), dF rows/cols c m + j: Q on each harmonic's block
                dF = dF.reshape(n_e, nb * m * nb, m) @ Q
                blk = np.einsum("eja,ecjx->ecax", Q, dF.reshape(n_e, nb, m, nb * d))
                blocks.append(blk.ravel())
        if not jac:
            return (R, Rw) if rate else R
        if not compiled:
            K, K0, M, C = self._lin_data
            wts = np.concatenate([K, self._c[self._K0_rows] * K0, -w * w * M, w * C] + blocks)
            data = np.bincount(self._inv, weights=wts, minlength=self._nnz)
        J = sp.csc_matrix((data, self._indices, self._indptr), shape=(self.size, self.size))
        return R, J, Rw

    def dense_residual(self) -> FullResidual:
        """The same residual, dense (:class:`FullResidual` on :attr:`model`): the reference."""
        return FullResidual(self.model, self.basis)

    # ------------------------------------------------------------ starts
    def static_guess(self) -> np.ndarray:
        """The prestress state in the mean, no vibration."""
        x = np.zeros((self.nb, self.ndof))
        x[self.basis.index(0)[0]] = self.x_static
        return x.ravel()

    def stuck_guess(self, omega: float) -> np.ndarray:
        """Prestress mean + the linear stuck ring's response at harmonic 1."""
        x = self.static_guess().reshape(self.nb, self.ndof)
        lin = LinearRing(self.sector, self.kappa, "stuck", self.f0)
        from scipy.sparse.linalg import splu

        Z = (lin.K - omega * omega * lin.M + 1j * omega * lin.C).tocsc()
        U = splu(Z).solve(lin.F)
        ic, isn = self.basis.index(1)
        x[ic], x[isn] = U.real, -U.imag
        return x.ravel()

    def from_sector(self, x_sector: np.ndarray) -> np.ndarray:
        """Ring unknowns of a cyclic sector solution: blade j = blade 0 advanced by j phi."""
        X = np.asarray(x_sector).reshape(self.nb, self.sector.n_dof)
        phi = self.sector.cfg.phi
        return np.hstack([neighbour_map(self.basis, j * phi) @ X
                          for j in range(self.blades)]).ravel()

    # ------------------------------------------------------------ outputs
    def blade(self, x: np.ndarray, j: int) -> np.ndarray:
        """Harmonics (n_b, n_dof) of blade j."""
        n = self.sector.n_dof
        return x.reshape(self.nb, self.ndof)[:, n * j:n * (j + 1)]

    def amplitudes(self, x: np.ndarray) -> np.ndarray:
        """First-harmonic magnitude (N_b,) of every blade's response DOF [m]."""
        X = x.reshape(self.nb, self.ndof)[:, self.sector.response::self.sector.n_dof]
        return self.basis.magnitude(X, 1)

    def friction_energy(self, x: np.ndarray, omega: float) -> np.ndarray:
        """Friction energy per cycle [J] of every damper (N_b,) (its contact points' sampled
        loops, dashpots excluded)."""
        X = x.reshape(self.nb, self.ndof)
        W = np.zeros(len(self.points))
        for e, el in enumerate(self.points):
            U = X[:, list(el.kinematics.dofs)] @ el.kinematics.Q.T
            r = el.evaluate(U, self.basis, omega, jac=False)
            W[e] = r.W - r.W_viscous
        per = len(self.points) // self.blades
        return W.reshape(self.blades, per).sum(axis=1)



def _back(Q: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Local force harmonics f (n_e, n_b m) of a group's elements (Q: (n_e, m, d)) as their
    DOFs' harmonics (I (x) Q)^T f, (n_e, n_b d)."""
    n_e, m, _ = Q.shape
    return np.einsum("eja,ecj->eca", Q, f.reshape(n_e, -1, m)).reshape(n_e, -1)
