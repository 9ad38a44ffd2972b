"""The FMUs under fmpy: valid model descriptions, and the same numbers as the array API.

The FMU and ``fmu_src.element`` run the same C core on the same straight-path
history, so they agree to round-off (in practice bit for bit).
"""
import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu
from fmu_helpers import N_CURVE, SEED, U_SLIP, Slave, curve_table

from fmu_src.element import IwanElement

#: Same C code and arithmetic on both sides: agreement to round-off.
EXACT_TOL = 1e-12


def _history(n: int = 300):
    """A decaying two-tone u (with reversals, minor loops) and a varying N."""
    rng = np.random.default_rng(SEED)
    t = np.linspace(0.0, 1.0, n)
    u = 1.5 * U_SLIP * (np.sin(2 * np.pi * 3 * t) + 0.3 * np.sin(2 * np.pi * 17 * t)) * np.exp(-t)
    N = N_CURVE * (1.0 + 0.3 * np.sin(2 * np.pi * 2 * t)) + rng.normal(0.0, 1.0, n)
    return t, u, N


def _reference(u, N, scale=1.0):
    uc, Tc = curve_table()
    return IwanElement.from_curve(uc, Tc, N_CURVE, scale=scale).series(u, N)


def _assert_close(a, b, scale):
    assert np.max(np.abs(np.asarray(a) - np.asarray(b))) <= EXACT_TOL * scale


@pytest.mark.parametrize("version", [2, 3])
def test_fmpy_validates_the_model_description(fmus, version):
    assert validate_fmu(str(fmus[version])) == []


@pytest.mark.parametrize("version", [2, 3])
def test_direct_drive_equals_array_api(fmus, version):
    t, u, N = _history()
    ref = _reference(u, N, scale=0.8)
    s = Slave(fmus[version], version).initialize(u[0], N[0], scale=0.8)
    F, kt, W, slip = s.run(u, N)
    s.close()
    fscale = np.max(np.abs(ref.F))
    _assert_close(F, ref.F, fscale)
    _assert_close(W, ref.W, ref.W[-1])
    _assert_close(kt, ref.kt, np.max(np.abs(ref.kt)))
    assert np.all((slip >= 0) & (slip <= 1)) and np.any(slip > 0)


@pytest.mark.parametrize("version", [2, 3])
def test_variable_step_sizes_change_nothing(fmus, version):
    """Rate independence: the same samples at random step sizes, the same results."""
    t, u, N = _history(120)
    ref = _reference(u, N)
    steps = np.random.default_rng(SEED + 1).uniform(1e-6, 10.0, u.size)
    s = Slave(fmus[version], version).initialize(u[0], N[0])
    F = [s.step(u[k], N[k], h=steps[k])[0] for k in range(u.size)]
    s.close()
    _assert_close(F, ref.F, np.max(np.abs(ref.F)))


@pytest.mark.parametrize("version", [2, 3])
def test_simulate_fmu_equals_array_api_one_sample_late(fmus, version):
    """fmpy records outputs right after doStep, before the next input: one sample late."""
    t, u, N = _history()
    ref = _reference(u, N)
    signals = np.array(list(zip(t, u, N)), dtype=[("time", float), ("u", float), ("N", float)])
    res = simulate_fmu(str(fmus[version]), input=signals, output_interval=t[1] - t[0],
                       stop_time=t[-1], output=["F", "W"])
    assert len(res) == len(t)
    _assert_close(res["F"][1:], ref.F[:-1], np.max(np.abs(ref.F)))
    _assert_close(res["W"][1:], ref.W[:-1], ref.W[-1])


def test_fmi2_input_derivatives_follow_the_straight_path(fmus):
    """With du/dt, dN/dt set, one doStep of any size lands on the next sample exactly."""
    t, u, N = _history(60)
    ref = _reference(u, N)
    s = Slave(fmus[2], 2).initialize(u[0], N[0])
    F = [s.step(u[0], N[0])[0]]   # inputs held over the first step (h > 0: FMI 3 requires it)
    for k in range(len(u) - 1):
        h = t[k + 1] - t[k]
        s.fmu.setRealInputDerivatives([1, 2], [1, 1], [(u[k + 1] - u[k]) / h, (N[k + 1] - N[k]) / h])
        s.fmu.doStep(s.t, h)
        s.t += h
        F.append(s.get(["F"])[0])  # outputs at the extrapolated inputs (u, N)(t + h)
    s.close()
    _assert_close(F, ref.F, np.max(np.abs(ref.F)))


@pytest.mark.parametrize("version", [2, 3])
def test_master_iterations_do_not_touch_the_history(fmus, version):
    """Set/get at trial inputs any number of times: only doStep commits."""
    t, u, N = _history(80)
    ref = _reference(u, N)
    s = Slave(fmus[version], version).initialize(u[0], N[0])
    F = []
    for k in range(len(u)):
        for trial in (3 * U_SLIP, -2 * U_SLIP, 0.1 * U_SLIP):
            s.set(["u", "N"], [trial, 0.5 * N_CURVE])
            s.get(["F", "W"])
        F.append(s.step(u[k], N[k])[0])
    s.close()
    _assert_close(F, ref.F, np.max(np.abs(ref.F)))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nonfinite_input_is_refused_and_history_kept(fmus, version, bad):
    s = Slave(fmus[version], version).initialize()
    F0 = s.step(0.5 * U_SLIP)[0]
    with pytest.raises(FMICallException):
        s.set(["u"], [bad])
    assert s.get(["u", "F"]) == [0.5 * U_SLIP, F0]
    s.close()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("scale", [0.0, 1.0, 3.5])
def test_extreme_histories_equal_array_api(fmus, version, scale):
    """Lift-off (N <= 0) and re-contact, gross slip far past the curve, tiny and
    zero increments, a zero friction scale: still the array API's numbers."""
    u = np.array([0, 1e-12, 1e-12, 5, -40, 3, 3, 0.2, -0.7, 1.1, 1e-300, 0.4]) * U_SLIP
    N = N_CURVE * np.array([1, 1, 0.5, 2, 1, -0.5, 0.0, 0.3, 1e-9, 1, 1, 4])
    ref = _reference(u, N, scale=scale)
    s = Slave(fmus[version], version).initialize(u[0], N[0], scale=scale)
    F, kt, W, slip = s.run(u, N)
    s.close()
    _assert_close(F, ref.F, max(1.0, np.max(np.abs(ref.F))))
    _assert_close(W, ref.W, max(1e-12, ref.W[-1]))
    assert np.all(np.isfinite(kt)) and np.all((slip >= 0) & (slip <= 1))
