"""A 3D contact point from Python: ctypes over ``fmu_src/core/contact_point.h``.

The 2D friction element (:mod:`fmu_src.element2d`) with a normal law N(p) of the
penetration: a table (the approach curve of ``damper normal``) or a penalty spring.
The law lives in C; this module builds the model, converts arrays and statuses.

Symbols (SI units)
------------------
q = (u_x, u_y, p) : slip in the contact plane [m] and penetration [m] (positive pressed)
f = (F_x, F_y, N) : friction force and normal load [N] (conjugate to q)
K = df/dq (3, 3) [N/m];  C = df/dv diagonal (3,) [N s/m] (dashpots, in contact)
W : friction work [J];  E : stored energy (sliders, residual and normal springs) [J]
state : 0 open, 1 stick, 2 slip
"""
from __future__ import annotations

import ctypes as ct
from dataclasses import dataclass

import numpy as np

from . import _clib
from ._clib import CPointModel, CPointOutput, CPointState, IwanInputError, arr
from ._clib import check as _check
from .element import IwanElement

__all__ = ["ContactPoint", "ContactPointState", "PointOutput", "STATE_NAMES"]

_lib = _clib.lib
#: Names of the contact states (``cpoint_output.state``).
STATE_NAMES = ("open", "stick", "slip")


class ContactPointState:
    """A copy of the contact point's flat C state.

    Attributes: q (3,) last committed (u_x, u_y, p) [m]; N [N]; W [J]; in_contact.
    """

    def __init__(self, raw: CPointState):
        self._raw = raw

    def copy(self) -> ContactPointState:
        raw = CPointState()
        ct.pointer(raw)[0] = self._raw
        return ContactPointState(raw)

    q = property(lambda self: np.array([*self._raw.s.u[:], self._raw.p]))
    N = property(lambda self: self._raw.s.N)
    W = property(lambda self: self._raw.s.w_diss)
    in_contact = property(lambda self: bool(self._raw.s.in_contact))


@dataclass(frozen=True)
class PointOutput:
    """Outputs: f (3,) [N], K (3, 3) [N/m], C (3,) [N s/m], W, E [J], slip [-], state (0/1/2)."""
    f: np.ndarray
    K: np.ndarray
    C: np.ndarray
    W: float
    E: float
    slip: float
    state: int


def _output(o: CPointOutput) -> PointOutput:
    return PointOutput(np.array(o.f[:]), np.array(o.K[:]).reshape(3, 3), np.array(o.C[:]),
                       o.W, o.E, o.slip, int(o.state))


class ContactPoint:
    """Contact point: 2D friction element + normal law N(p) (+ optional dashpots).

    Parameters
    ----------
    tangential : IwanElement
        The friction element (virgin curve at its ``N_ref``); its slip strengths scale
        with N(p) / N_ref.
    p, N : array_like, shape (m,)
        Normal law table [m], [N]: p[0] = N[0] = 0, both strictly increasing; the last
        slope continues beyond; N = 0 for p <= 0.
    c_t, c_n : float
        Tangential and normal dashpots [N s/m] (in contact; used when velocities are given).
    """

    def __init__(self, tangential: IwanElement, p, N, c_t: float = 0.0, c_n: float = 0.0):
        p = np.ascontiguousarray(p, dtype=float).ravel()
        N = np.ascontiguousarray(N, dtype=float).ravel()
        if p.shape != N.shape:
            raise IwanInputError(f"normal law: p and N must have the same length, got {p.size}, {N.size}")
        self.tangential = tangential
        self._model = CPointModel()
        status = _lib.cpoint_model_init(ct.byref(self._model), tangential._mp, arr(p), arr(N),
                                        p.size, float(c_t), float(c_n))
        if status == 2:
            raise IwanInputError("normal law: needs 2 to 256 points starting at (0, 0) with p and N "
                                 "strictly increasing (a normal curve that is not monotone, or a "
                                 "negative penetration, is refused)")
        _check(status, "ContactPoint")
        self._mp = ct.pointer(self._model)

    @classmethod
    def penalty(cls, tangential: IwanElement, k_n: float, **kw) -> ContactPoint:
        """Penalty normal law N = k_n max(p, 0): the table (0, 0), (1 m, k_n)."""
        return cls(tangential, [0.0, 1.0], [0.0, float(k_n)], **kw)

    n_normal = property(lambda self: int(self._model.n_normal))
    table = property(lambda self: (np.array(self._model.p[: self.n_normal]),
                                   np.array(self._model.N[: self.n_normal])))

    def normal(self, p: float) -> tuple[float, float]:
        """(N(p) [N], dN/dp [N/m]) of the law (the slope of the segment below p)."""
        slope = ct.c_double()
        return float(_lib.cpoint_normal(self._mp, float(p), ct.byref(slope))), slope.value

    def penetration(self, N: float) -> float:
        """p with N(p) = N (> 0): the inverse of the law (start values, preload)."""
        if not (np.isfinite(N) and N > 0):
            raise IwanInputError(f"normal load must be finite and > 0, got {N!r}")
        p, Nt = self.table
        i = min(int(np.searchsorted(Nt, N)), p.size - 1)
        i = max(i, 1)
        with np.errstate(over="ignore"):
            pen = float(p[i - 1] + (N - Nt[i - 1]) * (p[i] - p[i - 1]) / (Nt[i] - Nt[i - 1]))
        if not np.isfinite(pen):
            raise IwanInputError(f"the penetration at N = {N:g} N overflows: the normal law is too "
                                 "soft for this load")
        return pen

    def initial_state(self, p: float = 0.0) -> ContactPointState:
        """Virgin state at u = (0, 0) and penetration p [m]."""
        raw = CPointState()
        _check(_lib.cpoint_state_init(self._mp, ct.byref(raw), float(p)), "ContactPoint.initial_state")
        return ContactPointState(raw)

    @staticmethod
    def _q(q, v):
        qa = np.ascontiguousarray(q, dtype=float).reshape(3)
        va = None if v is None else np.ascontiguousarray(v, dtype=float).reshape(3)
        return qa, va

    def step(self, state: ContactPointState, q, v=None) -> PointOutput:
        """Advance ``state`` in place along the straight path to q = (u_x, u_y, p)."""
        qa, va = self._q(q, v)
        out = CPointOutput()
        _check(_lib.cpoint_step(self._mp, ct.byref(state._raw), arr(qa), arr(va), ct.byref(out)),
               "ContactPoint.step")
        return _output(out)

    def eval(self, state: ContactPointState, q, v=None) -> PointOutput:
        """Outputs at q reached by the straight path from ``state`` (unchanged)."""
        qa, va = self._q(q, v)
        out = CPointOutput()
        _check(_lib.cpoint_eval(self._mp, ct.byref(state._raw), arr(qa), arr(va), None,
                                ct.byref(out)), "ContactPoint.eval")
        return _output(out)
