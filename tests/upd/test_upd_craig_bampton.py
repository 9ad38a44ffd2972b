"""examples/craig_bampton_blade.py: the Craig-Bampton reduction of the scikit-fem blade
against the full FE model, and the reduced blade run with the default damper."""
import json

import numpy as np
import pytest

from damper.cli import main
from harmonic_balance.bladed_disk.blade import generalized_eigenfrequencies
from harmonic_balance.bladed_disk.solve import TOL_REL

#: Energy imbalance at the peak: the Newton stopping tolerance |R| < solve.TOL_REL max(F0, CF)
#: bounds it (the solver's guarantee); measured <= 2.4e-15 over these tests (revision a12e5f1).
ENERGY_IMBALANCE = TOL_REL

#: CB with 6 fixed-interface modes vs the full FE blade (1016 DOFs), first three modes;
#: measured 2.5e-6, 1.3e-4, 1.4e-3 (Rayleigh-Ritz: the CB frequencies are upper bounds).
CB_RTOL = (4e-6, 2e-4, 2.1e-3)
#: Damped peak / free-blade peak at the example's CF = 120 N, F0 = 10 N, H = 3: measured
#: 0.064 (1.944 mm against 30.56 mm).
DAMPED_BELOW = 0.1


@pytest.fixture(scope="module")
def example():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "craig_bampton_blade.py"
    spec = importlib.util.spec_from_file_location("craig_bampton_blade", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def fe(example):
    return example.fe_blade()


def test_reduction_matches_the_fe_model(example, fe):
    f_fe = example.fe_frequencies(fe, 3)
    errors = []
    for modes in (2, 4, 6):
        blade, T = example.reduce_blade(fe, modes)
        f_cb = generalized_eigenfrequencies(blade.M, blade.K, 3)
        assert np.all(f_cb >= f_fe * (1 - 1e-10))  # upper bounds
        errors.append(f_cb / f_fe - 1)
    assert np.all(errors[-1] <= CB_RTOL)
    # more fixed-interface modes, smaller error (mode by mode)
    assert np.all(np.diff(np.array(errors), axis=0) <= 1e-12)
    # the reduced physical DOFs are the FE DOFs: T is the identity on the boundary
    boundary = [*fe["left"], *fe["right"], fe["tip"][0]]
    assert np.array_equal(T[boundary, :5], np.eye(5))


def test_reduced_blade_runs_with_the_default_damper(example, fe, tmp_path, capsys):
    blade, _ = example.reduce_blade(fe, 6)
    toml = example.write_case(tmp_path, blade, (1.0, 2.0))
    f_free, f_stuck, lo, hi = example.linear_band(toml)
    toml = example.write_case(tmp_path, blade, (lo, hi))
    assert main(["upd", "modes", "--config", str(toml), "--json"]) == 0
    modes = json.loads(capsys.readouterr().out)
    # rigid disk (no K_next): the free blade's frequencies do not depend on the ND
    free = np.array([f[0] for f in modes["free_hz"]])
    assert np.ptp(free) <= 1e-9 * free[0] and free[0] == pytest.approx(f_free, rel=1e-12)
    assert main(["upd", "frf", "--config", str(toml), "--damper", "free", "--json"]) == 0
    a_free = json.loads(capsys.readouterr().out)["peak_amplitude"]
    assert main(["upd", "frf", "--config", str(toml), "--harmonics", "3", "--points", "40",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert abs(out["energy_per_cycle_at_peak"]["imbalance"]) < ENERGY_IMBALANCE
    # the damper lowers the resonance below the free blade's and lies between the limits
    assert 0 < out["peak_amplitude"] < DAMPED_BELOW * a_free
    assert lo < out["peak_frequency_hz"] < f_stuck
