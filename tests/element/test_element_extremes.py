"""Extreme and degenerate inputs tried on purpose: tiny/huge scales, one sample, no friction."""
from __future__ import annotations

import numpy as np
import pytest
from elcases import N_SPHERE, cattaneo_table

from fmu_src.element import IwanElement

U_TAB, T_TAB = cattaneo_table(20)


@pytest.fixture(scope="module")
def el():
    return IwanElement.from_curve(U_TAB, T_TAB, N_ref=N_SPHERE)


@pytest.mark.parametrize("length_scale", [1e-15, 1.0, 1e6])
def test_loop_energy_scales_with_units(length_scale):
    # the same curve in other length units: W scales like u, F is unchanged
    base = IwanElement.from_curve(U_TAB, T_TAB, N_ref=N_SPHERE)
    scaled = IwanElement.from_curve(U_TAB * length_scale, T_TAB, N_ref=N_SPHERE)
    th = 2 * np.pi * np.arange(50) / 50
    a = 0.7 * U_TAB[-2]
    W0 = base.periodic(a * np.cos(th)).W_cycle
    W1 = scaled.periodic(length_scale * a * np.cos(th)).W_cycle
    assert W1 == pytest.approx(length_scale * W0, rel=1e-12)


def test_single_sample_and_constant_input_periodic(el):
    one = el.periodic([3e-7])
    assert one.W_cycle == 0.0 and one.periods == 1
    # never slipping: virgin at u = 0, so a constant 3e-7 gives the virgin force
    assert one.F[0] == pytest.approx(el.virgin([3e-7])[0], rel=1e-12)
    F, J, _, W = el.periodic_jac([3e-7], np.ones((1, 1)))
    assert F[0] == pytest.approx(one.F[0]) and W == 0.0 and J[0, 0] == pytest.approx(one.kt[0])


def test_symmetric_input_gives_the_masing_loop_with_tips_on_the_virgin_curve(el):
    a = 0.3 * U_TAB[-2]
    loop = el.periodic(a * np.cos(2 * np.pi * np.arange(64) / 64))
    g_a = el.virgin([a])[0]
    assert loop.F.max() == pytest.approx(g_a, rel=1e-12)
    assert loop.F.min() == pytest.approx(-g_a, rel=1e-12)


def test_zero_friction_scale_leaves_the_residual_spring_only():
    el = IwanElement.from_curve(U_TAB[:-1], T_TAB[:-1], N_ref=N_SPHERE, scale=0.0)
    u = np.array([0.0, 1e-6, -2e-6, 5e-7])
    r = el.series(u)
    np.testing.assert_allclose(r.F, el.k_res * u, rtol=1e-14)
    assert np.all(r.W == 0.0) and np.all(r.kt == el.k_res)
    st = el.initial_state()
    assert el.step(st, 1e-6).slip == 1.0


def test_all_lifted_periodic_loop_is_zero(el):
    u = 1e-6 * np.sin(2 * np.pi * np.arange(16) / 16)
    loop = el.periodic(u, N=np.full(16, -1.0))
    assert np.all(loop.F == 0.0) and loop.W_cycle == 0.0
    F, J, JN, W = el.periodic_jac(u, np.ones((16, 1)), N=0.0, EN=np.ones((16, 1)))
    assert np.all(F == 0.0) and np.all(J == 0.0) and np.all(JN == 0.0)


def test_gross_slip_amplitudes_far_beyond_the_curve(el):
    a = 1e3 * U_TAB[-2]                     # 1000 times the slip displacement
    loop = el.periodic(a * np.cos(2 * np.pi * np.arange(32) / 32))
    assert np.abs(loop.F).max() == pytest.approx(T_TAB[-1], rel=1e-12)
    # every slider slips: W = sum_j 4 fs_j (a - r_j)
    W = np.sum(4 * el.fs * (a - el.slip_radii()))
    assert loop.W_cycle == pytest.approx(W, rel=1e-12)


def test_long_collinear_and_concave_tables(el):
    u = np.linspace(0, 1e-5, 100_001)
    lin = IwanElement.from_curve(u, 3e6 * u, N_ref=1.0)
    assert lin.n_sliders == 0 and lin.k_res == pytest.approx(3e6)
    np.testing.assert_allclose(lin.series([0, 1e-6, -1e-6]).F, [0, 3.0, -3.0], rtol=1e-12)
    m = 256
    uu = np.linspace(0, 1, m + 1)
    most = IwanElement.from_curve(uu, 1 - (1 - uu) ** 2, N_ref=1.0)
    assert most.n_sliders == m - 1 and most.k_res == pytest.approx(1.0 / m, rel=1e-9)   # chord of the last segment
