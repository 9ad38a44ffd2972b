"""The compiled block elimination of the ring (``ring_lu.c``) and the assembly of its
Jacobian's contact blocks (``ring_assemble.c``), through ctypes.

One C call factors the ring's Jacobian (the loop over the blades of
:class:`.ring_lu.BlockRingFactor`, LAPACK ``getrf``/``getrs`` and BLAS ``gemm`` on each
blade's blocks), one solves and refines in double against J. The LAPACK and BLAS are
scipy's: their addresses come from ``scipy.linalg.cython_lapack`` and ``cython_blas``
(PyCapsules) and are handed to the library once, so it links against nothing and its
dense kernels are the ones the numpy path calls. :data:`lib` is None when the library was
not built (``pip install -e .`` builds it); :class:`.ring_lu.BlockRingFactor` then runs
its numpy path, the same arithmetic.
"""
from __future__ import annotations

import ctypes as ct
import importlib.machinery
from pathlib import Path

import numpy as np
from scipy.linalg import cython_blas, cython_lapack

_I = np.ctypeslib.ndpointer(np.int32, flags="C_CONTIGUOUS")
_D = np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS")


class RingPattern(ct.Structure):
    """``ring_pattern`` of ring_lu.c: sizes and the couplings' index sets (int32)."""

    _fields_ = [(n, ct.c_int) for n in ("N", "m", "ku", "kl", "nlr", "nvr", "nwc")] + [
        (n, ct.POINTER(ct.c_int)) for n in ("uc", "lr", "lc", "wc", "vr", "w_lc", "w_uc", "v_lr")]


def pattern(N: int, m: int, sets: dict) -> tuple[RingPattern, list]:
    """The C pattern of N blades of m unknowns from the index sets (``uc``, ``lr``, ...,
    ``v_lr``: 1-D integer arrays); also the int32 arrays it points into (keep them)."""
    keep = {k: np.ascontiguousarray(v, dtype=np.int32) for k, v in sets.items()}
    p = RingPattern(N, m, keep["uc"].size, keep["lc"].size, keep["lr"].size, keep["vr"].size,
                    keep["wc"].size)
    for k, v in keep.items():
        setattr(p, k, v.ctypes.data_as(ct.POINTER(ct.c_int)))
    return p, list(keep.values())


def _capsule(module, name: str) -> int:
    """The address of scipy's ``name`` (a cython_lapack / cython_blas PyCapsule)."""
    api = ct.pythonapi
    api.PyCapsule_GetName.restype = ct.c_char_p
    api.PyCapsule_GetName.argtypes = [ct.py_object]
    api.PyCapsule_GetPointer.restype = ct.c_void_p
    api.PyCapsule_GetPointer.argtypes = [ct.py_object, ct.c_char_p]
    cap = module.__pyx_capi__[name]
    return api.PyCapsule_GetPointer(cap, api.PyCapsule_GetName(cap))


def _load():
    here = Path(__file__).resolve().parent
    path = next((here / f"_ring_lu{s}" for s in importlib.machinery.EXTENSION_SUFFIXES
                 if (here / f"_ring_lu{s}").exists()), None)
    if path is None:
        return None
    lib = ct.CDLL(str(path))
    lib.ringlu_set_kernels.restype = ct.c_int
    lib.ringlu_set_kernels.argtypes = [ct.c_void_p] * 6
    ptrs = [_capsule(cython_lapack, "sgetrf"), _capsule(cython_lapack, "sgetrs"),
            _capsule(cython_blas, "sgemm"), _capsule(cython_lapack, "dgetrf"),
            _capsule(cython_lapack, "dgetrs"), _capsule(cython_blas, "dgemm")]
    if lib.ringlu_set_kernels(*ptrs) != 0:
        return None
    for sfx, dt in (("_s", np.float32), ("_d", np.float64)):
        R = np.ctypeslib.ndpointer(dt, flags="C_CONTIGUOUS")
        f = getattr(lib, "ringlu_factor" + sfx)
        f.restype = ct.c_int
        f.argtypes = [ct.POINTER(RingPattern), ct.c_size_t,
                      np.ctypeslib.ndpointer(np.int64, flags="C_CONTIGUOUS"), _D, R, R, _I, R,
                      R, R, R]
        s = getattr(lib, "ringlu_solve" + sfx)
        s.restype = ct.c_int
        s.argtypes = [ct.POINTER(RingPattern), R, _I, R, R, R, R, R, _I, _D, _I, _I, _D,
                      ct.c_int, ct.c_double, _D]
    lib.ring_add_blocks.restype = None
    lib.ring_add_blocks.argtypes = [ct.c_int] * 4 + [_D, _D, _I, _D, _D]
    return lib


#: The loaded library, or None (not built).
lib = _load()


def add_blocks(Q: np.ndarray, dF: np.ndarray, pos: np.ndarray, data: np.ndarray) -> None:
    """``data[pos] +=`` each contact's block (I (x) Q_e)^T dF_e (I (x) Q_e) (ring_assemble.c).

    Parameters
    ----------
    Q : (n_e, m, d) float64          the contacts' local coordinates on their DOFs
    dF : (n_e, n_b m, n_b m) float64  their local Jacobians (rows/cols c m + j)
    pos : (n_e, n_b d, n_b d) int32   where each block entry goes in ``data``, [e, col, row]
    data : (nnz,) float64             the Jacobian's CSC values, added to in place
    """
    n_e, m, d = Q.shape
    nb = dF.shape[1] // m
    work = np.empty((nb * m + nb * d) * nb * d)
    lib.ring_add_blocks(n_e, nb, m, d, np.ascontiguousarray(Q), np.ascontiguousarray(dF), pos,
                        data, work)


class CompiledBlocks:
    """The factors of one ring pattern in the caller's arrays, filled by ring_lu.c.

    Parameters
    ----------
    N, m : int   blades and unknowns per blade
    sets : dict  the pattern's index sets (:func:`pattern`)
    dtype : float32 or float64   of the factors
    """

    def __init__(self, N: int, m: int, sets: dict, dtype):
        self.p, self._keep = pattern(N, m, sets)
        p, self.dt = self.p, np.dtype(dtype)
        sfx = "_s" if self.dt == np.float32 else "_d"
        self._factor, self._solve = getattr(lib, "ringlu_factor" + sfx), getattr(lib, "ringlu_solve" + sfx)
        # column-major matrices: the arrays are their transposes (rows = columns)
        e = lambda *s: np.empty(s, dtype=self.dt)  # noqa: E731 - the factors' arrays
        self.lus, self.piv = e(N, m, m), np.empty((N, m), dtype=np.int32)
        self.g, self.gl = e(N - 2, p.kl + p.ku, m), e(p.nwc, m)
        self.vs, self.vl = e(N - 2, p.ku, p.nvr), e(m, p.nvr)

    def factor(self, data: np.ndarray, dest: np.ndarray, buf: np.ndarray) -> bool:
        """Factor J, its stored values ``data`` (float64) scattered to ``buf[dest]``
        (:meth:`.BlockRingFactor._analyse`'s layout, the rest of ``buf`` zero); False at
        a singular blade block. MemoryError when C's work space fails."""
        st = self._factor(ct.byref(self.p), data.size, dest, data, buf, self.lus, self.piv,
                          self.g, self.gl, self.vs, self.vl)
        if st < 0:
            raise MemoryError("no memory for the ring's block elimination")
        self.buf = buf
        return st == 0

    def solve(self, perm, J, indptr, indices, b, refine: int, rtol: float):
        """x with J x = b refined to ``rtol`` (at most ``refine`` steps), or None when it
        stays above it. J: CSC (its data used; indptr, indices int32)."""
        x = np.empty(b.shape[0])
        st = self._solve(ct.byref(self.p), self.lus, self.piv, self.buf, self.g, self.gl,
                         self.vs, self.vl, perm, J.data, indptr, indices, b, refine, rtol, x)
        if st < 0:
            raise MemoryError("no memory for the ring's block solve")
        return x if st == 0 else None
