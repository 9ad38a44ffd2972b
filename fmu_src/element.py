"""The Masing/Iwan friction element from Python: a thin ctypes layer over the C core.

The law itself lives once, in ``fmu_src/core/iwan.c`` (see ``iwan.h``); this
module only validates and converts numpy arrays, calls one C function per time
series, and turns a bad status into an exception.

Symbols (SI units)
------------------
u : tangential displacement [m];  N : normal load [N];  F : friction force [N]
k_j, fs_j : stiffness [N/m] and slip strength at ``N_ref`` [N] of Jenkins slider j
k_res : residual spring [N/m];  N_ref : normal load of the virgin curve [N]
scale : friction scale multiplying every fs_j;  W : dissipated energy [J]
kt = dF/du [N/m] (for continued motion in the direction of the last increment);
dFdN = dF/dN at fixed u [-];  E : stored elastic energy [J]

Slip strengths are ``fs_j * scale * N / N_ref`` (same curve shape at every N);
``N <= 0`` is lift-off (F = 0, memory released, virgin again at re-contact).
"""
from __future__ import annotations

import ctypes as ct
from dataclasses import dataclass

import numpy as np

from . import _clib
from ._clib import MAX_SLIDERS, IwanInputError, IwanNotConvergedError, Model, Output, State, arr
from ._clib import check as _check
from ._clib import normal as _normal
from ._clib import vec as _vec
from .curve_fit import FITS, TAILS, check_table, prepare_table

__all__ = ["IwanElement", "IwanState", "IwanInputError", "IwanNotConvergedError",
           "MAX_SLIDERS", "flat_tail"]

_FIT_CODE = {"reject": 0, "concave": 1}   # iwan_fit
_lib = _clib.lib


def flat_tail(u, T) -> tuple[np.ndarray, np.ndarray]:
    """The table (u, T), shape (m,), with a point (2 u[-1], T[-1]) appended, shape (m + 1,).

    Its last segment is flat, so the element built from it has no residual spring
    (k_res = 0): the force stays at T[-1] past the end of the curve (``tail="flat"``,
    gross slip). The FMU packager writes the same table into the FMU.
    """
    u = _vec(u, "u")
    T = _vec(T, "T", u.size)
    return np.append(u, 2.0 * u[-1]), np.append(T, T[-1])


def _from_model_bytes(data: bytes, fit_error: float) -> IwanElement:
    """The element of a pickled C model (:meth:`IwanElement.__reduce__`)."""
    el = IwanElement(Model.from_buffer_copy(data))
    el.fit_error = fit_error
    return el


class IwanState:
    """A copy of the element's flat C state (save/restore by copying).

    Attributes
    ----------
    u, N : float
        Last committed displacement [m] and normal load [N].
    W : float
        Cumulative dissipated energy [J].
    in_contact : bool
    z : ndarray, shape (n_sliders,)
        Slider positions [m]; slider force k_j (u - z_j).
    """

    def __init__(self, raw: State, n_sliders: int):
        self._raw = raw
        self._n = n_sliders

    def copy(self) -> IwanState:
        raw = State()
        ct.pointer(raw)[0] = self._raw
        return IwanState(raw, self._n)

    u = property(lambda self: self._raw.u)
    N = property(lambda self: self._raw.N)
    W = property(lambda self: self._raw.w_diss)
    in_contact = property(lambda self: bool(self._raw.in_contact))
    z = property(lambda self: np.array(self._raw.z[: self._n]))

    def __repr__(self):
        return f"IwanState(u={self.u!r}, N={self.N!r}, W={self.W!r}, in_contact={self.in_contact})"


@dataclass(frozen=True)
class StepOutput:
    """Outputs at one point: F [N], kt [N/m], dFdN [-], W [J], E [J], slip [-]."""
    F: float
    kt: float
    dFdN: float
    W: float
    E: float
    slip: float


@dataclass(frozen=True)
class SeriesResult:
    """Per-sample outputs, arrays of shape (n,), and the advanced state."""
    F: np.ndarray
    kt: np.ndarray
    dFdN: np.ndarray
    W: np.ndarray
    state: IwanState


@dataclass(frozen=True)
class PeriodicResult:
    """The converged loop: F, kt, dFdN of shape (n,); energy per period [J]; periods used."""
    F: np.ndarray
    kt: np.ndarray
    dFdN: np.ndarray
    W_cycle: float
    periods: int


class IwanElement:
    """Masing/Iwan element: parallel Jenkins sliders plus a residual spring.

    Build it with :meth:`from_curve`, :meth:`from_sliders` or :meth:`jenkins`.
    """

    def __init__(self, model: Model):
        if model.derived_n != model.n:  # _clib.Model must mirror iwan_model field by field
            raise ImportError("fmu_src._iwan does not match fmu_src._clib.Model: "
                              "rebuild with `pip install -e .`")
        self._model = model
        self._mp = ct.pointer(model)   # resolved once: every call passes the same pointer
        #: Largest force error of the reduction to MAX_SLIDERS [N] (from_virgin_curve).
        self.fit_error = 0.0

    # ------------------------------------------------------------ construction
    @classmethod
    def from_curve(cls, u, T, N_ref, fit: str = "reject", scale: float = 1.0,
                   tail: str = "slope") -> IwanElement:
        """Element reproducing a concave piecewise-linear virgin curve exactly (Iwan).

        Parameters
        ----------
        u, T : array_like, shape (m,)
            Virgin curve: displacement [m] strictly increasing from 0, force [N] from 0.
        N_ref : float
            Normal load [N] at which the curve was computed.
        fit : {"reject", "concave"}
            "reject": a non-concave table raises ``IwanInputError`` naming the point.
            "concave": use the least concave non-decreasing majorant (upper hull, flat
            after the maximum).
        scale : float
            Friction scale multiplying every slip strength (>= 0).
        tail : {"slope", "flat"}
            Beyond u[-1]: the last slope continues as the residual spring, or the force
            stays at T[-1] (gross slip: :func:`flat_tail`, k_res = 0).

        A table with more slope changes than ``MAX_SLIDERS`` is refused here; use
        :meth:`from_virgin_curve` or :func:`fmu_src.curve_fit.prepare_table` to reduce it.
        """
        if tail not in TAILS:
            raise IwanInputError(f"tail must be one of {TAILS}, got {tail!r}")
        u, T = check_table(u, T, fit)
        if tail == "flat":
            u, T = flat_tail(u, T)
        model = Model()
        status = _lib.iwan_model_init(ct.byref(model), arr(u), arr(T), u.size, float(N_ref),
                                      _FIT_CODE[fit])
        if status == 2:    # every other table rule was checked above: the slider limit
            raise IwanInputError(f"IwanElement.from_curve: the curve has more than {MAX_SLIDERS} "
                                 "slope changes (the element's limit); reduce it with "
                                 "fmu_src.curve_fit.prepare_table or IwanElement.from_virgin_curve")
        _check(status, "IwanElement.from_curve")
        return cls._scaled(model, scale)

    @classmethod
    def from_virgin_curve(cls, curve, fit: str = "reject", scale: float = 1.0) -> IwanElement:
        """Element of a curve object (``contact_core.curve.VirginCurve``: ``.u``, ``.T``, ``.N``, ``.tail``).

        The one place where every tool (``damper loop``, ``damper fmu``, harmonic
        balance) turns a curve file into an element: N_ref is the curve's N (1 when
        it records none), the tail is the curve's own (``"flat"``: gross slip), and a
        curve with more segments than the element holds is reduced by the min-max
        optimal fit (:func:`fmu_src.curve_fit.prepare_table`); the element's
        :attr:`fit_error` [N] is that fit's largest force error (0.0 if not reduced).
        """
        if fit not in FITS:
            raise IwanInputError(f"fit must be one of {FITS}, got {fit!r}")
        u, T, error = prepare_table(curve.u, curve.T, fit, curve.tail)
        N_ref = curve.N if curve.N is not None else 1.0
        el = cls.from_curve(u, T, N_ref, fit=fit, scale=scale, tail=curve.tail)
        el.fit_error = error
        return el

    @classmethod
    def from_sliders(cls, k, fs, k_res: float = 0.0, N_ref: float = 1.0) -> IwanElement:
        """Element from slider stiffnesses ``k`` [N/m] and strengths ``fs`` [N] (shape (n,))."""
        k = np.atleast_1d(np.asarray(k, dtype=np.float64)).copy()
        fs = np.atleast_1d(np.asarray(fs, dtype=np.float64)).copy()
        if k.ndim != 1 or k.shape != fs.shape or k.size > MAX_SLIDERS:
            raise IwanInputError(f"k and fs must have the same shape (n,), n <= {MAX_SLIDERS}")
        model = Model()
        _check(_lib.iwan_model_from_sliders(ct.byref(model), arr(k), arr(fs), k.size, float(k_res),
                                            float(N_ref)), "IwanElement.from_sliders")
        return cls(model)

    @classmethod
    def jenkins(cls, k: float, fs: float) -> IwanElement:
        """One Jenkins element (spring k [N/m] in series with a slider fs [N]), N_ref = 1."""
        return cls.from_sliders([k], [fs], 0.0, 1.0)

    def __reduce__(self):
        """Pickle (e.g. to a process pool) as the C model's bytes: the copy is bit-identical."""
        return (_from_model_bytes, (bytes(self._model), self.fit_error))

    @classmethod
    def _scaled(cls, model: Model, scale: float) -> IwanElement:
        scale = float(scale)
        if not np.isfinite(scale) or scale < 0.0:
            raise IwanInputError(f"scale must be finite and >= 0, got {scale!r}")
        model.scale = scale
        return cls(model)

    # ------------------------------------------------------------ parameters
    n_sliders = property(lambda self: int(self._model.n))
    k = property(lambda self: np.array(self._model.k[: self._model.n]))
    fs = property(lambda self: np.array(self._model.fs[: self._model.n]))
    k_res = property(lambda self: float(self._model.k_res))
    N_ref = property(lambda self: float(self._model.n_ref))
    scale = property(lambda self: float(self._model.scale))

    def slip_radii(self, N: float | None = None) -> np.ndarray:
        """Slider stretch at slip, fs_j scale N / (N_ref k_j) [m], shape (n_sliders,).

        The virgin curve at N is piecewise linear with these breakpoints.
        """
        N = self.N_ref if N is None else float(N)
        return self.fs * self.scale * (N / self.N_ref) / self.k

    def gross_slip_force(self, N: float | None = None) -> float:
        """Largest force of the element at N [N]: total slip strength, or inf if k_res > 0."""
        if self.k_res > 0.0:
            return float("inf")
        N = self.N_ref if N is None else float(N)
        return float(np.sum(self.fs) * self.scale * max(N, 0.0) / self.N_ref)

    def __repr__(self):
        return (f"IwanElement(n_sliders={self.n_sliders}, k_res={self.k_res!r}, "
                f"N_ref={self.N_ref!r}, scale={self.scale!r})")

    # ------------------------------------------------------------ evaluation
    def initial_state(self, N: float | None = None) -> IwanState:
        """Virgin state at u = 0 under normal load N [N] (default ``N_ref``)."""
        raw = State()
        _check(_lib.iwan_state_init(self._mp, ct.byref(raw),
                           self.N_ref if N is None else float(N)), "IwanElement.initial_state")
        return IwanState(raw, self.n_sliders)

    def step(self, state: IwanState, u: float, N: float | None = None) -> StepOutput:
        """Advance ``state`` in place along the straight path to (u, N); N defaults to N_ref."""
        out = Output()
        _check(_lib.iwan_step(self._mp, ct.byref(state._raw), float(u),
                     self.N_ref if N is None else float(N), ct.byref(out)), "IwanElement.step")
        return StepOutput(out.F, out.kt, out.dFdN, out.W, out.E, out.slip)

    def eval(self, state: IwanState, u: float, N: float | None = None) -> StepOutput:
        """Outputs at (u, N) reached from ``state`` by the straight path; ``state`` unchanged.

        The trial of :meth:`step` (the same C code, the same bits), for integrators
        that evaluate forces at points they may reject and commit accepted ones with
        :meth:`step`.
        """
        out = Output()
        _check(_lib.iwan_eval(self._mp, ct.byref(state._raw), float(u),
                     self.N_ref if N is None else float(N), None, ct.byref(out)),
               "IwanElement.eval")
        return StepOutput(out.F, out.kt, out.dFdN, out.W, out.E, out.slip)

    # batches of independent states (one C call per sample): fmu_src.element_batch
    def initial_states(self, n: int, N=None) -> np.ndarray:
        """``n`` virgin states in one buffer (:func:`fmu_src.element_batch.initial_states`)."""
        from .element_batch import initial_states
        return initial_states(self, n, N)

    def step_batch(self, states: np.ndarray, u, N=None, out=None):
        """One sample for each state, one C call (:func:`fmu_src.element_batch.step_batch`)."""
        from .element_batch import step_batch
        return step_batch(self, states, u, N, out)

    def batch_stepper(self, states: np.ndarray, N=None):
        """Fixed-buffer stepper on ``states`` (:class:`fmu_src.element_batch.BatchStepper`)."""
        from .element_batch import BatchStepper
        return BatchStepper(self, states, N)

    def series(self, u, N=None, state: IwanState | None = None) -> SeriesResult:
        """Whole history in one C call.

        Parameters
        ----------
        u : array_like, shape (n,)
            Displacement samples [m], joined by straight paths (with N).
        N : None, float or array_like shape (n,)
            Normal load [N]; None means ``N_ref``.
        state : IwanState, optional
            Start state (not modified); default virgin at u = 0 and N[0].

        Returns
        -------
        SeriesResult
            F, kt, dFdN, W of shape (n,) and the state after the last sample.
        """
        u = _vec(u, "u")
        n = u.size
        Nv = None if N is None else _normal(N, n, self.N_ref)
        if state is None:
            st = self.initial_state(None if Nv is None else Nv[0])
        else:
            st = state.copy()
        out = np.empty((4, n))
        _check(_lib.iwan_series(self._mp, ct.byref(st._raw), n, arr(u), arr(Nv), arr(out[0]),
                                arr(out[1]), arr(out[2]), arr(out[3])), "IwanElement.series")
        return SeriesResult(out[0], out[1], out[2], out[3], st)

    def periodic(self, u, N=None, max_periods: int = 100, tol: float = 1e-12) -> PeriodicResult:
        """Converged loop of a periodic input, u shape (n,) (sample n = sample 0).

        Constant N: exact in one pass. Varying N: periods are repeated until the
        state recurs within ``tol`` times the force range (``IwanNotConvergedError``
        after ``max_periods``).
        """
        u = _vec(u, "u")
        n = u.size
        Nv = None if N is None else _normal(N, n, self.N_ref)
        out = np.empty((3, n))
        w = ct.c_double()
        p = ct.c_int()
        _check(_lib.iwan_periodic(self._mp, n, arr(u), arr(Nv), arr(out[0]), arr(out[1]),
                                  arr(out[2]), ct.byref(w),
                                  int(max_periods), float(tol), ct.byref(p)),
               "IwanElement.periodic")
        return PeriodicResult(out[0], out[1], out[2], w.value, p.value)

    def _jac_inputs(self, u, Eu, N, EN):
        """Checked inputs of the periodic Jacobians: u (n,), n, Eu (n, nb), nb, the normal
        load samples (or None) and EN (n, nb) (or None)."""
        u = _vec(u, "u")
        n = u.size
        Eu = np.ascontiguousarray(Eu, dtype=np.float64)
        if Eu.ndim != 2 or Eu.shape[0] != n or Eu.shape[1] == 0:
            raise IwanInputError(f"Eu must have shape ({n}, nb), got {Eu.shape}")
        Nv = None if N is None else _normal(N, n, self.N_ref)
        ENa = None
        if EN is not None:
            ENa = np.ascontiguousarray(EN, dtype=np.float64)
            if ENa.shape != Eu.shape:
                raise IwanInputError(f"EN must have shape {Eu.shape}, got {ENa.shape}")
        return u, n, Eu, Eu.shape[1], Nv, ENa

    def periodic_jac(self, u, Eu, N=None, EN=None, max_periods: int = 100,
                     tol: float = 1e-12):
        """Periodic loop and its exact derivatives for u = Eu X (and N = EN XN).

        Parameters
        ----------
        u : array_like, shape (n,)
            Displacement samples [m] over one period (u = Eu @ X).
        Eu : array_like, shape (n, nb)
            Basis (e.g. the inverse DFT) mapping coefficients X to u.
        N : None, float or array_like shape (n,)
            Normal load [N] (N = EN @ XN when EN is given).
        EN : array_like, shape (n, nb), optional
            Basis of the normal load.

        Returns
        -------
        F : ndarray (n,);  dFdX : ndarray (n, nb);  dFdXN : ndarray (n, nb) or None;
        W_cycle : float
        """
        u, n, Eu, nb, Nv, ENa = self._jac_inputs(u, Eu, N, EN)
        F = np.empty(n)
        dFdX = np.empty((n, nb))
        dFdXN = None if ENa is None else np.empty((n, nb))
        w = ct.c_double()
        p = ct.c_int()
        _check(_lib.iwan_periodic_jac(self._mp, n, arr(u), arr(Nv), arr(Eu), arr(ENa), nb, arr(F),
                                      arr(dFdX), arr(dFdXN),
                                      ct.byref(w), int(max_periods), float(tol), ct.byref(p)),
               "IwanElement.periodic_jac")
        return F, dFdX, dFdXN, w.value

    def periodic_jac_rows(self, u, Eu, N=None, EN=None, max_periods: int = 100,
                          tol: float = 1e-12):
        """:meth:`periodic_jac` with the Jacobian's non-zero rows only (same numbers).

        On a stiff contact in gross slip only the few samples where a slider sticks
        depend on X (a slipping slider carries +-g), so the C core fills those rows
        alone: O(n + rows x nb) instead of O(n x nb).

        Returns
        -------
        F : ndarray (n,);  rows : ndarray (r,) of int, the samples whose rows follow;
        dFdX : ndarray (r, nb);  dFdXN : ndarray (r, nb) or None;  W_cycle : float.
        Every row not in ``rows`` is exactly zero.
        """
        u, n, Eu, nb, Nv, ENa = self._jac_inputs(u, Eu, N, EN)
        F = np.empty(n)
        rows = np.empty(n, dtype=np.uintp)
        dFdX = np.empty((n, nb))
        dFdXN = None if ENa is None else np.empty((n, nb))
        r, w, p = ct.c_size_t(), ct.c_double(), ct.c_int()
        _check(_lib.iwan_periodic_jac_rows(self._mp, n, arr(u), arr(Nv), arr(Eu), arr(ENa), nb,
                                           arr(F), arr(rows, _clib.SizeArray), ct.byref(r),
                                           arr(dFdX), arr(dFdXN), ct.byref(w), int(max_periods),
                                           float(tol), ct.byref(p)),
               "IwanElement.periodic_jac_rows")
        k = r.value
        return (F, rows[:k].astype(np.intp), dFdX[:k], None if dFdXN is None else dFdXN[:k],
                w.value)

    def periodic_jac_terms(self, u, N=None, with_N: bool = False, max_periods: int = 100,
                           tol: float = 1e-12):
        """:meth:`periodic_jac`'s Jacobian as sparse terms in the samples (same numbers
        to round-off), for any basis: row t of dF/dX is ``dX[t] Eu[t] + sum_i cX[i]
        Eu[col[i]]`` over the terms with ``row[i] == t`` (of dF/dXN, with ``with_N`` and
        N given, the same with dXN, cXN and EN; else they are zero). The diagonal is a
        stuck slider's stiffness or a slipping one's strength slope; the other terms
        are the samples where stuck sliders stuck and the ends of a re-contact step
        (few distinct columns), so a projection onto a Fourier basis needs no (n, nb)
        row per sample (:meth:`harmonic_balance.fourier.FourierBasis.project_terms`).

        Returns
        -------
        F, dX, dXN : ndarray (n,);  row, col : ndarray (k,) of int (col != row);
        cX, cXN : ndarray (k,);  W_cycle : float.
        """
        u = _vec(u, "u")
        n = u.size
        Nv = None if N is None else _normal(N, n, self.N_ref)
        cap = n * (2 * self._model.n + 2)
        F, dX, dXN = np.empty(n), np.empty(n), np.empty(n)
        row, col = np.empty(cap, dtype=np.uintp), np.empty(cap, dtype=np.uintp)
        cX, cXN = np.empty(cap), np.empty(cap)
        k, w, p = ct.c_size_t(), ct.c_double(), ct.c_int()
        _check(_lib.iwan_periodic_jac_terms(self._mp, n, arr(u), arr(Nv), int(bool(with_N)), arr(F),
                                            arr(dX), arr(dXN), cap, ct.byref(k),
                                            arr(row, _clib.SizeArray), arr(col, _clib.SizeArray),
                                            arr(cX), arr(cXN), ct.byref(w), int(max_periods),
                                            float(tol), ct.byref(p)),
               "IwanElement.periodic_jac_terms")
        r = k.value
        # size_t -> intp without a copy (indices < n): numpy indexes and counts with intp
        return (F, dX, dXN, row[:r].view(np.intp), col[:r].view(np.intp), cX[:r], cXN[:r],
                w.value)

    def periodic_branches(self, u_ext):
        """Exact periodic loop of an input monotone between its extrema ``u_ext`` (n >= 2,
        alternating maxima and minima, periodic), at N_ref: piecewise-linear branches.

        Returns
        -------
        dict with ``seg`` (m,) int (segment: from extremum seg to the next), ``u_lo``,
        ``u_hi`` (m,) [m] (interval ends in travel order), ``slope`` (m,) [N/m],
        ``icpt`` (m,) [N] (F = icpt + slope u on the interval), ``A`` (m, n) [N/m]
        (d icpt / d u_ext = -A) and ``W`` [J] (energy dissipated per period).
        """
        u = _vec(u_ext, "u_ext")
        n = u.size
        if n < 2:
            raise IwanInputError(f"u_ext needs at least two extrema, got {n}")
        cap = n * (self._model.n + 1)
        seg = np.empty(cap, dtype=np.uintp)
        lo, hi, sl, c = (np.empty(cap) for _ in range(4))
        A = np.empty((cap, n))
        m, w = ct.c_size_t(), ct.c_double()
        _check(_lib.iwan_periodic_branches(self._mp, n, arr(u), cap, ct.byref(m),
                                           arr(seg, _clib.SizeArray), arr(lo), arr(hi), arr(sl),
                                           arr(c), arr(A), ct.byref(w)),
               "IwanElement.periodic_branches")
        k = m.value
        return {"seg": seg[:k].astype(np.intp), "u_lo": lo[:k], "u_hi": hi[:k],
                "slope": sl[:k], "icpt": c[:k], "A": A[:k], "W": w.value}

    def periodic_fourier(self, harmonics, U, n_scan: int):
        """Exact Fourier coefficients of the periodic loop (N_ref) for the input with
        coefficients ``U`` (n_b,) over ``harmonics`` (ascending; per harmonic cos, sin, the
        mean alone), and their Jacobian: (Fh (n_b,), dFh (n_b, n_b), W [J], extrema found;
        0 for a constant input, then Fh and dFh are zero). ``n_scan`` > 2 max(harmonics):
        the points of u' scanned for its sign changes."""
        h, nb = _harmonic_orders(harmonics)
        U = _vec(U, "U")
        if U.size != nb:
            raise IwanInputError(f"U must have {nb} coefficients for harmonics {tuple(h)}, got {U.size}")
        Fh, dFh = np.empty(nb), np.empty((nb, nb))
        w, ne = ct.c_double(), ct.c_size_t()
        _check(_lib.iwan_periodic_fourier(self._mp, h.size, arr(h, _clib.Int32Array), arr(U),
                                          int(n_scan), arr(Fh), arr(dFh), ct.byref(w),
                                          ct.byref(ne)),
               "IwanElement.periodic_fourier")
        return Fh, dFh, w.value, ne.value

    def virgin(self, u, N: float | None = None) -> np.ndarray:
        """Virgin-curve force [N] at normal load N (default N_ref), odd extension, shape (n,)."""
        u = _vec(u, "u")
        order = np.argsort(np.abs(u), kind="stable")
        F = np.empty_like(u)
        F[order] = self.series(np.abs(u)[order], None if N is None else float(N)).F
        return np.sign(u) * F


#: The orders of periodic_fourier's harmonic sets met so far (a basis passes the same
#: tuple at every call): (int32 array, n_b), so a call converts none.
_ORDERS: dict = {}


def _harmonic_orders(harmonics):
    """(int32 C array of the orders, n_b) of a harmonic set, kept per tuple."""
    key = tuple(int(k) for k in harmonics) if not isinstance(harmonics, tuple) else harmonics
    got = _ORDERS.get(key)
    if got is None:
        h = np.ascontiguousarray(key, dtype=np.int32)
        got = _ORDERS[key] = (h, int(np.sum(np.where(h == 0, 1, 2))))
    return got
