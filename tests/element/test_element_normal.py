"""Normal-load input: scaling, lift-off and re-contact, energy invariants."""
from __future__ import annotations

import numpy as np
import pytest
from elcases import MU, N_SPHERE, SEED, cattaneo_table, random_reversal_history

from fmu_src.element import IwanElement

#: Round-off of sums over ~40 sliders and a few hundred samples (relative to the force scale).
ROUNDOFF = 1e-11


@pytest.fixture(scope="module")
def el():
    return IwanElement.from_curve(*cattaneo_table(40), N_ref=N_SPHERE)


@pytest.mark.parametrize("c", [0.25, 1.0, 3.7])
def test_normal_load_scaling_F_of_cN_is_c_times_F_of_u_over_c(el, c):
    rng = np.random.default_rng(SEED)
    u = random_reversal_history(rng, 30, 8e-6)
    N = N_SPHERE * rng.uniform(0.4, 1.6, u.size)          # varying N, scaled as a whole
    base = el.series(u, N)
    scaled = el.series(c * u, c * N)
    np.testing.assert_allclose(scaled.F, c * base.F, rtol=0, atol=ROUNDOFF * c * MU * N_SPHERE)
    np.testing.assert_allclose(scaled.W, c * c * base.W, rtol=1e-10, atol=1e-30)


def test_lift_off_gives_zero_force_and_recontact_restarts_on_the_virgin_curve(el):
    u_tab, T_tab = cattaneo_table(40)
    g = lambda s: np.sign(s) * np.interp(np.abs(s), u_tab, T_tab)   # noqa: E731
    u_lift = 3e-6
    # load, lift off (N = -5 N) while sliding on, re-contact with no tangential motion, reload
    u = np.array([0.0, 2e-6, 4e-6, u_lift, 1e-5, -2e-6, 1.0e-6, 1.0e-6, 2e-6, 5e-6, -3e-6])
    N = np.array([1, 1, 1, 1, -0.05, -0.05, -0.05, 1, 1, 1, 1]) * N_SPHERE
    r = el.series(u, N)
    assert np.all(r.F[4:7] == 0.0) and np.all(r.kt[4:7] == 0.0)
    # lift-off between samples 3 and 4 at s = 1/1.05: the sliders slid to zero force on the way
    assert r.W[4] > r.W[3]
    u_c = 1.0e-6                                          # re-contact point (N crosses 0 at u = 1e-6)
    np.testing.assert_allclose(r.F[7:10], g(u[7:10] - u_c), rtol=0, atol=ROUNDOFF * MU * N_SPHERE)
    # and the reversal after re-contact follows Masing from the new origin
    np.testing.assert_allclose(r.F[10], r.F[9] + 2.0 * g((u[10] - u[9]) / 2.0), rtol=0,
                               atol=ROUNDOFF * MU * N_SPHERE)
    assert r.state.in_contact and r.state.N == N_SPHERE


def test_recontact_inside_a_step_is_located_on_the_straight_path(el):
    # N goes from -N_ref to +N_ref while u goes 0 -> 2 d: contact starts at u = d, N = 0
    d = 1.5e-6
    one = el.series([0.0, 2 * d], [-N_SPHERE, N_SPHERE])
    two = el.series([0.0, d, 2 * d], [-N_SPHERE, 0.0, N_SPHERE])
    assert one.F[-1] == pytest.approx(two.F[-1], rel=1e-12)
    assert one.W[-1] == pytest.approx(two.W[-1], rel=1e-12)


def test_energy_never_negative_and_dissipation_never_decreases(el):
    rng = np.random.default_rng(SEED + 11)
    u = random_reversal_history(rng, 60, 1.2e-5)
    N = N_SPHERE * rng.uniform(-0.3, 1.5, u.size)         # includes lift-offs
    st = el.initial_state(N[0])
    outs = [el.step(st, ui, Ni) for ui, Ni in zip(u, N)]
    E = np.array([o.E for o in outs])
    W = np.array([o.W for o in outs])
    slip = np.array([o.slip for o in outs])
    assert np.all(E >= 0.0)
    assert np.all(np.diff(W) >= 0.0)
    assert np.all((slip >= 0.0) & (slip <= 1.0))
    np.testing.assert_array_equal(W, el.series(u, N).W)


def test_energy_balance_at_constant_normal_load(el):
    # work of F along a finely sampled path = stored energy + dissipated energy
    t = np.linspace(0.0, 2.5, 20001)
    u = 6e-6 * np.sin(2 * np.pi * t) * (1 + 0.3 * np.cos(5 * t))
    st = el.initial_state()
    outs = [el.step(st, ui) for ui in u[1:]]
    F = np.concatenate([[0.0], [o.F for o in outs]])
    work = np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(u))     # trapezoid, O(h^2)
    assert work == pytest.approx(outs[-1].E + outs[-1].W, rel=1e-5)


def test_dFdN_is_the_derivative_when_N_decreases_at_fixed_u(el):
    rng = np.random.default_rng(SEED + 5)
    u = random_reversal_history(rng, 6, 5e-6)
    N = N_SPHERE * rng.uniform(0.8, 1.2, u.size)
    r = el.series(u, N)
    h = 1e-9 * N_SPHERE
    for i in range(1, u.size):
        st = el.series(u[: i + 1], N[: i + 1]).state
        F_h = el.series([u[i]], [N[i] - h], state=st).F[0]
        assert (r.F[i] - F_h) / h == pytest.approx(r.dFdN[i], rel=1e-5, abs=1e-9)
