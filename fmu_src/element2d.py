"""The two-dimensional Masing/Iwan element from Python: ctypes over ``fmu_src/core/iwan2d.h``.

The law lives once, in ``fmu_src/core/iwan2d.c``: each Jenkins slider of the 1D
element (:class:`fmu_src.element.IwanElement`, the same model built from the same
isotropic virgin curve) becomes a 2D slider with a circular slip limit; along a
straight line the element is the 1D one. This module converts arrays and statuses.

Symbols (SI units)
------------------
u = (u_x, u_y) : slip in the contact plane [m];  N : normal load [N]
F = (F_x, F_y) : friction force [N];  K = dF/du (2, 2) [N/m];  dFdN = dF/dN (2,) [-]
W : dissipated energy [J];  E : stored elastic energy [J];  slip : slipping strength fraction [-]
k_j, fs_j, r_j = fs_j scale N / (N_ref k_j) : slider stiffness, strength, slip radius

K and dFdN are the exact derivatives of the outputs at the end of a step with respect
to its end point (the committed state fixed); for a zero step, the tangent for
continued motion in the direction of the last motion (``iwan2d.h``).
"""
from __future__ import annotations

import ctypes as ct
from dataclasses import dataclass

import numpy as np

from . import _clib
from ._clib import Output2, State2, arr
from ._clib import check as _check
from ._clib import vec as _vec
from .element import IwanElement

__all__ = ["IwanElement2D", "IwanState2D", "StepOutput2D", "SeriesResult2D", "PeriodicResult2D"]

_lib = _clib.lib


class IwanState2D:
    """A copy of the 2D element's flat C state (save/restore by copying).

    Attributes
    ----------
    u : ndarray, shape (2,)     last committed slip [m]
    N : float                   last committed normal load [N]
    W : float                   cumulative dissipated energy [J]
    in_contact : bool
    z : ndarray, shape (n_sliders, 2)   slider positions [m]; slider force k_j (u - z_j)
    """

    def __init__(self, raw: State2, n_sliders: int):
        self._raw = raw
        self._n = n_sliders

    def copy(self) -> IwanState2D:
        raw = State2()
        ct.pointer(raw)[0] = self._raw
        return IwanState2D(raw, self._n)

    u = property(lambda self: np.array(self._raw.u[:]))
    N = property(lambda self: self._raw.N)
    W = property(lambda self: self._raw.w_diss)
    in_contact = property(lambda self: bool(self._raw.in_contact))
    z = property(lambda self: np.array(self._raw.z[: 2 * self._n]).reshape(self._n, 2))

    def __repr__(self):
        return (f"IwanState2D(u={self.u.tolist()!r}, N={self.N!r}, W={self.W!r}, "
                f"in_contact={self.in_contact})")


@dataclass(frozen=True)
class StepOutput2D:
    """Outputs at one point: F (2,) [N], K (2, 2) [N/m], dFdN (2,) [-], W, E [J], slip [-]."""
    F: np.ndarray
    K: np.ndarray
    dFdN: np.ndarray
    W: float
    E: float
    slip: float


@dataclass(frozen=True)
class SeriesResult2D:
    """Per-sample outputs: F (n, 2) [N], W (n,) [J], and the advanced state."""
    F: np.ndarray
    W: np.ndarray
    state: IwanState2D


@dataclass(frozen=True)
class PeriodicResult2D:
    """Periodic loop: F (n, 2) [N], dF (n, 2, 3, n_b) or None, W_cycle [J], periods."""
    F: np.ndarray
    dF: np.ndarray | None
    W_cycle: float
    periods: int


def _output(out: Output2) -> StepOutput2D:
    return StepOutput2D(np.array(out.F[:]), np.array(out.K[:]).reshape(2, 2),
                        np.array(out.dFdN[:]), out.W, out.E, out.slip)


class IwanElement2D:
    """2D Masing/Iwan element: the sliders of a 1D :class:`IwanElement` in the plane.

    Parameters
    ----------
    element : IwanElement
        The 1D element whose model (sliders, residual spring, N_ref, scale) is used.
    """

    def __init__(self, element: IwanElement):
        self.element = element
        self._mp = element._mp

    @classmethod
    def from_curve(cls, u, T, N_ref, **kw) -> IwanElement2D:
        """From a virgin curve, as :meth:`IwanElement.from_curve` (same keywords)."""
        return cls(IwanElement.from_curve(u, T, N_ref, **kw))

    @classmethod
    def jenkins(cls, k: float, fs: float) -> IwanElement2D:
        """One 2D Jenkins slider: spring k [N/m], slip force fs [N] at N_ref = 1."""
        return cls(IwanElement.jenkins(k, fs))

    @classmethod
    def from_sliders(cls, k, fs, k_res: float = 0.0, N_ref: float = 1.0) -> IwanElement2D:
        return cls(IwanElement.from_sliders(k, fs, k_res, N_ref))

    n_sliders = property(lambda self: self.element.n_sliders)
    N_ref = property(lambda self: self.element.N_ref)

    def __repr__(self):
        return f"IwanElement2D({self.element!r})"

    def _N(self, N) -> float:
        return self.N_ref if N is None else float(N)

    def initial_state(self, N: float | None = None) -> IwanState2D:
        """Virgin state at u = (0, 0) under normal load N [N] (default N_ref)."""
        raw = State2()
        _check(_lib.iwan2_state_init(self._mp, ct.byref(raw), self._N(N)),
               "IwanElement2D.initial_state")
        return IwanState2D(raw, self.n_sliders)

    def step(self, state: IwanState2D, u, N: float | None = None) -> StepOutput2D:
        """Advance ``state`` in place along the straight path to (u, N); u of shape (2,)."""
        ux, uy = (float(v) for v in np.asarray(u, dtype=float).reshape(2))
        out = Output2()
        _check(_lib.iwan2_step(self._mp, ct.byref(state._raw), ux, uy, self._N(N),
                               ct.byref(out)), "IwanElement2D.step")
        return _output(out)

    def eval(self, state: IwanState2D, u, N: float | None = None) -> StepOutput2D:
        """Outputs at (u, N) reached by the straight path from ``state`` (unchanged)."""
        ux, uy = (float(v) for v in np.asarray(u, dtype=float).reshape(2))
        out = Output2()
        _check(_lib.iwan2_eval(self._mp, ct.byref(state._raw), ux, uy, self._N(N), None,
                               ct.byref(out)), "IwanElement2D.eval")
        return _output(out)

    def series(self, u, N=None, state: IwanState2D | None = None) -> SeriesResult2D:
        """Whole history in one C call.

        Parameters
        ----------
        u : array_like, shape (n, 2)
            Slip samples [m], joined by straight lines (from the state's u).
        N : None, float or array_like, shape (n,)
            Normal load [N] (default N_ref).
        state : IwanState2D, optional
            Start state (advanced in place); default a virgin state at N_ref.
        """
        u = np.ascontiguousarray(u, dtype=float)
        if u.ndim != 2 or u.shape[1] != 2 or u.shape[0] == 0:
            raise _clib.IwanInputError(f"u must have shape (n, 2), got {u.shape}")
        n = u.shape[0]
        ux, uy = _vec(u[:, 0], "u_x"), _vec(u[:, 1], "u_y")
        Nv = None if N is None else _clib.normal(N, n, self.N_ref)
        if state is None:
            state = self.initial_state()
        F, W = np.empty(2 * n), np.empty(n)
        _check(_lib.iwan2_series(self._mp, ct.byref(state._raw), n, arr(ux), arr(uy), arr(Nv),
                                 arr(F), arr(W)), "IwanElement2D.series")
        return SeriesResult2D(F.reshape(n, 2), W, state)

    def periodic_jac(self, ux, uy, E=None, N=None, EN=None, max_periods: int = 100,
                     tol: float = 1e-12) -> PeriodicResult2D:
        """Periodic loop of a sampled path and its exact Jacobian (``iwan2_periodic_jac``).

        Parameters
        ----------
        ux, uy : array_like, shape (n,)
            Slip samples over one period [m] (straight lines between them, sample n = 0).
        E : array_like, shape (n, n_b), optional
            Basis of u_x and u_y: u_x = E X_x, u_y = E X_y. None: no Jacobian.
        N : None, float or array_like, shape (n,)
            Normal load [N] (default N_ref).
        EN : array_like, shape (n, n_b), optional
            Basis of N = EN X_N (None: N does not depend on the coefficients).
        max_periods, tol : int, float
            Each slider is marched until its position at the sweep start recurs to
            ``tol`` times its largest slip radius (iwan2d.h).

        Returns
        -------
        PeriodicResult2D
            F (n, 2) [N]; dF (n, 2, 3, n_b): dF_i(t) / d(X_x, X_y, X_N) (None without E);
            W_cycle [J]; periods.
        """
        ux, uy = _vec(ux, "u_x"), _vec(uy, "u_y", ux.size)
        n = ux.size
        Nv = None if N is None else _clib.normal(N, n, self.N_ref)
        Ea = ENa = work = dF = None
        nb = 0
        if E is not None:
            Ea = np.ascontiguousarray(E, dtype=float)
            if Ea.ndim != 2 or Ea.shape[0] != n:
                raise _clib.IwanInputError(f"E must have shape ({n}, n_b), got {Ea.shape}")
            nb = Ea.shape[1]
            if EN is not None:
                ENa = np.ascontiguousarray(EN, dtype=float)
                if ENa.shape != Ea.shape:
                    raise _clib.IwanInputError(f"EN must have the shape of E {Ea.shape}, got {ENa.shape}")
            work = np.empty(_lib.iwan2_periodic_work_size(nb))
            dF = np.empty((n, 2, 3, nb))
        F, W, periods = np.empty((n, 2)), ct.c_double(), ct.c_int()
        _check(_lib.iwan2_periodic_jac(self._mp, n, arr(ux), arr(uy), arr(Nv), arr(Ea), arr(ENa), nb,
                                       arr(F), arr(dF), ct.byref(W), int(max_periods), float(tol),
                                       ct.byref(periods), arr(work)), "IwanElement2D.periodic_jac")
        return PeriodicResult2D(F, dF, W.value, periods.value)
