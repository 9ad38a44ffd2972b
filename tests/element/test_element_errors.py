"""Bad input gives a clear exception (ValueError / RuntimeError), never a crash or a number."""
from __future__ import annotations

import numpy as np
import pytest
from elcases import N_SPHERE, cattaneo_table

from fmu_src.element import IwanElement, IwanInputError, IwanNotConvergedError

U_TAB, T_TAB = cattaneo_table(10)


def mutated(**changes):
    u, T = U_TAB.copy(), T_TAB.copy()
    for name, (i, value) in changes.items():
        {"u": u, "T": T}[name][i] = value
    return u, T


#: The key phrase of the generic refusal of a non-positive count or size.
BAD_PARAMETER = r"bad parameter \(k <= 0, fs < 0, k_res < 0, N_ref <= 0"


@pytest.mark.parametrize("u, T, N_ref, message", [
    (*mutated(u=(3, np.nan)), N_SPHERE, "point 3: u = nan is not finite"),
    (*mutated(T=(4, np.inf)), N_SPHERE, "point 4: T = inf is not finite"),
    (*mutated(u=(0, 1e-9)), N_SPHERE, r"a virgin curve starts at \(0, 0\)"),
    (*mutated(T=(0, 1.0)), N_SPHERE, r"a virgin curve starts at \(0, 0\)"),
    (*mutated(u=(5, U_TAB[4])), N_SPHERE, "point 5: .*u must be strictly increasing"),
    (*mutated(T=(3, T_TAB[3] - 5.0)), N_SPHERE, "not concave at point 3"),
    (U_TAB[:1], T_TAB[:1], N_SPHERE, "needs at least 2 points"),
    (U_TAB, np.zeros_like(T_TAB), N_SPHERE, "T is 0 at every point: no stiffness"),
    (U_TAB, T_TAB, 0.0, BAD_PARAMETER),
    (U_TAB, T_TAB, -1.0, BAD_PARAMETER),
    (U_TAB, T_TAB, np.nan, "NaN or infinite input"),
    (U_TAB, T_TAB[:-1], N_SPHERE, "u and T must be 1-D of equal length"),
])
def test_bad_curve_tables_raise_value_error(u, T, N_ref, message):
    with pytest.raises(ValueError, match=message):
        IwanElement.from_curve(u, T, N_ref)


def test_too_many_slope_changes_are_refused():
    m = 300
    u = np.linspace(0, 1, m)
    with pytest.raises(ValueError, match="more than 256 slope changes"):
        IwanElement.from_curve(u, np.sqrt(u), 1.0)


@pytest.mark.parametrize("kwargs, message", [
    (dict(k=[-1.0], fs=[1.0]), BAD_PARAMETER), (dict(k=[1.0], fs=[-1.0]), BAD_PARAMETER),
    (dict(k=[1.0], fs=[np.nan]), "NaN or infinite input"),
    (dict(k=[1.0], fs=[1.0], k_res=-1.0), BAD_PARAMETER), (dict(k=[1.0], fs=[1.0], N_ref=0.0), BAD_PARAMETER),
    (dict(k=[1.0, 2.0], fs=[1.0]), "k and fs must have the same shape"),
    (dict(k=np.ones(300), fs=np.ones(300)), "n <= 256"),
])
def test_bad_sliders_raise_value_error(kwargs, message):
    with pytest.raises(ValueError, match=message):
        IwanElement.from_sliders(**kwargs)


def test_bad_scale_and_fit_raise_value_error():
    with pytest.raises(ValueError, match="scale must be finite and >= 0, got -1.0"):
        IwanElement.from_curve(U_TAB, T_TAB, N_SPHERE, scale=-1.0)
    with pytest.raises(ValueError, match=r"fit must be one of \('reject', 'concave'\), got 'smooth'"):
        IwanElement.from_curve(U_TAB, T_TAB, N_SPHERE, fit="smooth")


def test_nonfinite_histories_raise_and_commit_nothing():
    el = IwanElement.jenkins(1e6, 2.0)
    st = el.initial_state()
    el.step(st, 1e-6)
    before = (st.u, st.W, st.z.copy())
    for u, N in [(np.nan, 1.0), (np.inf, 1.0), (1e-6, np.nan)]:
        with pytest.raises(ValueError, match="NaN or infinite"):
            el.step(st, u, N)
    assert (st.u, st.W) == before[:2] and np.array_equal(st.z, before[2])
    for bad, message in (([0.0, np.nan], "NaN or infinite input"), ([], r"n >= 1, got \(0,\)")):
        with pytest.raises(ValueError, match=message):
            el.series(bad)
        with pytest.raises(ValueError, match=message):
            el.periodic(bad)
    with pytest.raises(ValueError, match=r"N must have shape \(2,\), got \(1,\)"):
        el.series([0.0, 1e-6], N=[1.0])                  # shape mismatch
    with pytest.raises(ValueError, match="IwanElement.periodic: bad parameter"):
        el.periodic([0.0, 1e-6], tol=-1.0)
    with pytest.raises(ValueError, match=r"Eu must have shape \(2, nb\), got \(3, 2\)"):
        el.periodic_jac([0.0, 1e-6], np.ones((3, 2)))


def test_periodic_loop_that_cannot_close_raises_runtime_error():
    el = IwanElement.from_curve(U_TAB, T_TAB, N_SPHERE)
    th = 2 * np.pi * np.arange(32) / 32
    u = 4e-6 * np.cos(th)
    N = N_SPHERE * (1 + 0.5 * np.sin(th))                # varying N: needs two periods at least
    with pytest.raises(IwanNotConvergedError):
        el.periodic(u, N, max_periods=1)
    with pytest.raises(RuntimeError):
        el.periodic_jac(u, np.ones((32, 1)), N, max_periods=1)
    assert el.periodic(u, N).periods >= 2


def test_exceptions_are_value_and_runtime_errors():
    assert issubclass(IwanInputError, ValueError)
    assert issubclass(IwanNotConvergedError, RuntimeError)


def test_non_concave_message_points_to_the_fit_option():
    u, T = mutated(T=(3, T_TAB[3] - 4.0))
    with pytest.raises(ValueError, match="not concave.*fit='concave'"):
        IwanElement.from_curve(u, T, N_SPHERE)
    assert IwanElement.from_curve(u, T, N_SPHERE, fit="concave").n_sliders < U_TAB.size
