"""Batches of independent element states: one C call advances every state one sample.

For vectorised time integration (every frequency of a curve, or every variant of a
parameter study, marched together): the states of one element live side by side in
one numpy buffer of :data:`STATE_DTYPE` (the C ``iwan_state``), and
``iwan_step_batch`` advances state i to (u[i], N[i]) through the time series' own
code, so each state gets the bits ``IwanElement.step`` would give it alone. Reached
through :meth:`IwanElement.initial_states`, :meth:`IwanElement.step_batch` and
:meth:`IwanElement.batch_stepper`. Likewise :func:`periodic_jac_many` runs the
periodic loops of many elements (e.g. a ring's contacts) with their Jacobians in one C
call, :func:`periodic_many` without them, and :class:`PeriodicBatch` both on elements
whose C pointers it resolves once. Symbols as
in :mod:`fmu_src.element`. Only the ctypes layer (:mod:`fmu_src._clib`) is imported
here: ``element`` imports this module, never the other way round; ``element``
arguments are duck-typed (``._mp``, ``.N_ref``).
"""
from __future__ import annotations

import ctypes as ct

import numpy as np

from ._clib import STATE_DTYPE, IwanInputError, State, StateArray, arr, check, lib, normal, vec

__all__ = ["STATE_DTYPE", "BatchStepper", "PeriodicBatch", "initial_states", "periodic_jac_many",
           "periodic_many", "step_batch"]


def _check_states(states) -> int:
    """Number of states in a batch buffer; IwanInputError unless usable in place."""
    if (not isinstance(states, np.ndarray) or states.dtype != STATE_DTYPE
            or states.ndim != 1 or not states.flags.c_contiguous
            or not states.flags.writeable or states.size == 0):
        raise IwanInputError("states must be a writeable C-contiguous 1-D array of "
                             "STATE_DTYPE (from IwanElement.initial_states)")
    return states.size


class BatchStepper:
    """Repeated :meth:`IwanElement.step_batch` on one states buffer, with fixed buffers.

    Fill :attr:`u` (and :attr:`N` when made with a normal load), call :meth:`step`;
    the pointers are resolved once, so a call costs a few us plus ~25 ns per state
    instead of ~9 us (time integration calls it once per element per time step).

    Attributes
    ----------
    states : ndarray, shape (n,), dtype STATE_DTYPE (advanced in place)
    u : ndarray, shape (n,)  displacement input [m]
    N : ndarray, shape (n,) or None  normal load input [N] (None: N_ref)
    F, kt : ndarray, shape (n,)  outputs of the last step [N], [N/m] (overwritten)
    """

    def __init__(self, element, states: np.ndarray, N=None):
        n = _check_states(states)
        self.element, self.states = element, states
        self.u = np.zeros(n)
        self.N = None if N is None else normal(N, n, element.N_ref).copy()
        self.F, self.kt = np.zeros(n), np.zeros(n)
        # typed pointers resolved once (the buffers never move): no Python per call
        self._args = (element._mp, arr(states, StateArray), n, arr(self.u), arr(self.N),
                      arr(self.F), arr(self.kt))

    def step(self, u=None) -> np.ndarray:
        """Advance every state to (u, N); returns :attr:`F` (shape (n,), overwritten next call).

        u : array_like shape (n,), optional -- copied into :attr:`u` first.
        """
        if u is not None:
            np.copyto(self.u, u)
        check(lib.iwan_step_batch(*self._args), "BatchStepper.step")
        return self.F


def initial_states(element, n: int, N=None) -> np.ndarray:
    """``n`` virgin states at u = 0 in one buffer, for :func:`step_batch`.

    Parameters
    ----------
    n : int
        Number of independent states (>= 1).
    N : None, float or array_like shape (n,)
        Normal load [N] of each state (default ``N_ref``).

    Returns
    -------
    ndarray, shape (n,), dtype :data:`STATE_DTYPE`
        The flat C states (``iwan_state``) side by side; fields ``u``, ``N``,
        ``w_diss`` (dissipated energy), ``z`` ... readable as numpy columns.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise IwanInputError(f"n must be an integer >= 1, got {n!r}")
    Nv = normal(N, int(n), element.N_ref)
    states = np.zeros(int(n), dtype=STATE_DTYPE)
    first = {}
    for i, Ni in enumerate(Nv):
        key = float(Ni)
        if key not in first:  # one C init per distinct load, copied to the others
            raw = State()
            check(lib.iwan_state_init(element._mp, ct.byref(raw), key),
                  "IwanElement.initial_states")
            states[i] = np.frombuffer(raw, dtype=STATE_DTYPE)[0]
            first[key] = i
        else:
            states[i] = states[first[key]]
    return states


def step_batch(element, states: np.ndarray, u, N=None, out=None):
    """Advance many independent states by one sample each, in one C call.

    State i moves along the straight path to (u[i], N[i]), exactly as
    :meth:`step` would move it (the same C code: the same bits). Every input
    and state is checked before any state moves: on error nothing changes.

    Parameters
    ----------
    states : ndarray, shape (n,), dtype :data:`STATE_DTYPE`
        Buffer from :func:`initial_states` (C-contiguous, writeable), updated in place.
    u : array_like, shape (n,)
        Displacement of each state [m].
    N : None, float or array_like shape (n,)
        Normal load [N]; None means ``N_ref`` for every state.
    out : tuple (F, kt) of float64 arrays shape (n,), optional
        Where to write the outputs (avoids allocating per call).

    Returns
    -------
    F : ndarray, shape (n,)
        Friction force [N].
    kt : ndarray, shape (n,)
        Tangent stiffness dF/du for continued motion [N/m].
    """
    n = _check_states(states)
    u = vec(u, "u", n)
    Nv = None if N is None else normal(N, n, element.N_ref)
    if out is None:
        F, kt = np.empty(n), np.empty(n)
    else:
        F, kt = out
        for a in (F, kt):
            if (not isinstance(a, np.ndarray) or a.dtype != np.float64 or a.shape != (n,)
                    or not a.flags.c_contiguous or not a.flags.writeable):
                raise IwanInputError(f"out must be two writeable float64 arrays of shape ({n},)")
    check(lib.iwan_step_batch(element._mp, arr(states, StateArray), n, arr(u), arr(Nv), arr(F),
                              arr(kt)), "IwanElement.step_batch")
    return F, kt


class PeriodicBatch:
    """The periodic loops of many elements (e.g. a ring's contacts), one C call each
    evaluation, with the elements' pointers resolved once.

    Parameters
    ----------
    elements : sequence of n_e IwanElement (each its own law)
    EN : sequence of n_e arrays, shape (n, nb), optional
        Each element's normal-load basis (for :meth:`jac`); kept, not copied per call.
    """

    def __init__(self, elements, EN=None):
        self.n_e = len(elements)
        if self.n_e == 0:
            raise IwanInputError("a batch needs at least one element")
        self._models = (ct.POINTER(type(elements[0]._mp.contents)) * self.n_e)(
            *[el._mp for el in elements])
        self._EN = self._ens = None
        if EN is not None:
            self._EN = [np.ascontiguousarray(a, dtype=np.float64) for a in EN]
            if len(self._EN) != self.n_e or any(a.shape != self._EN[0].shape for a in self._EN):
                raise IwanInputError(f"EN must be {self.n_e} arrays of one shape (n, nb)")
            self._ens = (ct.POINTER(ct.c_double) * self.n_e)(
                *[a.ctypes.data_as(ct.POINTER(ct.c_double)) for a in self._EN])

    def _samples(self, u, N):
        u = np.ascontiguousarray(u, dtype=np.float64)
        Nv = np.ascontiguousarray(N, dtype=np.float64)
        if u.ndim != 2 or u.shape[0] != self.n_e or Nv.shape != u.shape:
            raise IwanInputError(f"u and N must have shape ({self.n_e}, n), got {u.shape} "
                                 f"and {Nv.shape}")
        return u, Nv

    def jac(self, u, Eu, N, max_periods: int = 100, tol: float = 1e-12):
        """:func:`periodic_jac_many` of the batch (EN given at construction)."""
        if self._ens is None:
            raise IwanInputError("the batch was made without EN: no Jacobian")
        u, Nv = self._samples(u, N)
        n = u.shape[1]
        Eu = np.ascontiguousarray(Eu, dtype=np.float64)
        if Eu.ndim != 2 or Eu.shape[0] != n or Eu.shape[1] == 0:
            raise IwanInputError(f"Eu must have shape ({n}, nb), got {Eu.shape}")
        if self._EN[0].shape != Eu.shape:
            raise IwanInputError(f"EN must be {self.n_e} arrays of shape {Eu.shape}")
        n_e, nb = self.n_e, Eu.shape[1]
        F, W = np.empty((n_e, n)), np.empty(n_e)
        dFdX, dFdXN = np.empty((n_e, n, nb)), np.empty((n_e, n, nb))
        failed = ct.c_size_t()
        status = lib.iwan_periodic_jac_many(self._models, n_e, n, arr(u), arr(Nv), arr(Eu),
                                            self._ens, nb, arr(F), arr(dFdX), arr(dFdXN), arr(W),
                                            int(max_periods), float(tol), ct.byref(failed))
        check(status, f"periodic_jac_many (element {failed.value})")
        return F, dFdX, dFdXN, W

    def loops(self, u, N, max_periods: int = 100, tol: float = 1e-12):
        """:func:`periodic_many` of the batch: F (n_e, n) [N] and W_cycle (n_e,) [J]."""
        u, Nv = self._samples(u, N)
        n = u.shape[1]
        F, W = np.empty((self.n_e, n)), np.empty(self.n_e)
        failed = ct.c_size_t()
        status = lib.iwan_periodic_many(self._models, self.n_e, n, arr(u), arr(Nv), arr(F),
                                        arr(W), int(max_periods), float(tol), ct.byref(failed))
        check(status, f"periodic_many (element {failed.value})")
        return F, W


def periodic_jac_many(elements, u, Eu, N, EN, max_periods: int = 100, tol: float = 1e-12):
    """:meth:`IwanElement.periodic_jac` of many elements in one C call (same numbers).

    Parameters
    ----------
    elements : sequence of n_e IwanElement (each its own law)
    u : array_like, shape (n_e, n)   displacement samples of each element [m]
    Eu : array_like, shape (n, nb)   the shared basis (u = Eu X per element)
    N : array_like, shape (n_e, n)   normal load samples [N]
    EN : sequence of n_e arrays, shape (n, nb)   each element's normal-load basis
    max_periods, tol : as :meth:`IwanElement.periodic_jac`

    Returns
    -------
    F : (n_e, n) [N];  dFdX, dFdXN : (n_e, n, nb);  W_cycle : (n_e,) [J].

    Raises the first failing element's error (IwanInputError, IwanNotConvergedError)
    with its index. Repeated calls on the same elements: :class:`PeriodicBatch`.
    """
    if len(elements) == 0:
        raise IwanInputError("u and N must have shape (n_e, n) with n_e >= 1")
    return PeriodicBatch(elements, EN).jac(u, Eu, N, max_periods, tol)


def periodic_many(elements, u, N, max_periods: int = 100, tol: float = 1e-12):
    """The periodic loops of many elements without their Jacobians, in one C call: the F
    and W_cycle of each element's own :meth:`IwanElement.periodic_jac_terms` (the same
    bits: the same march).

    Parameters
    ----------
    elements : sequence of n_e IwanElement
    u, N : array_like, shape (n_e, n)   displacement [m] and normal load [N] samples
    max_periods, tol : as :meth:`IwanElement.periodic_jac`

    Returns
    -------
    F : (n_e, n) [N];  W_cycle : (n_e,) [J].
    """
    if len(elements) == 0:
        raise IwanInputError("u and N must have shape (n_e, n) with n_e >= 1")
    return PeriodicBatch(elements).loops(u, N, max_periods, tol)
