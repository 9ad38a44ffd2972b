"""Curves the element cannot hold: exact rejection messages, and the optimal reduction."""
from __future__ import annotations

import json

import numpy as np
import pytest
from elcases import MU, N_SPHERE, cattaneo_table

from contact_core.curve import VirginCurve, write_curve
from damper.cli import main
from fmu_src.curve_fit import check_table, concave_majorant, prepare_table, reduce_table, reduce_virgin_curve
from fmu_src.element import MAX_SLIDERS, IwanElement, IwanInputError

U_TAB, T_TAB = cattaneo_table(10)


def _mut(name, i, value):
    u, T = U_TAB.copy(), T_TAB.copy()
    {"u": u, "T": T}[name][i] = value
    return u, T


@pytest.mark.parametrize("u, T, message", [
    ([], [], "empty"),
    ([0.0], [0.0], "one point"),
    (*_mut("u", 3, np.nan), "point 3: u = nan is not finite"),
    (*_mut("T", 4, np.inf), "point 4: T = inf is not finite"),
    (*_mut("u", 0, 1e-9), "point 0 is"),
    (*_mut("u", 5, U_TAB[4]), "point 5: u = .* is not above u\\[4\\]"),
    (*_mut("T", 3, T_TAB[3] - 5.0), "not concave at point 3"),
    (*_mut("T", 6, T_TAB[5] - 1.0), "point 6: T = .* falls below T\\[5\\]"),
    (U_TAB, np.zeros_like(T_TAB), "no stiffness"),
])
def test_each_rejected_curve_names_the_point_and_the_rule(u, T, message):
    with pytest.raises(IwanInputError, match=message):
        check_table(u, T)
    with pytest.raises(IwanInputError, match=message):
        IwanElement.from_curve(u, T, N_SPHERE)


def _exact_minmax(u, T, K):
    """Independent reference: dynamic programming over every chord, O(K m^2)."""
    m = len(u)
    err = np.zeros((m, m))
    for i in range(m):
        for j in range(i + 2, m):
            x = u[i + 1:j]
            chord = T[i] + (T[j] - T[i]) / (u[j] - u[i]) * (x - u[i])
            err[i, j] = np.max(np.abs(T[i + 1:j] - chord))
    best = np.full(m, np.inf)
    best[0] = 0.0
    for _ in range(K):
        best = np.array([min([best[j]] + [max(best[i], err[i, j]) for i in range(j)])
                         for j in range(m)])
    return best[-1]


@pytest.mark.parametrize("m, K", [(30, 4), (41, 7), (25, 12)])
def test_reduction_is_min_max_optimal_and_its_error_exact(m, K):
    u, T = cattaneo_table(m)
    u, T = u[:-1], T[:-1]                      # strictly concave part
    ur, Tr, error = reduce_table(u, T, K)
    assert len(ur) - 1 <= K and ur[0] == 0.0 and ur[-1] == u[-1] and Tr[-1] == T[-1]
    # reported error = measured error of the fit on every point (both are linear between points)
    assert error == pytest.approx(np.max(np.abs(np.interp(u, ur, Tr) - T)), rel=1e-12)
    # optimal: the brute-force min-max over all subsets with K chords, to the bisection's
    # relative width (1e-6)
    assert error == pytest.approx(_exact_minmax(u, T, K), rel=1.5e-6)
    assert np.all(np.diff(np.diff(Tr) / np.diff(ur)) <= 0.0)    # still concave


@pytest.mark.slow
def test_long_curve_is_reduced_to_the_element_limit_with_its_error():
    u, T = cattaneo_table(2000)
    curve = VirginCurve(u=u[:-1], T=T[:-1], N=N_SPHERE, mu=MU, tail="flat")
    reduced, error = reduce_virgin_curve(curve)
    assert reduced.u.size - 1 <= MAX_SLIDERS and reduced.tail == "flat" and reduced.N == curve.N
    el = IwanElement.from_virgin_curve(curve)
    assert el.n_sliders <= MAX_SLIDERS and el.fit_error == error
    # the element's virgin curve is the fit: its force differs from the table by <= error
    F = el.virgin(curve.u)
    assert np.max(np.abs(F - curve.T)) <= error * (1 + 1e-9) + 1e-12 * MU * N_SPHERE
    # 2000 uniform-T segments of Cattaneo-Mindlin, 256 chords: measured 1.43e-4 N (of 50 N)
    assert 0.0 < error < 2.2e-4
    small = VirginCurve(u=U_TAB, T=T_TAB, N=N_SPHERE)
    assert reduce_virgin_curve(small) == (small, 0.0)


def test_concave_fit_of_a_long_noisy_curve_reduces_its_majorant():
    rng = np.random.default_rng(7)
    u = np.linspace(0.0, 1e-5, 1500)
    T = 50.0 * (1 - np.exp(-u / 2e-6)) + rng.normal(0, 0.01, u.size)
    T[0] = 0.0
    with pytest.raises(IwanInputError, match="not concave at point|falls below"):
        prepare_table(u, T, "reject")
    ur, Tr, error = prepare_table(u, T, "concave", "slope")
    uh, Th = concave_majorant(u, T)
    assert len(ur) - 1 <= MAX_SLIDERS + 1 and error <= np.max(Th) - np.min(Th)
    assert np.all(np.interp(u, uh, Th) >= T - 1e-12)          # a majorant of the data


def test_damper_loop_prints_the_reduction_error(tmp_path, capsys):
    u, T = cattaneo_table(600)
    path = write_curve(VirginCurve(u=u[:-1], T=T[:-1], N=N_SPHERE, mu=MU, tail="flat"),
                       tmp_path / "long.json")
    assert main(["loop", "--curve", str(path), "--amplitude", "1e-6", "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert out["curve_points"] == 601 and out["fit_error"] > 0.0
    assert "reduced" in cap.err and "largest force error" in cap.err


def test_damper_loop_names_the_bad_point(tmp_path, capsys):
    u, T = _mut("T", 3, T_TAB[3] - 5.0)
    path = write_curve(VirginCurve(u=u, T=T, N=N_SPHERE), tmp_path / "bad.json")
    assert main(["loop", "--curve", str(path), "--amplitude", "1e-6"]) == 2
    assert "not concave at point 3" in capsys.readouterr().err


@pytest.mark.slow
def test_damper_fmu_reduces_a_long_curve_like_the_element(tmp_path, capsys):
    """damper fmu: the same reduced curve as IwanElement.from_virgin_curve, error printed."""
    from fmpy import simulate_fmu

    u, T = cattaneo_table(600)
    curve = VirginCurve(u=u[:-1], T=T[:-1], N=N_SPHERE, mu=MU, tail="flat")
    path = write_curve(curve, tmp_path / "long.json")
    out = tmp_path / "long.fmu"
    assert main(["fmu", "--curve", str(path), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    el = IwanElement.from_virgin_curve(curve)
    assert f"{el.fit_error:.3g} N" in err and el.fit_error > 0.0
    t = np.arange(40) * 1e-3
    hist = 1.5 * u[-2] * np.sin(0.3 * np.arange(40))
    res = simulate_fmu(str(out), start_time=0.0, stop_time=t[-1], output_interval=1e-3,
                       input=np.array(list(zip(t, hist)), dtype=[("time", float), ("u", float)]),
                       output=["F"])
    ref = el.series(hist).F
    # fmpy records each output one sample late (it applies the next input after recording)
    np.testing.assert_allclose(res["F"][1:len(ref)], ref[:-1][: len(res["F"]) - 1], rtol=0,
                               atol=1e-12 * MU * N_SPHERE)
