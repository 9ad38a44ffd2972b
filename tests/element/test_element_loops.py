"""Loop energies of the Iwan element against closed forms (references.md)."""
from __future__ import annotations

import numpy as np
import pytest
from elcases import MU, N_SPHERE, cattaneo_table, mindlin_deresiewicz_energy, tanh_table
from refcheck import check

from fmu_src.element import IwanElement

#: Round-off of sums over a few hundred samples and sliders (relative).
ROUNDOFF = 1e-12
#: Samples per period: the loop energy of a piecewise-linear table is exact at any
#: sampling that hits the extremes, so this only sets the cost.
N_SAMPLES = 64


def cosine(a: float, n: int = N_SAMPLES) -> np.ndarray:
    return a * np.cos(2.0 * np.pi * np.arange(n) / n)


@pytest.mark.parametrize("a_over_slip", [0.5, 1.0, 1.0001, 1.7, 10.0, 1e4])
def test_jenkins_loop_energy_is_4fs_times_slip(a_over_slip):
    k, fs = 3.0e7, 12.5
    a = a_over_slip * fs / k
    loop = IwanElement.jenkins(k, fs).periodic(cosine(a))
    expected = 4.0 * fs * max(a - fs / k, 0.0)
    check(f"Jenkins loop energy per cycle [J], a = {a_over_slip:g} fs/k", loop.W_cycle, expected, rtol=ROUNDOFF,
          atol=ROUNDOFF * fs * a, source="W = 4 fs (a - fs/k)")
    assert loop.periods == 1


def masing_energy_table(u_tab, T_tab, a):
    """W(a) = 8 int_0^a g - 4 a g(a) for the piecewise-linear table (exact integral)."""
    grid = np.union1d(u_tab[u_tab < a], [a])
    g = np.interp(grid, u_tab, T_tab)
    return 8.0 * np.trapezoid(g, grid) - 4.0 * a * g[-1]


#: Loop energy of a table against the Masing integral: both exact, round-off of the
#: sums over 40 segments. Measured 9.5e-16 (revision a12e5f1); 100x for other compilers
#: and platforms.
TABLE_ENERGY_RTOL = 1e-13


def test_masing_energy_of_a_table_is_exact():
    u_tab, T_tab = tanh_table(40)
    el = IwanElement.from_curve(u_tab, T_tab, N_ref=1.0)
    for a in (1e-7, 1.3e-6, 4.44e-6, 9.9e-6):
        W = el.periodic(cosine(a)).W_cycle
        check(f"loop energy [J] of a 40-point table, a = {a:g} m", W, masing_energy_table(u_tab, T_tab, a),
              rtol=TABLE_ENERGY_RTOL, source="Masing: 8 int_0^a g - 4 a g(a)")


def test_masing_energy_of_a_smooth_curve_converges_with_table():
    F0, u0, a = 40.0, 2e-6, 5e-6
    exact = 8.0 * F0 * u0 * np.log(np.cosh(a / u0)) - 4.0 * a * F0 * np.tanh(a / u0)
    errors = []
    for m in (10, 40, 160):
        el = IwanElement.from_curve(*tanh_table(m, F0, u0), N_ref=1.0)
        errors.append(abs(el.periodic(cosine(a)).W_cycle / exact - 1.0))
    # chord (piecewise-linear) interpolation: error O(h^2), a factor ~16 per 4x refinement
    assert errors[1] < errors[0] / 8.0 and errors[2] < errors[1] / 8.0
    assert errors[2] < 1e-3


@pytest.mark.parametrize("x", [0.2, 0.6, 0.95])
def test_mindlin_deresiewicz_energy_error_falls_with_refinement(x):
    T_amp = x * MU * N_SPHERE
    errors = []
    for m in (16, 64, 256):
        u_tab, T_tab = cattaneo_table(m)
        el = IwanElement.from_curve(u_tab, T_tab, N_ref=N_SPHERE)
        a = np.interp(T_amp, T_tab, u_tab)          # this table's displacement amplitude
        loop = el.periodic(cosine(a, 128))
        assert loop.F.max() == pytest.approx(T_amp, rel=ROUNDOFF)
        errors.append(abs(loop.W_cycle / mindlin_deresiewicz_energy(T_amp) - 1.0))
    assert errors[1] < errors[0] / 3.0 and errors[2] < errors[1] / 3.0
    check(f"loop energy of a 256-point Mindlin table / Mindlin-Deresiewicz - 1, T* = {x:g} mu N", errors[2], 0.0,
          atol=5e-3, source="Mindlin-Deresiewicz 1953")


def test_branches_after_reversals_are_twice_the_virgin_curve_at_half_distance():
    u_tab, T_tab = cattaneo_table(50)
    el = IwanElement.from_curve(u_tab, T_tab, N_ref=N_SPHERE)
    g = lambda s: np.sign(s) * np.interp(np.abs(s), u_tab, T_tab)   # noqa: E731
    us = u_tab[-2]
    legs = [0.0, 0.8 * us, -0.3 * us, 0.5 * us, 0.1 * us]        # nested reversals
    u = np.concatenate([np.linspace(legs[i], legs[i + 1], 41)[1:] for i in range(4)])
    F = el.series(np.concatenate([[0.0], u])).F[1:]
    F_r = 0.0
    for i in range(4):
        seg = slice(40 * i, 40 * (i + 1))
        u_r = legs[i]
        expected = g(u[seg]) if i == 0 else F_r + 2.0 * g((u[seg] - u_r) / 2.0)
        np.testing.assert_allclose(F[seg], expected, rtol=0, atol=ROUNDOFF * MU * N_SPHERE * 10)
        F_r = F[seg][-1]


def test_concave_fit_is_an_upper_hull_and_keeps_a_concave_table():
    u_tab, T_tab = cattaneo_table(30)
    exact = IwanElement.from_curve(u_tab, T_tab, N_ref=N_SPHERE)
    np.testing.assert_allclose(exact.virgin(u_tab), T_tab, rtol=1e-12, atol=1e-12)
    bumpy = T_tab.copy()
    bumpy[5] -= 0.3                                     # dent: not concave any more
    bumpy[-1] -= 1e-3                                   # noisy plateau: T decreases at the end
    with pytest.raises(ValueError):
        IwanElement.from_curve(u_tab, bumpy, N_ref=N_SPHERE)
    fit = IwanElement.from_curve(u_tab, bumpy, N_ref=N_SPHERE, fit="concave")
    Fv = fit.virgin(u_tab)
    assert np.all(Fv >= bumpy - 1e-12)                  # a majorant ...
    keep = np.ones(u_tab.size, bool)
    keep[[5, u_tab.size - 1]] = False
    np.testing.assert_allclose(Fv[keep], bumpy[keep], rtol=1e-12)   # ... touching the rest
    assert fit.k_res == 0.0                             # flat after the maximum
