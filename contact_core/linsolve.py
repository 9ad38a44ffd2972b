"""Sparse symmetric positive-definite solves with many right-hand sides.

Three back ends, the same answers to round-off (tests/bench/test_linsolve.py):

* ``cholmod``: CHOLMOD from the system's SuiteSparse through scikit-sparse
  (``apt-get install libsuitesparse-dev`` as root, then ``pip install
  "scikit-sparse<0.5"``); used first where it imports.
* ``pardiso``: MKL PARDISO through pypardiso, a pip-only install with bundled
  binaries (the ``fast`` extra; Linux/Windows x86-64). Its Schur-complement mode
  (iparm[35]) returns the condensed stiffness on the contact DOFs directly.
  Measured on the 41x41 sphere condensation (one 75k-DOF block, same run):
  CHOLMOD 13.8 s, PARDISO 14.0 s, cvxopt's bundled CHOLMOD 59-167 s (no METIS),
  cholespy 236 s (no partial factor: one solve per contact DOF), SuperLU 127 s
  (python-mumps' wheel does not load under numpy 2; scikit-sparse ships no
  wheels). Chosen as the default where it installs.
* ``superlu``: scipy's SuperLU, always there. Told the matrix is symmetric
  (``MMD_AT_PLUS_A`` ordering, no pivoting) which keeps its fill close to a
  Cholesky factor.

``DAMPER_SOLVER`` = ``cholmod``, ``pardiso`` or ``scipy`` forces one back end
(an unavailable one is an error, not a silent fallback).

Reproducibility: a parallel sparse factorization sums in an order that depends on its
thread count, so the last bits of k_t differed between a serial run (MKL's default, one
thread per core) and a Dask worker (whose nanny sets ``MKL_NUM_THREADS=1``). Every PARDISO
call therefore runs on :data:`SOLVER_THREADS` threads wherever it runs (serial, Dask
worker, any machine): results are bit-for-bit the same across them. SuperLU is serial.
"""
from __future__ import annotations

import contextlib
import ctypes
import functools
import os

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: Right-hand sides per block solve (bounds the dense work array).
RHS_BLOCK = 256


#: Threads of every PARDISO call, whatever MKL_NUM_THREADS or the machine says
#: (``DAMPER_SOLVER_THREADS`` sets another count; results then differ in the last bits
#: from runs with another count). One: a Dask worker runs one task per core anyway; a
#: serial condensation gives up at most the second core's share of its wall time (CPU time
#: equal: 2.4 s vs 2.5 s user for a 64k-DOF Laplacian on one and two threads, 6d412c9).
SOLVER_THREADS_DEFAULT = 1


def solver_threads() -> int:
    """Threads of every PARDISO call: ``DAMPER_SOLVER_THREADS`` or :data:`SOLVER_THREADS_DEFAULT`."""
    text = os.environ.get("DAMPER_SOLVER_THREADS", "").strip()
    if not text:
        return SOLVER_THREADS_DEFAULT
    try:
        n = int(text)
    except ValueError:
        n = 0
    if not 1 <= n <= 1024:
        raise ValueError(f"DAMPER_SOLVER_THREADS={text!r}: give a whole number of threads from 1 to 1024")
    return n


@contextlib.contextmanager
def _pinned_mkl_threads():
    """Run the enclosed PARDISO calls on :func:`solver_threads` threads (MKL's thread-local
    setting, restored after: other MKL users in the process keep theirs)."""
    local = _mkl_set_threads_local()
    previous = local(solver_threads())
    try:
        yield
    finally:
        local(previous)


#: Back ends in order of preference; "superlu" is always available.
BACKENDS = ("cholmod", "pardiso", "superlu")
_ALIASES = {"scipy": "superlu"}


@functools.cache
def _available(name: str) -> bool:
    if name == "superlu":
        return True
    try:
        if name == "cholmod":
            import sksparse.cholmod  # noqa: F401
        else:
            _pardiso_lib()
    except (ImportError, OSError):
        return False
    return True


def available_backends() -> tuple[str, ...]:
    """The back ends that load on this machine, in order of preference."""
    return tuple(b for b in BACKENDS if _available(b))


def backend() -> str:
    """Name of the solver used: "cholmod", "pardiso" or "superlu".

    ``DAMPER_SOLVER`` forces one (``scipy`` is ``superlu``); otherwise the first
    available of BACKENDS.
    """
    want = os.environ.get("DAMPER_SOLVER", "").strip().lower()
    if want:
        want = _ALIASES.get(want, want)
        if want not in BACKENDS:
            raise ValueError(f"DAMPER_SOLVER={want!r}: use one of cholmod, pardiso, scipy")
        if not _available(want):
            raise ValueError(f"DAMPER_SOLVER={want!r} is not installed here (available: "
                             f"{', '.join(available_backends())}); unset DAMPER_SOLVER or install it "
                             "(pardiso: pip install pypardiso; cholmod: make accel)")
        return want
    return available_backends()[0]


def factorize(K: sp.spmatrix):
    """Factor a sparse SPD matrix; return ``solve(B) -> X`` for dense B (n, m)."""
    if backend() == "cholmod":
        from sksparse.cholmod import cholesky
        factor = cholesky(sp.csc_matrix(K))
        return factor
    if backend() == "pardiso":
        import pypardiso

        solver = pypardiso.PyPardisoSolver(mtype=2)  # real symmetric positive definite
        A = sp.triu(K, format="csr")
        with _pinned_mkl_threads():
            solver.factorize(A)

        def solve(B):
            with _pinned_mkl_threads():
                return solver.solve(A, B)
        return solve
    lu = spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    return lu.solve


def compliance_block(K: sp.spmatrix, dofs: np.ndarray, order: np.ndarray | None = None) -> np.ndarray:
    """Rows and columns ``dofs`` of K^-1: the compliance at those DOFs, shape (m, m).

    CHOLMOD: the DOFs are ordered last after a fill-reducing ordering of the
    rest, so the trailing block L22 of the Cholesky factor K = L L' satisfies
    L22 L22' = S, the Schur complement (condensed stiffness) on ``dofs``, and
    the compliance is S^-1 = L22^-T L22^-1: no solves with the whole factor.
    PARDISO: its Schur-complement mode returns S, inverted densely.
    SuperLU with a fill-reducing ``order`` (a permutation of K's rows, e.g. the
    mesh's nested dissection): the same with K = L U, S = L22 U22. Otherwise
    (or if a factorisation re-orders the trailing block) K X = E is solved for
    the unit vectors E of ``dofs`` in blocks of RHS_BLOCK.
    """
    name = backend()
    if name == "cholmod":
        C = _schur_compliance(sp.csc_matrix(K), dofs)
        if C is not None:
            return C
    elif name == "pardiso":
        return _schur_pardiso(K, dofs)
    elif order is not None:
        C = _schur_superlu(sp.csc_matrix(K), dofs, order)
        if C is not None:
            return C
    solve = factorize(K)
    n, m = K.shape[0], dofs.size
    C = np.empty((m, m))
    for start in range(0, m, RHS_BLOCK):
        cols = dofs[start:start + RHS_BLOCK]
        B = np.zeros((n, cols.size))
        B[cols, np.arange(cols.size)] = 1.0
        C[:, start:start + cols.size] = solve(B)[dofs]
    return 0.5 * (C + C.T)  # symmetric by Maxwell-Betti; remove round-off asymmetry


def _schur_compliance(K: sp.csc_matrix, dofs: np.ndarray) -> np.ndarray | None:
    """S^-1 from the trailing block of a Cholesky factor with ``dofs`` last (CHOLMOD)."""
    from sksparse.cholmod import analyze, cholesky

    n, m = K.shape[0], dofs.size
    order = analyze(K).P()
    is_dof = np.zeros(n, bool)
    is_dof[dofs] = True
    perm = np.concatenate([order[~is_dof[order]], dofs])
    factor = cholesky(K[perm][:, perm].tocsc(), ordering_method="natural")
    if not np.array_equal(factor.P(), np.arange(n)):
        return None
    L22 = factor.L()[n - m:, n - m:].toarray()
    Linv = sla.solve_triangular(L22, np.eye(m), lower=True, check_finite=False)
    C = Linv.T @ Linv
    return 0.5 * (C + C.T)


def _trailing_last(order: np.ndarray, dofs: np.ndarray, n: int) -> np.ndarray:
    """``order`` with ``dofs`` moved to the end (in the order given)."""
    is_dof = np.zeros(n, bool)
    is_dof[dofs] = True
    return np.concatenate([order[~is_dof[order]], dofs])


def _schur_superlu(K: sp.csc_matrix, dofs: np.ndarray, order: np.ndarray) -> np.ndarray | None:
    """S^-1 from the trailing blocks of K = L U (SuperLU, no pivoting) with ``dofs`` last."""
    n, m = K.shape[0], dofs.size
    if np.sort(order).size != n or not np.array_equal(np.sort(order), np.arange(n)):
        raise ValueError("order is not a permutation of the matrix rows")
    perm = _trailing_last(order, dofs, n)
    lu = spla.splu(K[perm][:, perm].tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    if not (np.array_equal(lu.perm_r, np.arange(n)) and np.array_equal(lu.perm_c, np.arange(n))):
        return None
    S = lu.L[n - m:, n - m:].toarray() @ lu.U[n - m:, n - m:].toarray()
    C = sla.inv(S, check_finite=False)
    return 0.5 * (C + C.T)


@functools.cache
def _mkl_set_threads_local():
    """MKL's ``mkl_set_num_threads_local(n) -> previous`` (0 restores the global setting)."""
    import pypardiso

    # the C entry point (the lower-case name is the Fortran one, taking a pointer)
    fn = pypardiso.PyPardisoSolver().libmkl.MKL_Set_Num_Threads_Local
    fn.argtypes = [ctypes.c_int]
    fn.restype = ctypes.c_int
    return fn


@functools.cache
def _pardiso_lib():
    """The MKL runtime's ``pardiso`` entry point, typed (loaded by pypardiso's lookup)."""
    import pypardiso

    fn = pypardiso.PyPardisoSolver()._mkl_pardiso
    i32 = ctypes.POINTER(ctypes.c_int32)
    fn.argtypes = [ctypes.POINTER(ctypes.c_int64)] + [i32] * 5 + [ctypes.c_void_p, i32, i32, i32, i32, i32, i32,
                                                                  ctypes.c_void_p, ctypes.c_void_p, i32]
    fn.restype = None
    return fn


def _schur_pardiso(K: sp.spmatrix, dofs: np.ndarray) -> np.ndarray:
    """S^-1 on ``dofs`` from PARDISO's Schur complement (mtype 2, iparm[35] = 1).

    PARDISO orders the rest itself (METIS), eliminates it and returns the dense
    Schur complement S (m, m) of the flagged rows in increasing index order.
    """
    fn = _pardiso_lib()
    n = K.shape[0]
    uniq, inv = np.unique(dofs, return_inverse=True)
    m = uniq.size
    A = sp.triu(K, format="csr")  # the upper triangle, as mtype 2 wants
    A.sort_indices()
    data = np.ascontiguousarray(A.data, dtype=np.float64)
    ia, ja = A.indptr.astype(np.int32), A.indices.astype(np.int32)
    iparm = np.zeros(64, dtype=np.int32)
    iparm[0], iparm[1], iparm[34], iparm[35] = 1, 2, 1, 1  # own iparm, METIS, 0-based, Schur
    flags = np.zeros(n, dtype=np.int32)
    flags[uniq] = 1
    S = np.zeros(m * m)
    pt = np.zeros(64, dtype=np.int64)
    err = ctypes.c_int32(0)
    i32 = ctypes.POINTER(ctypes.c_int32)

    def call(phase: int, x: np.ndarray) -> None:
        c = ctypes.c_int32
        fn(pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ctypes.byref(c(1)), ctypes.byref(c(1)),
           ctypes.byref(c(2)), ctypes.byref(c(phase)), ctypes.byref(c(n)), data.ctypes.data,
           ia.ctypes.data_as(i32), ja.ctypes.data_as(i32), flags.ctypes.data_as(i32), ctypes.byref(c(1)),
           iparm.ctypes.data_as(i32), ctypes.byref(c(0)), np.zeros(1).ctypes.data, x.ctypes.data,
           ctypes.byref(err))

    try:
        with _pinned_mkl_threads():
            call(12, S)  # analysis + factorisation; S receives the Schur complement
        if err.value != 0:
            why = "not positive definite" if err.value == -4 else "see the MKL PARDISO manual"
            raise np.linalg.LinAlgError(f"PARDISO error {err.value} factoring the stiffness ({why}); "
                                        "check the material data and the boundary conditions")
    finally:
        with _pinned_mkl_threads():
            call(-1, np.zeros(1))  # release PARDISO's memory
    S = S.reshape(m, m)
    C = sla.inv(0.5 * (S + S.T), check_finite=False)[np.ix_(inv, inv)]
    return 0.5 * (C + C.T)
