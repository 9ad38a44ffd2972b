"""Sparse LU of the ring's Jacobians, one fixed sparsity pattern: symbolic analysis reused.

The ring's Jacobian (:mod:`.ring_hb`) keeps its sparsity pattern over every Newton step,
frequency and scatter scale; only its values change. Two back ends, the same solutions
to round-off (``tests/upd/test_upd_ring_fast.py``):

* ``pardiso``: MKL PARDISO (pypardiso's library, the ``fast`` extra; opt-in), real
  nonsymmetric (mtype 11): the fill-reducing ordering and the symbolic factorization
  (phase 11, METIS) once for the pattern, then the numerical factorization (phase 22)
  and the solves (phase 33) per Jacobian, with PARDISO's pivot perturbation and
  iterative refinement. At 24 blades, H = 7 (2520 unknowns, 205k non-zeros): ~10 ms
  a factorization against ~24 ms for SuperLU with its ordering each time. Its calls
  run on :func:`contact_core.linsolve.solver_threads` threads (bit-for-bit the same
  wherever they run).
* ``superlu``: scipy's SuperLU (COLAMD), the reference's factorization, always there
  (the default).

SuperLU is the default: its solutions are bit-for-bit the same in every process, so a
study on Dask workers equals the serial one exactly. PARDISO, chosen with
``DAMPER_SOLVER=pardiso``, is faster (20 % less CPU time a UPD-24 sample, 43 % at 48 blades) and agrees to
round-off in each solve, but its last bits differ between a Dask worker and a serial
run (its kernels depend on more than the thread count), and Newton's iterates and the
per-blade peaks then differ in the ~8th digit.
"""
from __future__ import annotations

import ctypes
import os

import numpy as np
from scipy.sparse.linalg import splu

from contact_core import linsolve


def ring_backend() -> str:
    """'pardiso' when ``DAMPER_SOLVER=pardiso`` (an error if it does not load), else 'superlu'."""
    want = os.environ.get("DAMPER_SOLVER", "").strip().lower()
    return "pardiso" if want == "pardiso" and linsolve.backend() == "pardiso" else "superlu"


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


def make_factor(name: str | None = None):
    """A fresh factor object of ``name`` ('pardiso', 'superlu'; default :func:`ring_backend`)."""
    name = name or ring_backend()
    return PardisoFactor() if name == "pardiso" else SuperLUFactor()
