"""The one ctypes layer over the C core (``fmu_src/core/iwan.h``): library, structs, signatures.

Every C function the Python side calls is declared here once, with typed
arguments: the structs by pointer to their ctypes mirror, arrays as
``POINTER(c_double)`` / ``POINTER(State)`` (:func:`arr` turns a numpy array into
one, ``None`` is NULL), scalar outputs as ``POINTER(c_double)`` / ``POINTER(c_int)``.
``tests/element/test_clib_header.py`` parses ``iwan.h`` and checks every declaration
(and every struct field) against it.

:mod:`fmu_src.element` and :mod:`fmu_src.element_batch` both import this module and
never each other both ways. Symbols as in :mod:`fmu_src.element`.
"""
from __future__ import annotations

import ctypes as ct
import importlib.machinery
from pathlib import Path

import numpy as np

__all__ = ["MAX_SLIDERS", "STATE_VERSION", "STATE2_VERSION", "Model", "State", "Output", "State2",
           "Output2", "MAX_NORMAL", "CPOINT_STATE_VERSION", "CPointModel", "CPointState",
           "CPointOutput", "STATE_DTYPE",
           "DoubleArray", "StateArray", "SizeArray", "Int32Array", "arr", "FUNCTIONS", "lib", "check", "IwanInputError",
           "IwanNotConvergedError", "vec", "normal"]

MAX_SLIDERS = 256          # IWAN_MAX_SLIDERS in iwan.h (the header test checks it)
STATE_VERSION = 1          # IWAN_STATE_VERSION in iwan.h
STATE2_VERSION = 1         # IWAN2_STATE_VERSION in iwan2d.h


class IwanInputError(ValueError):
    """Bad input to the element (NaN, bad table, bad parameter or state)."""


class IwanNotConvergedError(RuntimeError):
    """The periodic loop did not close within the allowed number of periods."""


# ------------------------------------------------------------------ the structs (once)
class Model(ct.Structure):
    """``iwan_model``."""
    _fields_ = [("n", ct.c_int32), ("k", ct.c_double * MAX_SLIDERS),
                ("fs", ct.c_double * MAX_SLIDERS), ("k_res", ct.c_double),
                ("n_ref", ct.c_double), ("scale", ct.c_double),
                ("rad", ct.c_double * MAX_SLIDERS), ("fs_sum", ct.c_double),
                ("derived_n", ct.c_int32)]


class State(ct.Structure):
    """``iwan_state``."""
    _fields_ = [("version", ct.c_int32), ("in_contact", ct.c_int32), ("u", ct.c_double),
                ("N", ct.c_double), ("u_contact", ct.c_double), ("w_diss", ct.c_double),
                ("z", ct.c_double * MAX_SLIDERS), ("dir", ct.c_double)]


class Output(ct.Structure):
    """``iwan_output``."""
    _fields_ = [(name, ct.c_double) for name in ("F", "kt", "dFdN", "W", "E", "slip")]


class State2(ct.Structure):
    """``iwan2_state`` (iwan2d.h)."""
    _fields_ = [("version", ct.c_int32), ("in_contact", ct.c_int32), ("u", ct.c_double * 2),
                ("N", ct.c_double), ("u_contact", ct.c_double * 2), ("w_diss", ct.c_double),
                ("dir", ct.c_double * 2), ("z", ct.c_double * (2 * MAX_SLIDERS))]


class Output2(ct.Structure):
    """``iwan2_output`` (iwan2d.h)."""
    _fields_ = [("F", ct.c_double * 2), ("K", ct.c_double * 4), ("dFdN", ct.c_double * 2),
                ("W", ct.c_double), ("E", ct.c_double), ("slip", ct.c_double)]


MAX_NORMAL = 256           # CPOINT_MAX_NORMAL in contact_point.h
CPOINT_STATE_VERSION = 1   # CPOINT_STATE_VERSION in contact_point.h


class CPointModel(ct.Structure):
    """``cpoint_model`` (contact_point.h)."""
    _fields_ = [("t", Model), ("n_normal", ct.c_int32), ("p", ct.c_double * MAX_NORMAL),
                ("N", ct.c_double * MAX_NORMAL), ("E_n", ct.c_double * MAX_NORMAL),
                ("c_t", ct.c_double), ("c_n", ct.c_double)]


class CPointState(ct.Structure):
    """``cpoint_state`` (contact_point.h)."""
    _fields_ = [("version", ct.c_int32), ("reserved", ct.c_int32), ("p", ct.c_double),
                ("s", State2)]


class CPointOutput(ct.Structure):
    """``cpoint_output`` (contact_point.h)."""
    _fields_ = [("f", ct.c_double * 3), ("K", ct.c_double * 9), ("C", ct.c_double * 3),
                ("W", ct.c_double), ("E", ct.c_double), ("slip", ct.c_double),
                ("state", ct.c_int32)]


#: numpy view of ``iwan_state`` (one record per state), derived from :class:`State`.
STATE_DTYPE = np.dtype(State)


# ------------------------------------------------------------------ typed pointers
#: ``double *``: arrays are passed as ``arr(x)`` (a float64 C-contiguous numpy array).
DoubleArray = ct.POINTER(ct.c_double)
#: ``iwan_state *``: one state (``ct.byref``) or a batch (``arr(states, StateArray)``).
StateArray = ct.POINTER(State)
#: ``int32_t *``: small integer arrays (``arr(h, Int32Array)``, numpy dtype ``np.int32``).
Int32Array = ct.POINTER(ct.c_int32)
#: ``size_t *``: index arrays (``arr(rows, SizeArray)``, numpy dtype ``np.uintp``).
SizeArray = ct.POINTER(ct.c_size_t)


def arr(a, kind=DoubleArray):
    """Typed pointer to the data of numpy array ``a`` (None -> NULL).

    ``a`` must be C-contiguous with the pointer's dtype (float64, or
    :data:`STATE_DTYPE` for ``StateArray``); the callers make it so (``vec``).
    The conversion happens here (``byref`` of the buffer when writeable, the cheapest
    typed form; a cast pointer otherwise), so that ctypes checks only the pointer type,
    a C-level test, at the call; a fixed argument list resolved once (``BatchStepper``)
    can be reused for every call.
    """
    if a is None:
        return None
    want = (STATE_DTYPE if kind is StateArray else np.uintp if kind is SizeArray
            else np.int32 if kind is Int32Array else np.float64)
    if a.dtype != want or not a.flags.c_contiguous:
        raise TypeError(f"expected a C-contiguous {np.dtype(want)} array, got {a.dtype} "
                        f"(contiguous: {a.flags.c_contiguous})")
    if a.flags.writeable:
        return ct.byref(kind._type_.from_buffer(a))
    return a.ctypes.data_as(kind)


_S, _D, _I = ct.c_size_t, ct.c_double, ct.c_int
_PM, _PS, _PO = ct.POINTER(Model), ct.POINTER(State), ct.POINTER(Output)
_PD, _PI = ct.POINTER(ct.c_double), ct.POINTER(ct.c_int)
_PS2, _PO2 = ct.POINTER(State2), ct.POINTER(Output2)
_PCM, _PCS, _PCO = ct.POINTER(CPointModel), ct.POINTER(CPointState), ct.POINTER(CPointOutput)
_STATUS = ct.c_int   # iwan_status (an enum: int)

#: name -> (restype, argtypes), in iwan.h, iwan2d.h, contact_point.h order. The only declaration of each function.
FUNCTIONS = {
    "iwan_model_init": (_STATUS, [_PM, DoubleArray, DoubleArray, _S, _D, _I]),
    "iwan_model_from_sliders": (_STATUS, [_PM, DoubleArray, DoubleArray, _S, _D, _D]),
    "iwan_state_init": (_STATUS, [_PM, _PS, _D]),
    "iwan_eval": (_STATUS, [_PM, _PS, _D, _D, _PS, _PO]),
    "iwan_step": (_STATUS, [_PM, _PS, _D, _D, _PO]),
    "iwan_series": (_STATUS, [_PM, _PS, _S, DoubleArray, DoubleArray, DoubleArray,
                              DoubleArray, DoubleArray, DoubleArray]),
    "iwan_step_batch": (_STATUS, [_PM, StateArray, _S, DoubleArray, DoubleArray,
                                  DoubleArray, DoubleArray]),
    "iwan_periodic": (_STATUS, [_PM, _S, DoubleArray, DoubleArray, DoubleArray, DoubleArray,
                                DoubleArray, _PD, _I, _D, _PI]),
    "iwan_periodic_jac": (_STATUS, [_PM, _S, DoubleArray, DoubleArray, DoubleArray,
                                    DoubleArray, _S, DoubleArray, DoubleArray, DoubleArray,
                                    _PD, _I, _D, _PI]),
    "iwan_periodic_jac_rows": (_STATUS, [_PM, _S, DoubleArray, DoubleArray, DoubleArray,
                                         DoubleArray, _S, DoubleArray, SizeArray, ct.POINTER(_S),
                                         DoubleArray, DoubleArray, _PD, _I, _D, _PI]),
    "iwan_periodic_jac_many": (_STATUS, [ct.POINTER(_PM), _S, _S, DoubleArray, DoubleArray,
                                         DoubleArray, ct.POINTER(DoubleArray), _S, DoubleArray,
                                         DoubleArray, DoubleArray, DoubleArray, _I, _D,
                                         ct.POINTER(_S)]),
    "iwan_periodic_many": (_STATUS, [ct.POINTER(_PM), _S, _S, DoubleArray, DoubleArray,
                                     DoubleArray, DoubleArray, _I, _D, ct.POINTER(_S)]),
    "iwan_periodic_jac_terms": (_STATUS, [_PM, _S, DoubleArray, DoubleArray, _I, DoubleArray,
                                          DoubleArray, DoubleArray, _S, ct.POINTER(_S),
                                          SizeArray, SizeArray, DoubleArray, DoubleArray, _PD,
                                          _I, _D, _PI]),
    "iwan_periodic_branches": (_STATUS, [_PM, _S, DoubleArray, _S, SizeArray, SizeArray,
                                         DoubleArray, DoubleArray, DoubleArray, DoubleArray,
                                         DoubleArray, _PD]),
    "iwan_periodic_fourier": (_STATUS, [_PM, _S, Int32Array, DoubleArray, _S, DoubleArray,
                                        DoubleArray, _PD, SizeArray]),
    "iwan_status_text": (ct.c_char_p, [_STATUS]),
    # iwan2d.h: the 2D element (same model)
    "iwan2_state_init": (_STATUS, [_PM, _PS2, _D]),
    "iwan2_eval": (_STATUS, [_PM, _PS2, _D, _D, _D, _PS2, _PO2]),
    "iwan2_step": (_STATUS, [_PM, _PS2, _D, _D, _D, _PO2]),
    "iwan2_series": (_STATUS, [_PM, _PS2, _S, DoubleArray, DoubleArray, DoubleArray,
                               DoubleArray, DoubleArray]),
    "iwan2_periodic_work_size": (_S, [_S]),
    "iwan2_periodic_jac": (_STATUS, [_PM, _S, DoubleArray, DoubleArray, DoubleArray, DoubleArray,
                                     DoubleArray, _S, DoubleArray, DoubleArray, _PD, _I, _D, _PI,
                                     DoubleArray]),
    # contact_point.h: the 3D contact point (2D element + normal law)
    "cpoint_model_init": (_STATUS, [_PCM, _PM, DoubleArray, DoubleArray, _S, _D, _D]),
    "cpoint_normal": (_D, [_PCM, _D, _PD]),
    "cpoint_state_init": (_STATUS, [_PCM, _PCS, _D]),
    "cpoint_eval": (_STATUS, [_PCM, _PCS, DoubleArray, DoubleArray, _PCS, _PCO]),
    "cpoint_step": (_STATUS, [_PCM, _PCS, DoubleArray, DoubleArray, _PCO]),
    "cpoint_check_state": (_STATUS, [_PCM, _PCS]),
}


def _load_library() -> ct.CDLL:
    here = Path(__file__).resolve().parent
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = here / f"_iwan{suffix}"
        if path.exists():
            return ct.CDLL(str(path))
    raise ImportError(f"fmu_src/_iwan*.so not found in {here}: run `pip install -e .`")


lib = _load_library()
for _name, (_res, _args) in FUNCTIONS.items():
    getattr(lib, _name).restype = _res
    getattr(lib, _name).argtypes = _args

_MESSAGES = {1: "NaN or infinite input", 2: "bad curve table (fewer than 2 points, "
             "not starting at (0, 0), u not strictly increasing, T decreasing, no "
             f"stiffness, or more than {MAX_SLIDERS} slope changes)",
             3: "curve table is not concave (a slope exceeds the previous one); pass "
             "fit='concave' to use its least concave majorant",
             4: "bad parameter (k <= 0, fs < 0, k_res < 0, N_ref <= 0, scale < 0, "
             "empty array, ...)",
             5: "periodic loop did not close within max_periods",
             6: "bad state (other version or corrupted)"}


def check(status: int, where: str) -> None:
    """Raise the Python error of a non-zero ``iwan_status``."""
    if status == 0:
        return
    text = _MESSAGES.get(status) or lib.iwan_status_text(status).decode()
    if status == 5:
        raise IwanNotConvergedError(f"{where}: {text}")
    raise IwanInputError(f"{where}: {text}")


def vec(x, name: str, n: int | None = None) -> np.ndarray:
    """Contiguous float64 1-D copy-free view of ``x`` (shape (n,) when n is given)."""
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim != 1 or a.size == 0 or (n is not None and a.size != n):
        want = f"({n},)" if n is not None else "(n,) with n >= 1"
        raise IwanInputError(f"{name} must have shape {want}, got {a.shape}")
    return a


def normal(N, n: int, default: float) -> np.ndarray:
    """Normal-load samples: None -> ``default`` everywhere, scalar -> constant, shape (n,)."""
    if N is None:
        return np.full(n, float(default))
    if np.ndim(N) == 0:
        return np.full(n, float(N))
    return vec(N, "N", n)
