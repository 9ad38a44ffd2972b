"""The forced response reports its progress without changing its answer."""
import numpy as np
from hbcases import sdof

from harmonic_balance.frf import compute_frf

# The single-DOF Jenkins case of test_hb_frf (m = k = 1, c = 0.01, k_t = 1, slip 0.05, P = 0.05).
MODEL = dict(m=1.0, k=1.0, c=0.01, kt=1.0, fs=0.05, P=0.05)


def _model():
    p = MODEL
    return sdof(p["m"], p["k"], p["c"], p["kt"], p["fs"], p["P"])


def test_frf_progress_rises_to_the_end_of_the_range_and_leaves_the_curve_unchanged():
    calls = []
    with_progress = compute_frf(_model(), 3, (0.9, 1.3), progress=lambda d, t, label: calls.append((d, t, label)))
    plain = compute_frf(_model(), 3, (0.9, 1.3))
    done = [d for d, _, _ in calls]
    assert len(calls) >= with_progress.points - 2          # one call per continuation point
    assert all(t == 100 and label == "continuation" for _, t, label in calls)
    assert done == sorted(done) and 0 <= done[0] and done[-1] == 100
    assert np.array_equal(with_progress.omega, plain.omega)  # a display hook, no effect on the solve
    assert np.array_equal(with_progress.amplitude, plain.amplitude)
