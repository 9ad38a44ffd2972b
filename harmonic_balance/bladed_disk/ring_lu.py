"""LU of the ring's Jacobians, one fixed sparsity pattern: the blades' block structure used.

The ring's Jacobian (:mod:`.ring_hb`) keeps its sparsity pattern over every Newton step,
frequency and scatter scale; only its values change. Three back ends, the same solutions
to round-off (``tests/upd/test_upd_ring_fast.py``):

* ``block`` (the default): :class:`BlockRingFactor`, Gaussian elimination blade by blade
  on the cyclic block-tridiagonal Jacobian with LAPACK (``getrf``/``getrs``) on each
  blade's dense block, the last blade the border that closes the ring; the loop over
  the blades and the refined solve are one compiled call each (``ring_lu.c`` through
  :mod:`.ring_lu_c`, scipy's LAPACK and BLAS), with this module's numpy loop as the
  reference and the fallback when the library is not built. At 24 blades, H = 7 (2520
  unknowns, 205k non-zeros): ~5 ms a factorization with single-precision factors and
  solves refined in double (~7 ms with double factors) against ~22-28 ms for SuperLU
  with its ordering each time. Its arithmetic is fixed by the pattern, so its bits are
  the same in a Dask worker and a serial run (one BLAS thread each).
* ``pardiso``: MKL PARDISO (pypardiso's library, the ``fast`` extra; opt-in with
  ``DAMPER_SOLVER=pardiso``), real nonsymmetric (mtype 11): the fill-reducing ordering
  and the symbolic factorization (phase 11, METIS) once for the pattern, then the
  numerical factorization (phase 22) and the solves (phase 33) per Jacobian, with
  PARDISO's pivot perturbation and iterative refinement: ~10 ms a factorization at 24
  blades. Its calls run on :func:`contact_core.linsolve.solver_threads` threads, but its
  last bits differ between a Dask worker and a serial run (its kernels depend on more
  than the thread count), and Newton's iterates and the per-blade peaks then differ in
  the ~8th digit.
* ``superlu``: scipy's SuperLU (COLAMD), the reference's factorization, always there
  (``DAMPER_SOLVER=superlu`` or ``scipy``; also for rings of fewer than 3 blades, and
  for a Jacobian the block elimination cannot pivot).
"""
from __future__ import annotations

import ctypes
import os

import numpy as np
from scipy.linalg.lapack import dgetrf, dgetrs, sgetrf, sgetrs
from scipy.sparse.linalg import splu

from contact_core import linsolve

from . import ring_lu_c


def ring_backend() -> str:
    """``DAMPER_SOLVER``: 'pardiso' (an error if it does not load), 'scipy' or 'superlu'
    (SuperLU), else 'block' (:class:`BlockRingFactor`)."""
    want = os.environ.get("DAMPER_SOLVER", "").strip().lower()
    if want == "pardiso" and linsolve.backend() == "pardiso":
        return "pardiso"
    return "superlu" if want in ("scipy", "superlu") else "block"


class SuperLUFactor:
    """SuperLU (COLAMD) of each Jacobian; ``factor(J)`` then ``solve(b)``."""

    name = "superlu"

    def __init__(self):
        self.lu = None

    def factor(self, J) -> None:
        """RuntimeError when J is singular."""
        self.lu = splu(J.tocsc(), permc_spec="COLAMD")

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.lu.solve(b)


class PardisoFactor:
    """PARDISO LU with the analysis of the first Jacobian's pattern reused (module docstring).

    ``factor(J)`` takes CSC or CSR; a CSC matrix is passed as the CSR of J^T and solved
    transposed (iparm[11] = 2), so no conversion is made per Jacobian.
    """

    name = "pardiso"

    def __init__(self):
        self.fn = linsolve._pardiso_lib()
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        self.pattern = None
        self.data = None

    def _call(self, phase: int, b: np.ndarray, x: np.ndarray) -> None:
        c, i32 = ctypes.c_int32, ctypes.POINTER(ctypes.c_int32)
        n = self.ia.size - 1
        err = c(0)
        with linsolve._pinned_mkl_threads():
            self.fn(self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ctypes.byref(c(1)),
                    ctypes.byref(c(1)), ctypes.byref(c(11)), ctypes.byref(c(phase)),
                    ctypes.byref(c(n)), self.data.ctypes.data, self.ia.ctypes.data_as(i32),
                    self.ja.ctypes.data_as(i32), None, ctypes.byref(c(1)),
                    self.iparm.ctypes.data_as(i32), ctypes.byref(c(0)), b.ctypes.data,
                    x.ctypes.data, ctypes.byref(err))
        if err.value != 0:
            raise RuntimeError(f"PARDISO error {err.value} in phase {phase} (singular Jacobian?)")

    def factor(self, J) -> None:
        """Numerical factorization of J (CSC or CSR, the pattern of the first call)."""
        csc = J.format == "csc"
        key = (csc, J.shape, J.indptr.tobytes(), J.indices.tobytes())
        self.data = np.ascontiguousarray(J.data, dtype=np.float64)
        dummy = np.zeros(J.shape[0])
        if key != self.pattern:
            self.release()
            self.ia = J.indptr.astype(np.int32)
            self.ja = J.indices.astype(np.int32)
            self.iparm[:] = 0
            # own iparm; METIS; 2 refinement steps; perturbation 1e-13; scaling; matching;
            # 0-based indices; a CSC J is the CSR of J^T: solve the transposed system
            self.iparm[[0, 1, 7, 9, 10, 12, 34]] = [1, 2, 2, 13, 1, 1, 1]
            self.iparm[11] = 2 if csc else 0
            self._call(11, dummy, dummy.copy())
            self.pattern = key
        self._call(22, dummy, dummy.copy())

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.ascontiguousarray(b, dtype=np.float64)
        x = np.zeros_like(b)
        self._call(33, b, x)
        return x

    def release(self) -> None:
        """Free PARDISO's memory (also when the pattern changes)."""
        if self.pattern is not None:
            dummy = np.zeros(1)
            self._call(-1, dummy, dummy.copy())
            self.pattern = None

    def __del__(self):
        try:
            self.release()
        except Exception:  # noqa: BLE001 - interpreter shutdown: the library may be gone
            pass


#: Relative residual |b - J x| / |b| a block solve must reach (after at most
#: :data:`BLOCK_REFINE` refinement steps on its own factors), else the Jacobian is
#: factored by SuperLU instead: block elimination pivots within each blade's block
#: only, so a nearly singular blade block (a blade's own resonance with its neighbours
#: held) would lose digits that SuperLU's global pivoting keeps.
BLOCK_RTOL, BLOCK_REFINE = 1e-10, 2
#: The block elimination's kernel when none is given: None for the compiled one where it is
#: built (else numpy), or 'c' / 'numpy' (``examples/bench_mistuning.py`` compares them).
BLOCK_KERNEL = None
#: Refinement steps allowed with single-precision factors (``precision="mixed"``): each
#: step gains ~-log10(cond(J) 6e-8) digits, 2-3 steps reach BLOCK_RTOL on UPD-24.
MIXED_REFINE = 6


class BlockRingFactor:
    """LU of the ring's Jacobian by block elimination over the blades (LAPACK, dense blocks).

    Ordered blade by blade (blade i's n_b n_dof unknowns, harmonic-major inside), the
    Jacobian is cyclic block-tridiagonal: D_i = J_ii dense-ish, and the couplings
    U_i = J_i,i+1, L_i = J_i,i-1 (indices mod N_b) non-zero only on the few DOFs the
    neighbours share (the rim; a damper and the next blade's platform). Blades
    0 .. N_b - 2 are eliminated in turn (Gaussian elimination by blocks, partial
    pivoting inside each block: ``getrf``), the last blade is the border that closes
    the ring; its Schur complement is factored at the end::

        D~_0 = D_0,  D~_(i+1) = D_(i+1) - L_(i+1) D~_i^-1 U_i,
        W_0 = L_0,   W_(i+1) = -L_(i+1) D~_i^-1 W_i        (fill in the border column)
        V_0 = U_(N-1), V_(i+1) = -V_i D~_i^-1 U_i           (fill in the border row)
        S = D_(N-1) - sum_i V_i D~_i^-1 W_i

    with U_(N-2) added to W_(N-2) and L_(N-1) to V_(N-2). Only the couplings'
    non-zero rows and columns enter the products, so a factorization costs about
    N_b (2/3 m^3 + 2 m^2 (k_U + k_L)) flops (m = n_b n_dof, k the couplings' column
    counts): at 24 UPD-24 blades, H = 7 (m = 105, k_U = 45, k_L = 60) ~70 Mflop on
    BLAS-3 kernels. Its arithmetic is fixed by the pattern (no data-dependent
    ordering), so results are bit-for-bit the same in every process with the same BLAS
    thread count.

    ``precision="mixed"`` (the default) factors in single precision and refines every
    solve in double (mixed-precision iterative refinement, Buttari et al. 2007): the
    residual r = b - J x in float64, the correction from the float32 factors, until
    |r| <= :data:`BLOCK_RTOL` |b| (:data:`MIXED_REFINE` steps at most). The
    factorization, flop-bound, costs ~25 % less (~5 against ~7 ms at 24 UPD-24 blades,
    compiled), a solve ~0.8 ms more (2-3 refinement steps); the solutions are those
    of the double factors to the same residual. ``"double"``: float64 factors.

    A solve is checked and refined (:data:`BLOCK_RTOL`, :data:`BLOCK_REFINE` or
    :data:`MIXED_REFINE`); where it stays inaccurate the Jacobian is factored by
    SuperLU instead (``fallbacks`` counts).

    Parameters
    ----------
    blades, n_dof, nb : int   N_b, DOFs per sector and coefficients per DOF; unknowns
        ordered coefficient-major over the ring (:mod:`.ring_hb`), N_b >= 3
    precision : 'mixed' or 'double'   of the factors (above)
    kernel : 'c', 'numpy' or None   the elimination and the refined solves as one compiled
        call each (``ring_lu.c``) or in numpy here (the reference the compiled one is
        tested against): the same steps on scipy's LAPACK, the products by scipy's BLAS
        or numpy's, so the same solutions to round-off; None: :data:`BLOCK_KERNEL`
    """

    name = "block"

    def __init__(self, blades: int, n_dof: int, nb: int, precision: str = "mixed",
                 kernel: str | None = None):
        if blades < 3:
            raise ValueError(f"block elimination needs >= 3 blades, not {blades}")
        self.N, self.m = int(blades), int(n_dof) * int(nb)
        nbl, c, d = np.meshgrid(np.arange(blades), np.arange(nb), np.arange(n_dof), indexing="ij")
        self.perm = (c * n_dof * blades + nbl * n_dof + d).ravel()   # blade-major -> ring index
        self.pattern = None
        self.fallback = SuperLUFactor()
        self.fallbacks = 0
        if precision not in ("mixed", "double"):
            raise ValueError(f"precision {precision!r}: give 'mixed' or 'double'")
        single = precision == "mixed"
        self.dt = np.float32 if single else np.float64
        self._rf = sgetrf if single else dgetrf
        self.refine = MIXED_REFINE if single else BLOCK_REFINE
        kernel = kernel or BLOCK_KERNEL or ("c" if ring_lu_c.lib is not None else "numpy")
        if kernel not in ("c", "numpy") or (kernel == "c" and ring_lu_c.lib is None):
            raise ValueError(f"kernel {kernel!r}: give 'numpy', or 'c' once ring_lu.c is "
                             "built (pip install -e .)")
        self.kernel = kernel

    # ------------------------------------------------------------ pattern
    def _analyse(self, J) -> None:
        """Where each stored entry of J goes (D, U or L of its block row) and the
        couplings' non-zero rows and columns, from the pattern (once per ring)."""
        N, m = self.N, self.m
        inv = np.empty_like(self.perm)
        inv[self.perm] = np.arange(self.perm.size)
        col = np.repeat(np.arange(J.shape[1]), np.diff(J.indptr))
        r, c = inv[J.indices], inv[col]
        bi, bj, ri, cj = r // m, c // m, r % m, c % m
        diag, up, lo = bi == bj, bj == (bi + 1) % N, bj == (bi - 1) % N
        if not np.all(diag | up | lo):
            raise ValueError("the Jacobian couples blades that are not neighbours")
        self.ur, self.uc = np.unique(ri[up]), np.unique(cj[up])
        self.lr, self.lc = np.unique(ri[lo]), np.unique(cj[lo])
        pos = lambda idx, n: np.searchsorted(idx, n)  # noqa: E731 - position in a sorted set
        ku, kl = self.uc.size, self.lc.size
        # one buffer: D (N, m, m) | U (N, m, k_U) on U's columns, both column-major
        # (LAPACK's order: no transposed copies) | L (N, |lr|, k_L)
        offs = np.cumsum([0, N * m * m, N * m * ku])
        dest = np.empty(J.indices.size, dtype=np.int64)
        dest[diag] = offs[0] + (bi[diag] * m + cj[diag]) * m + ri[diag]
        dest[up] = offs[1] + (bi[up] * ku + pos(self.uc, cj[up])) * m + ri[up]
        dest[lo] = offs[2] + (bi[lo] * self.lr.size + pos(self.lr, ri[lo])) * kl + pos(self.lc, cj[lo])
        self.dest, self.offs = dest, offs
        self.buf = np.zeros(offs[2] + N * self.lr.size * kl, dtype=self.dt)
        # the border's columns and rows: W's (L's columns, U's at the end), V's
        self.wc = np.union1d(self.lc, self.uc)
        self.vr = np.union1d(self.ur, self.lr)
        self.w_lc, self.w_uc = pos(self.wc, self.lc), pos(self.wc, self.uc)
        self.v_lr = pos(self.vr, self.lr)
        self.at_lr_uc = (self.uc[None, :] * m + self.lr[:, None]).ravel()   # (lr, uc), column-major
        if self.kernel == "c":
            sets = dict(uc=self.uc, lr=self.lr, lc=self.lc, wc=self.wc, vr=self.vr,
                        w_lc=self.w_lc, w_uc=self.w_uc, v_lr=self.v_lr)
            self.compiled = ring_lu_c.CompiledBlocks(N, m, sets, self.dt)
            self.c_index = [np.ascontiguousarray(a, dtype=np.int32)
                            for a in (self.perm, J.indptr, J.indices)]
        self.pattern = (J.shape, J.indptr.tobytes(), J.indices.tobytes())

    # ------------------------------------------------------------ factor, solve
    def factor(self, J) -> None:
        """Block factors of J (the ring's CSC pattern), or SuperLU's where a blade's
        block is singular; RuntimeError when J is."""
        J = J.tocsc()
        if J.dtype != np.float64:   # the compiled solve's residual reads float64
            J = J.astype(np.float64)
        if self.pattern is None or self.pattern[0] != J.shape or not (
                np.array_equal(np.frombuffer(self.pattern[1], J.indptr.dtype), J.indptr)
                and np.array_equal(np.frombuffer(self.pattern[2], J.indices.dtype), J.indices)):
            self._analyse(J)
        self.J, self.use_fallback = J, False
        if not (self.uc.size and self.lc.size):   # blades not coupled: nothing to eliminate by
            self._fall_back()
            return
        if self.kernel == "c":
            if not self.compiled.factor(np.ascontiguousarray(J.data), self.dest, self.buf):
                self._fall_back()
            return
        try:
            self._eliminate(J)
        except np.linalg.LinAlgError:
            self._fall_back()

    def _fall_back(self) -> None:
        self.fallbacks += 1
        self.use_fallback = True
        self.fallback.factor(self.J)

    def _eliminate(self, J) -> None:
        """The elimination of the class docstring; LinAlgError at a singular block.

        The fills are kept on their non-zero rows and columns: W_i on (lr, lc) and
        V_i on (vr, uc) for i < N_b - 2; blade N_b - 2 (both its neighbours in the
        border) on the border's columns wc and rows vr."""
        self.buf[self.dest] = J.data
        N, m, o = self.N, self.m, self.offs
        D = self.buf[:o[1]].reshape(N, m, m).transpose(0, 2, 1)
        U = self.buf[o[1]:o[2]].reshape(N, self.uc.size, m).transpose(0, 2, 1)
        self.L = L = self.buf[o[2]:].reshape(N, self.lr.size, self.lc.size)
        uc, lr, lc, wc, vr = self.uc, self.lr, self.lc, self.wc, self.vr
        kl = lc.size
        rhs = np.zeros((m, kl + uc.size), order="F", dtype=self.dt)   # [W_i | U_i]
        rhs[lr, :kl] = L[0]                            # W_0 = J_0,N-1
        V = U[N - 1][vr]                               # V_0 = J_N-1,0
        SV = np.zeros((vr.size, kl), dtype=self.dt)    # sum_i V_i D~_i^-1 W_i, i < N - 2
        Dt = D[0].copy(order="F")
        self.lus, self.g, self.vs = [], [], []
        for i in range(N - 2):
            rhs[:, kl:] = U[i]
            lu = self._getrf(Dt)
            g = _getrs(lu, rhs)                        # D~_i^-1 [W_i | U_i]
            gw, gu = g[:, :kl], g[:, kl:]
            SV += V @ gw[uc]
            self.lus.append(lu)
            self.g.append(g)
            self.vs.append(V)
            Dt = D[i + 1].copy(order="F")
            Dt.T.reshape(-1)[self.at_lr_uc] -= (L[i + 1] @ gu[lc]).ravel()
            rhs[lr, :kl] = -(L[i + 1] @ gw[lc])
            V = -(V @ gu[uc])
        # blade N - 2: the border is both its neighbours
        W = np.zeros((m, wc.size), order="F", dtype=self.dt)
        W[:, self.w_lc] = rhs[:, :kl]
        W[:, self.w_uc] += U[N - 2]
        Vl = np.zeros((vr.size, m), dtype=self.dt)
        Vl[:, uc] = V
        Vl[np.ix_(self.v_lr, lc)] += L[N - 1]
        lu = self._getrf(Dt)
        gw = _getrs(lu, W)
        S = D[N - 1].copy(order="F")
        S[np.ix_(vr, lc)] -= SV
        S[np.ix_(vr, wc)] -= Vl @ gw
        self.lus += [lu, self._getrf(S)]
        self.g.append(gw)
        self.vs.append(Vl)

    def _getrf(self, A):
        lu, piv, info = self._rf(A, overwrite_a=True)
        if info != 0:
            raise np.linalg.LinAlgError("singular block in the ring's block elimination")
        return lu, piv

    def _solve_blocks(self, b: np.ndarray) -> np.ndarray:
        N, m, kl = self.N, self.m, self.lc.size
        lr, lc, uc, wc, vr = self.lr, self.lc, self.uc, self.wc, self.vr
        y = b[self.perm].reshape(N, m).astype(self.dt)
        z = np.empty_like(y)
        yb = y[N - 1]
        for i in range(N - 2):          # forward: L^-1 b, blade by blade
            z[i] = _getrs(self.lus[i], y[i])
            y[i + 1, lr] -= self.L[i + 1] @ z[i, lc]
            yb[vr] -= self.vs[i] @ z[i, uc]
        z[N - 2] = _getrs(self.lus[N - 2], y[N - 2])
        yb[vr] -= self.vs[N - 2] @ z[N - 2]
        x = np.empty_like(y)
        x[N - 1] = xb = _getrs(self.lus[N - 1], yb)
        x[N - 2] = z[N - 2] - self.g[N - 2] @ xb[wc]
        for i in range(N - 3, -1, -1):  # backward: x_i = z_i - D~_i^-1 (W_i x_b + U_i x_i+1)
            g = self.g[i]
            x[i] = z[i] - g[:, :kl] @ xb[lc] - g[:, kl:] @ x[i + 1, uc]
        out = np.empty(b.shape)
        out[self.perm] = x.ravel()
        return out

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x with J x = b (refined; SuperLU when the block factors stay inaccurate)."""
        b = np.asarray(b, dtype=float)
        if self.use_fallback:
            return self.fallback.solve(b)
        if b.shape != (self.N * self.m,):   # the block sweeps take one right-hand side
            raise ValueError(f"b of shape {b.shape}: give one vector of {self.N * self.m}")
        if self.kernel == "c":
            perm, indptr, indices = self.c_index
            x = self.compiled.solve(perm, self.J, indptr, indices, np.ascontiguousarray(b),
                                    self.refine, BLOCK_RTOL)
            if x is not None:
                return x
            self._fall_back()
            return self.fallback.solve(b)
        x = self._solve_blocks(b)
        nb = np.linalg.norm(b)
        for k in range(self.refine + 1):
            r = b - self.J @ x
            if np.linalg.norm(r) <= BLOCK_RTOL * nb:
                return x
            if k < self.refine:
                x = x + self._solve_blocks(r)
        self._fall_back()
        return self.fallback.solve(b)


def _getrs(lu, b: np.ndarray) -> np.ndarray:
    x, info = (sgetrs if lu[0].dtype == np.float32 else dgetrs)(lu[0], lu[1], b)
    return x


def make_factor(name: str | None = None, blocks: tuple | None = None):
    """A fresh factor object of ``name`` ('block', 'pardiso', 'superlu'; default
    :func:`ring_backend`). 'block' needs ``blocks`` = (N_b, n_dof, n_b) of the ring and
    N_b >= 3 (else SuperLU)."""
    name = name or ring_backend()
    if name == "pardiso":
        return PardisoFactor()
    if name == "block" and blocks is not None and blocks[0] >= 3:
        return BlockRingFactor(*blocks)
    return SuperLUFactor()
