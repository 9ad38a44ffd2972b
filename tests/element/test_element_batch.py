"""Batched step (iwan_step_batch): many independent states, one C call per sample.

The batch must be the step itself: each state advanced by ``step_batch`` carries
exactly the bits (state record, force, tangent) that ``step`` gives on its own
copy, on random histories with varying N, lift-off and re-contact.
"""
from __future__ import annotations

import ctypes as ct

import numpy as np
import pytest
from elcases import N_SPHERE, SEED, cattaneo_table

from fmu_src.element import IwanElement
from fmu_src.element_batch import STATE_DTYPE

#: Independent states and samples of the random histories (small: a quick test).
N_STATES, N_SAMPLES = 7, 120


@pytest.fixture(scope="module")
def el():
    return IwanElement.from_curve(*cattaneo_table(12), N_ref=N_SPHERE)


def _histories(rng):
    """Random (u, N) per state and sample, shape (N_SAMPLES, N_STATES): reversals,
    constant-N runs (the fast path), varying N and lift-off (N <= 0) stretches."""
    u = np.cumsum(rng.normal(0.0, 1.5e-6, (N_SAMPLES, N_STATES)), axis=0)
    N = N_SPHERE * rng.uniform(0.3, 1.5, (N_SAMPLES, N_STATES))
    hold = rng.uniform(size=N.shape) < 0.5          # hold N: a run of the constant-N path
    for i in range(1, N_SAMPLES):
        N[i, hold[i]] = N[i - 1, hold[i]]
    N[rng.uniform(size=N.shape) < 0.08] = -0.2 * N_SPHERE   # lift-off samples
    return u, N


def _as_bytes(state) -> bytes:
    return bytes(ct.string_at(ct.addressof(state._raw), STATE_DTYPE.itemsize))


def test_batch_is_bit_identical_to_stepping_each_state(el):
    rng = np.random.default_rng(SEED)
    u, N = _histories(rng)
    assert np.any(N <= 0.0) and np.any(N[1:] == N[:-1])   # both paths are exercised
    states = el.initial_states(N_STATES, N[0])
    singles = [el.initial_state(n0) for n0 in N[0]]
    lifted = 0
    for i in range(1, N_SAMPLES):
        F, kt = el.step_batch(states, u[i], N[i])
        lifted += int(np.sum(states["in_contact"] == 0))
        for j, s in enumerate(singles):
            o = el.step(s, u[i, j], N[i, j])
            assert F[j] == o.F and kt[j] == o.kt, (i, j)
            assert states[j].tobytes() == _as_bytes(s), (i, j)
    assert lifted > 0                                    # lift-off was reached


def test_batch_default_normal_load_and_out_arrays(el):
    rng = np.random.default_rng(SEED + 1)
    u = rng.uniform(-8e-6, 8e-6, (40, 5))
    states = el.initial_states(5)
    out = (np.empty(5), np.empty(5))
    ref = [el.initial_state() for _ in range(5)]
    for row in u:
        F, kt = el.step_batch(states, row, out=out)
        assert F is out[0] and kt is out[1]
        np.testing.assert_array_equal(F, [el.step(s, x).F for s, x in zip(ref, row)])
    np.testing.assert_array_equal(states["w_diss"], [s.W for s in ref])


def test_bad_input_raises_value_error_and_leaves_states_untouched(el):
    states = el.initial_states(4)
    el.step_batch(states, [1e-6, -2e-6, 3e-6, 0.0])
    keep = states.copy()
    bad_u = np.array([1e-6, np.nan, 0.0, 0.0])        # a NaN in the middle
    with pytest.raises(ValueError, match="NaN"):
        el.step_batch(states, bad_u)
    with pytest.raises(ValueError, match="NaN"):
        el.step_batch(states, np.zeros(4), [1.0, 1.0, 1.0, np.inf])
    broken = states.copy()
    broken[3]["version"] = 99                           # a corrupted last state
    with pytest.raises(ValueError, match="bad state"):
        el.step_batch(broken, np.full(4, 5e-6))
    assert broken[:3].tobytes() == keep[:3].tobytes()   # checked before any state moved
    with pytest.raises(ValueError, match="shape"):
        el.step_batch(states, np.zeros(3))
    with pytest.raises(ValueError, match="STATE_DTYPE"):
        el.step_batch(np.zeros(4), np.zeros(4))
    with pytest.raises(ValueError, match="C-contiguous"):
        el.step_batch(el.initial_states(8)[::2], np.zeros(4))
    with pytest.raises(ValueError, match="n must be"):
        el.initial_states(0)
    assert states.tobytes() == keep.tobytes()


def test_batch_stepper_matches_step_batch_and_refuses_nan(el):
    rng = np.random.default_rng(SEED + 2)
    u = rng.uniform(-8e-6, 8e-6, (30, 6))
    N = N_SPHERE * rng.uniform(0.5, 1.5, 6)
    a, b = el.initial_states(6, N), el.initial_states(6, N)
    stepper = el.batch_stepper(b, N)
    for row in u:
        F, kt = el.step_batch(a, row, N)
        assert np.array_equal(stepper.step(row), F) and np.array_equal(stepper.kt, kt)
    assert a.tobytes() == b.tobytes()
    keep = b.copy()
    stepper.u[:] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        stepper.step()
    assert b.tobytes() == keep.tobytes()


def test_eval_is_the_trial_of_step_and_leaves_the_state(el):
    rng = np.random.default_rng(SEED + 3)
    s = el.initial_state()
    for x, n in zip(rng.uniform(-8e-6, 8e-6, 40), N_SPHERE * rng.uniform(-0.2, 1.5, 40)):
        before = _as_bytes(s)
        o = el.eval(s, x, n)
        assert _as_bytes(s) == before
        assert o == el.step(s, x, n)
    with pytest.raises(ValueError, match="NaN"):
        el.eval(s, np.nan)
