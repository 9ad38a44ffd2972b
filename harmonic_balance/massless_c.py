"""The massless node solve of one history in one C call per step (``fmu_src/core/march_step.c``).

:meth:`.massless.MasslessContacts.solve` on one history with a
:class:`~.massless.FactorCache` (the condensed surface's march) spends its time in numpy
calls on arrays of a few dozen entries; ``march_step.c`` makes the same step (the trial
forces from the C core's Iwan step, Newton with the side passes, the factors kept by
contact state, the line search) in one call, operation for operation, so the numpy path
stays its reference (tests/hb/test_massless_c.py); :class:`CompiledSensitivity` advances
the march's forward sensitivities likewise (``march_sens.c``). LAPACK getrf/getrs and BLAS gemv are
scipy's, their addresses handed to the library once (as :mod:`.bladed_disk.ring_lu_c`
does), so it links against nothing. :data:`lib` is None when the library lacks the step
(an old build); :class:`CompiledStep` is then not used.

The step applies to blocks below :data:`.massless.DIAGONAL_UPDATE_MIN` DOFs whose contact
rows are one entry each (:meth:`CompiledStep.fits`); larger blocks stay on the numpy
path's diagonal updates.
"""
from __future__ import annotations

import ctypes as ct
from types import SimpleNamespace

import numpy as np
from scipy.linalg import cython_blas, cython_lapack

from fmu_src._clib import STATE_DTYPE, IwanInputError, Model, StateArray, arr
from fmu_src._clib import lib as _iwan

from .bladed_disk.ring_lu_c import _capsule

#: Factorizations kept per block (the stick phases' and the repeated period's settled
#: sets; a slot is m^2 doubles, 32 kB at the 63 DOFs of 5 nodes per side).
SLOTS = 16

_P32 = ct.POINTER(ct.c_int32)
_PD = ct.POINTER(ct.c_double)


class MsurfModel(ct.Structure):
    """``msurf_model`` of march_step.h."""
    _fields_ = ([(n, ct.c_int32) for n in ("n_b", "n_c", "n_f", "n_blocks", "n_laws")]
                + [(n, _PD) for n in ("kn", "p0", "s0", "kt_stuck")]
                + [(n, _P32) for n in ("cs", "cp")] + [(n, _PD) for n in ("qs", "qp")]
                + [(n, _P32) for n in ("f_contact", "f_law")] + [("f_c", _PD)]
                + [("laws", ct.POINTER(ct.POINTER(Model)))]
                + [(n, _PD) for n in ("law_r0", "law_r1")]
                + [(n, _P32) for n in ("blk_ptr", "blk_dofs", "blk_cptr", "blk_c", "blk_ls", "blk_lp")]
                + [("blk_A", _PD)]
                + [(n, ct.c_double) for n in ("fd_rel", "rtol", "section_rtol", "round_scale")]
                + [(n, ct.c_int32) for n in ("max_sides", "max_bracket", "max_section", "n_slots")]
                + [(n, ct.c_int32) for n in ("diag_min", "n_refs")] + [("ref_share", ct.c_double)])


class MsurfRefs(ct.Structure):
    """``msurf_refs`` of march_step.h."""
    _fields_ = [(n, _PD) for n in ("inv", "dref")] + [(n, ct.POINTER(ct.c_int64)) for n in ("id", "used")] \
        + [(n, ct.c_int64) for n in ("clock", "count")]


class MsurfSens(ct.Structure):
    """``msurf_sens`` of march_step.h."""
    _fields_ = ([(n, ct.c_int32) for n in ("n_d", "ns_max", "r")] + [(n, _PD) for n in ("dw", "dz", "duc", "AR")]
                + [("order", _P32)])


class MsurfCache(ct.Structure):
    """``msurf_cache`` of march_step.h."""
    _fields_ = [("keys", _PD), ("lu", _PD), ("piv", _P32), ("used", ct.POINTER(ct.c_int64)),
                ("clock", ct.c_int64), ("refs", ct.POINTER(MsurfRefs))]


def _load():
    if not hasattr(_iwan, "msurf_solve"):
        return None
    _iwan.msurf_set_kernels.restype = ct.c_int
    _iwan.msurf_set_kernels.argtypes = [ct.c_void_p] * 4
    if _iwan.msurf_set_kernels(_capsule(cython_lapack, "dgetrf"), _capsule(cython_lapack, "dgetrs"),
                               _capsule(cython_blas, "dgemv"), _capsule(cython_blas, "dgemm")) != 0:
        return None
    pm = ct.POINTER(MsurfModel)
    for name in ("msurf_work_size", "msurf_state_work_size"):
        getattr(_iwan, name).restype = ct.c_size_t
        getattr(_iwan, name).argtypes = [pm]
    _iwan.msurf_cache_sizes.restype = None
    _iwan.msurf_cache_sizes.argtypes = [pm] + [ct.POINTER(ct.c_size_t)] * 3
    _iwan.msurf_refs_sizes.restype = None
    _iwan.msurf_refs_sizes.argtypes = [pm] + [ct.POINTER(ct.c_size_t)] * 2
    _iwan.msurf_sens_work_size.restype = ct.c_size_t
    _iwan.msurf_sens_work_size.argtypes = [pm, ct.POINTER(MsurfSens)]
    _iwan.msurf_advance.restype = ct.c_int
    _iwan.msurf_advance.argtypes = [pm, ct.POINTER(MsurfCache), ct.POINTER(MsurfSens), StateArray,
                                    StateArray, _PD, _PD, _PD]
    _iwan.msurf_solve.restype = ct.c_int
    _iwan.msurf_solve.argtypes = [pm, ct.POINTER(MsurfCache), StateArray, _PD, _PD, ct.c_int32,
                                  _PD, StateArray, _P32]
    return _iwan


#: The library with the step, or None.
lib = _load()

_MESSAGES = {2: "a node displacement or force is not finite", 4: "the step's LAPACK kernels are not set"}


class CompiledStep:
    """The C step for one :class:`~.massless.MasslessContacts` of one history.

    Parameters
    ----------
    nodes : MasslessContacts
        With n_h = 1; its blocks and laws are read once (:meth:`fits` first).
    A : list of ndarray (1, m_k, m_k)
        The blocks of A (:meth:`.MasslessContacts.split`), fixed for the march.
    cache : FactorCache
        Holds the kept factorizations across marches (one per fixed A).
    params : dict
        The numpy path's tolerances and limits, by their names in :mod:`.massless`
        (FD_REL, RESIDUAL_RTOL, ...; :meth:`.MasslessContacts.compile` passes them), so
        that both paths read one set and this module does not import that one.
    """

    def __init__(self, nodes, A, cache, params: dict):
        ms = SimpleNamespace(**params)
        n_c = len(nodes.kn)
        cs, qs = self._single(nodes.Qs)
        cp, qp = self._single(nodes.Qp)
        f_contact = np.concatenate([idx for _, idx, _ in nodes.groups]).astype(np.int32) \
            if nodes.groups else np.zeros(0, np.int32)
        f_law = np.concatenate([np.full(idx.size, g, np.int32) for g, (_, idx, _) in
                                enumerate(nodes.groups)]) if nodes.groups else np.zeros(0, np.int32)
        f_c = np.concatenate([c for _, _, c in nodes.groups]) if nodes.groups else np.zeros(0)
        r0 = np.array([r[0] for r in nodes._radius], float)
        r1 = np.array([r[1] for r in nodes._radius], float)
        ptr, cptr, dofs, cons, ls, lp = [0], [0], [], [], [], []
        for dofs_b, c_b, _, _ in nodes.blocks:
            where = {int(d): i for i, d in enumerate(dofs_b)}
            dofs.extend(dofs_b)
            cons.extend(c_b)
            ls.extend(where.get(int(cs[i]), -1) for i in c_b)
            lp.extend(where.get(int(cp[i]), -1) for i in c_b)
            ptr.append(len(dofs))
            cptr.append(len(cons))
        i32 = lambda v: np.ascontiguousarray(v, dtype=np.int32)  # noqa: E731 - the index arrays
        f64 = lambda v: np.ascontiguousarray(v, dtype=np.float64)  # noqa: E731
        self._keep = keep = {
            "kn": f64(nodes.kn), "p0": f64(nodes.p0), "s0": f64(nodes.s0), "kt_stuck": f64(nodes.kt_stuck),
            "cs": i32(cs), "cp": i32(cp), "qs": f64(qs), "qp": f64(qp), "f_contact": f_contact,
            "f_law": f_law, "f_c": f64(f_c), "law_r0": r0, "law_r1": r1, "blk_ptr": i32(ptr),
            "blk_dofs": i32(dofs), "blk_cptr": i32(cptr), "blk_c": i32(cons), "blk_ls": i32(ls),
            "blk_lp": i32(lp), "blk_A": np.concatenate([Ak[0].ravel() for Ak in A])}
        laws = [ref for ref, _, _ in nodes.groups]
        self._laws = (ct.POINTER(Model) * max(len(laws), 1))(*[ref._mp for ref in laws])
        m = MsurfModel(nodes.n_b, n_c, f_contact.size, len(nodes.blocks), len(laws))
        for name, a in keep.items():
            setattr(m, name, a.ctypes.data_as(_P32 if a.dtype == np.int32 else _PD))
        m.laws = self._laws
        m.fd_rel, m.rtol, m.section_rtol = ms.FD_REL, ms.RESIDUAL_RTOL, ms.SECTION_RTOL
        m.round_scale = 10.0 ** ms.SLOPE_DIGITS
        m.max_sides, m.max_bracket, m.max_section, m.n_slots = ms.MAX_SIDES, ms.MAX_BRACKET, ms.MAX_SECTION, SLOTS
        m.diag_min, m.n_refs, m.ref_share = ms.DIAGONAL_UPDATE_MIN, ms.MAX_REFERENCES, ms.REFERENCE_SHARE
        self.m = m
        self.work = np.zeros(lib.msurf_work_size(ct.byref(m)))
        self.swork = np.zeros(lib.msurf_state_work_size(ct.byref(m)), STATE_DTYPE)
        self.cache = self._cache(cache, "compiled")
        self.sizes = [0] + [idx.size for _, idx, _ in nodes.groups]
        self.groups = nodes.groups
        self.n_iter = ct.c_int32()

    @staticmethod
    def fits(nodes, A) -> bool:
        """Whether the C step takes these nodes: one history, rows of one entry (so that a
        block of DIAGONAL_UPDATE_MIN DOFs or more takes diagonal updates), every contact
        with a normal row."""
        return (lib is not None and nodes.n_h == 1 and bool(nodes.groups)
                and nodes.rows_s.gather and nodes.rows_p.gather
                and bool(np.all(np.count_nonzero(nodes.Qp, axis=1) == 1)))

    @staticmethod
    def _single(Q):
        """Each row's one column (-1 for an empty row) and its entry."""
        Q = np.asarray(Q, float)
        has = np.any(Q != 0, axis=1)
        col = np.where(has, np.argmax(Q != 0, axis=1), -1)
        return col, np.where(has, Q[np.arange(Q.shape[0]), np.maximum(col, 0)], 0.0)

    def _cache(self, owner, name: str):
        """The kept factorizations, stored on the owner (a FactorCache: one per fixed A) as
        attribute ``name`` (the node solve's and the sensitivities' apart, sharing the large
        blocks' reference inverses, attribute ``compiled_refs``)."""
        got = getattr(owner, name, None)
        # the layout of the arrays: the blocks, and which of them take diagonal updates
        key = (self._keep["blk_ptr"].tobytes() + self._keep["blk_cptr"].tobytes()
               + np.array([self.m.diag_min, self.m.n_refs, self.m.n_slots, self.m.ref_share]).tobytes())
        if got is None or got[0] != key:
            p64 = ct.POINTER(ct.c_int64)
            refs = getattr(owner, "compiled_refs", None)
            if refs is None or refs[0] != key:
                ni, nd = ct.c_size_t(), ct.c_size_t()
                lib.msurf_refs_sizes(ct.byref(self.m), ct.byref(ni), ct.byref(nd))
                ra = (np.zeros(ni.value), np.zeros(nd.value), np.zeros(self.m.n_blocks * self.m.n_refs, np.int64),
                      np.zeros(self.m.n_blocks * self.m.n_refs, np.int64))
                refs = (key, MsurfRefs(ra[0].ctypes.data_as(_PD), ra[1].ctypes.data_as(_PD),
                                       ra[2].ctypes.data_as(p64), ra[3].ctypes.data_as(p64), 0, 0), ra)
                if owner is not None:
                    owner.compiled_refs = refs
                    if ra[0].size:   # the large blocks' reference inverses, beside the numpy path's
                        owner._inv["compiled"] = refs
            nk, nl, npv = ct.c_size_t(), ct.c_size_t(), ct.c_size_t()
            lib.msurf_cache_sizes(ct.byref(self.m), ct.byref(nk), ct.byref(nl), ct.byref(npv))
            arrays = (np.zeros(nk.value), np.zeros(nl.value), np.zeros(npv.value, np.int32),
                      np.zeros(self.m.n_blocks * SLOTS, np.int64))
            c = MsurfCache(arrays[0].ctypes.data_as(_PD), arrays[1].ctypes.data_as(_PD),
                           arrays[2].ctypes.data_as(_P32), arrays[3].ctypes.data_as(p64), 0,
                           ct.pointer(refs[1]))
            got = (key, c, arrays, refs)
            if owner is not None:
                setattr(owner, name, got)
        return got[1]

    def solve(self, states: list, rhs: np.ndarray, guess: np.ndarray, max_iter: int):
        """(w (1, n_b), the committed states per group) of one step (MasslessContacts.solve)."""
        buf = np.concatenate(states) if states else np.zeros(0, STATE_DTYPE)
        w = np.array(guess[0], dtype=np.float64)
        b = np.ascontiguousarray(rhs[0], dtype=np.float64)
        st = lib.msurf_solve(ct.byref(self.m), ct.byref(self.cache), arr(buf, StateArray), arr(b), arr(w),
                             int(max_iter), arr(self.work), arr(self.swork, StateArray),
                             ct.byref(self.n_iter))
        if st == 1:
            raise RuntimeError("the contact surface nodes found no equilibrium in a time step: "
                               "raise the steps per period, or check that the surface stays in contact")
        if st == 3:
            raise RuntimeError("the contact surface nodes' Newton matrix is singular: check that the "
                               "surface is held (every block in contact or tied to its bodies)")
        if st != 0:
            raise IwanInputError(f"the massless node step: {_MESSAGES.get(st, st)}")
        off = np.cumsum(self.sizes)
        return w[None], [buf[a:e] for a, e in zip(off[:-1], off[1:])]


class CompiledSensitivity:
    """The forward sensitivities' advance (:meth:`.surface_sensitivity.MarchSensitivity.advance`
    for one history, block-triangular, rows of one entry) in one C call per step, on the
    blocks and laws of a :class:`CompiledStep`.

    Parameters
    ----------
    step : CompiledStep
    AR : ndarray (n_b, r)
    n_d : int
        Directions carried.
    order : sequence of int
        The blocks in the order they are solved (normal blocks first).
    cache : FactorCache
        Holds the kept factorizations across marches.

    Attributes
    ----------
    dw : ndarray (1, n_b, n_d)
        Sensitivity of the last committed displacements (updated in place).
    """

    def __init__(self, step: CompiledStep, AR, n_d: int, order, cache):
        self.step = step
        ns = max(int(ref.n_sliders) for ref in (g[0] for g in step_groups(step)))
        n_f, n_b = step.m.n_f, step.m.n_b
        self.dw = np.zeros((1, n_b, n_d))
        self._dz, self._duc = np.zeros((n_f, ns, n_d)), np.zeros((n_f, n_d))
        self._AR = np.ascontiguousarray(AR, dtype=np.float64)
        self._order = np.ascontiguousarray(order, dtype=np.int32)
        self.s = MsurfSens(int(n_d), ns, self._AR.shape[1], self.dw.ctypes.data_as(_PD),
                           self._dz.ctypes.data_as(_PD), self._duc.ctypes.data_as(_PD),
                           self._AR.ctypes.data_as(_PD), self._order.ctypes.data_as(_P32))
        self.work = np.zeros(lib.msurf_sens_work_size(ct.byref(step.m), ct.byref(self.s)))
        self.cache = step._cache(cache, "compiled_sensitivity")

    def advance(self, before: list, after: list, w1: np.ndarray, dq1: np.ndarray) -> None:
        """Carry the sensitivities over the step just committed (states per group before and
        after it, w1 (1, n_b), dq1 (r, n_d))."""
        b0 = np.concatenate(before)
        b1 = np.concatenate(after)
        w = np.ascontiguousarray(w1[0], dtype=np.float64)
        dq = np.ascontiguousarray(dq1, dtype=np.float64)
        st = lib.msurf_advance(ct.byref(self.step.m), ct.byref(self.cache), ct.byref(self.s),
                               arr(b0, StateArray), arr(b1, StateArray), arr(w), arr(dq), arr(self.work))
        if st == 3:
            raise RuntimeError("the contact surface's sensitivity matrix is singular at a step")
        if st != 0:
            raise IwanInputError(f"the massless node sensitivities: {_MESSAGES.get(st, st)}")


def step_groups(step: CompiledStep) -> list:
    """The law groups of the nodes a :class:`CompiledStep` was made for."""
    return step.groups
