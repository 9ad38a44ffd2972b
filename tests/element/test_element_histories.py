"""Arbitrary histories: C core vs the extended-Masing oracle, sampling and rate independence."""
from __future__ import annotations

import numpy as np
import pytest
from elcases import N_SPHERE, SEED, cattaneo_table, random_reversal_history
from iwan_ref import MasingRef, table_curve

from fmu_src.element import IwanElement

#: Agreement with the oracle and between samplings: round-off of sums over ~50
#: sliders and a few hundred samples, relative to the gross-slip force.
ROUNDOFF = 1e-11


@pytest.fixture(scope="module")
def curve():
    u_tab, T_tab = cattaneo_table(48)
    return u_tab, T_tab, IwanElement.from_curve(u_tab, T_tab, N_ref=N_SPHERE)


@pytest.mark.parametrize("trial", range(4))
def test_random_nested_histories_match_the_masing_oracle(curve, trial):
    u_tab, T_tab, el = curve
    rng = np.random.default_rng(SEED + trial)
    amp = 1.2 * u_tab[-2] if trial % 2 else 0.4 * u_tab[-2]   # with and without gross slip
    u = random_reversal_history(rng, 40, amp, pts_per_leg=int(rng.integers(1, 5)))
    # decaying tail: deeply nested loops
    tail = np.cumsum(rng.uniform(0.3, 1.0, 20) * amp * 0.7 ** np.arange(20) * (-1) ** np.arange(20))
    u = np.concatenate([u, u[-1] + tail])
    F_ref = MasingRef(table_curve(u_tab, T_tab)).series(u)
    F = el.series(u).F
    np.testing.assert_allclose(F, F_ref, rtol=0, atol=ROUNDOFF * T_tab[-1])


def refine(vertices: np.ndarray, counts) -> np.ndarray:
    """Samples on the straight lines between vertices, counts[i] per segment (vertices kept)."""
    out = [vertices[:1]]
    for i, c in enumerate(counts):
        out.append(np.linspace(vertices[i], vertices[i + 1], c + 1)[1:])
    return np.concatenate(out)


def test_results_do_not_depend_on_sampling_of_a_piecewise_linear_history(curve):
    u_tab, _, el = curve
    rng = np.random.default_rng(SEED)
    vu = np.concatenate([[0.0], rng.uniform(-1.5, 1.5, 25) * u_tab[-2]])
    vN = np.concatenate([[N_SPHERE], rng.uniform(0.3, 1.5, 25) * N_SPHERE])
    counts = rng.integers(1, 12, size=vu.size - 1)
    ends = np.cumsum(counts)                    # index of each vertex in the fine history
    coarse = el.series(vu, vN)
    fine = el.series(refine(vu, counts), refine(vN, counts))
    scale = np.abs(coarse.F).max()
    np.testing.assert_allclose(fine.F[ends], coarse.F[1:], rtol=0, atol=ROUNDOFF * scale)
    np.testing.assert_allclose(fine.W[ends], coarse.W[1:], rtol=1e-10, atol=0)


def test_rate_independence_pauses_and_uneven_speed_change_nothing(curve):
    u_tab, _, el = curve
    t = np.linspace(0.0, 3.0, 301)
    slow = 0.9 * u_tab[-2] * np.sin(2 * np.pi * t)
    # same path at another speed profile: every sample repeated 1-3 times (pauses)
    reps = 1 + (np.arange(t.size) * 7) % 3
    paused = np.repeat(slow, reps)
    F_slow = el.series(slow).F
    F_paused = el.series(paused).F
    last = np.cumsum(reps) - 1
    np.testing.assert_array_equal(F_paused[last], F_slow)


def test_periodic_loop_closes_after_one_cycle(curve):
    u_tab, _, el = curve
    n = 96
    th = 2 * np.pi * np.arange(n) / n
    u = u_tab[-2] * (0.7 * np.cos(th) + 0.3 * np.sin(3 * th) + 0.1)
    loop = el.periodic(u)
    assert loop.periods == 1
    # marching from the virgin state: the second period repeats the periodic loop
    marched = el.series(np.tile(u, 3))
    np.testing.assert_allclose(marched.F[n:2 * n], loop.F, rtol=0, atol=ROUNDOFF * np.ptp(loop.F))
    np.testing.assert_allclose(marched.F[2 * n:], loop.F, rtol=0, atol=ROUNDOFF * np.ptp(loop.F))
    W_period = marched.W[2 * n - 1] - marched.W[n - 1]
    assert W_period == pytest.approx(loop.W_cycle, rel=1e-10)


def test_step_series_and_state_copies_agree(curve):
    _, _, el = curve
    rng = np.random.default_rng(SEED + 7)
    u = random_reversal_history(rng, 10, 4e-6)
    N = N_SPHERE * rng.uniform(0.5, 1.5, u.size)
    whole = el.series(u, N)
    half = el.series(u[:20], N[:20])
    rest = el.series(u[20:], N[20:], state=half.state)
    np.testing.assert_array_equal(np.concatenate([half.F, rest.F]), whole.F)
    st = el.initial_state(N[0])
    steps = [el.step(st, ui, Ni) for ui, Ni in zip(u, N)]
    np.testing.assert_allclose([s.F for s in steps], whole.F, rtol=0, atol=1e-12)
    np.testing.assert_allclose([s.W for s in steps], whole.W, rtol=1e-13)
    assert half.state.u == u[19]                              # the copy given back is advanced


def test_tangent_is_the_one_sided_derivative_in_the_direction_of_motion(curve):
    _, _, el = curve
    rng = np.random.default_rng(SEED + 3)
    u = random_reversal_history(rng, 8, 5e-6)
    h = 1e-13                                                 # far below any slider's slip radius
    r = el.series(u)
    for i in range(1, u.size):
        d = np.sign(u[i] - u[i - 1]) or 1.0
        F_h = el.series([u[i] + d * h], state=el.series(u[: i + 1]).state).F[0]
        assert (F_h - r.F[i]) / (d * h) == pytest.approx(r.kt[i], rel=1e-5)


def test_step_and_series_share_one_code_path_bit_for_bit(curve):
    # step() and series() run the same one-pass sweep at constant N and the same
    # straight-path update when N changes, so they agree to the bit; the sweep is
    # checked against the straight-path update in C (test_iwan.c,
    # test_fast_step_equals_straight_path) and against the oracle above
    u_tab, _, el = curve
    rng = np.random.default_rng(SEED + 21)
    u = random_reversal_history(rng, 30, 1.3 * u_tab[-2])
    N = N_SPHERE * np.repeat(rng.uniform(0.5, 1.5, u.size // 10 + 1), 10)[: u.size]
    fast = el.series(u, N)
    st = el.initial_state(N[0])
    steps = [el.step(st, ui, Ni) for ui, Ni in zip(u, N)]
    for name in ("F", "kt", "dFdN", "W"):
        np.testing.assert_array_equal([getattr(s, name) for s in steps], getattr(fast, name))
