"""damper upd: JSON keys of the documented interface, linear limits, optimal-load curve."""
import json

import numpy as np
import pytest

from damper.cli import main
from harmonic_balance.bladed_disk.solve import TOL_REL

#: Linear peak frequency against the natural frequency: the displacement peak lies ~zeta^2
#: = 4e-6 below it (0.2 % damping); measured 5.0e-6 (revision a12e5f1); as
#: test_upd_linear.PEAK_RTOL.
PEAK_RTOL = 2e-5

#: Energy imbalance at the peak: the Newton stopping tolerance |R| < solve.TOL_REL max(F0, CF)
#: bounds it (the solver's guarantee); measured <= 2.4e-15 over these tests (revision a12e5f1).
ENERGY_IMBALANCE = TOL_REL


def _run(argv, capsys):
    assert main(["upd", *argv]) == 0
    return json.loads(capsys.readouterr().out)


def test_frf_json_keys(capsys, tmp_path):
    out = _run(["frf", "--harmonics", "3", "--points", "30", "--band", "420", "470", "--json",
                "--plot", str(tmp_path)], capsys)
    for k in ("frequency_hz", "amplitude", "amplitude_max", "peak_frequency_hz", "peak_amplitude",
              "normal_load_mean", "normal_load_range", "lift_off", "time_s"):
        assert k in out
    assert len(out["frequency_hz"]) == len(out["amplitude"]) == 30
    assert len(out["normal_load_mean"]) == len(out["lift_off"]) == 3
    # the refined peak is not below the grid's largest value
    assert out["peak_amplitude"] >= max(out["amplitude"])
    assert abs(out["energy_per_cycle_at_peak"]["imbalance"]) < ENERGY_IMBALANCE
    assert (tmp_path / "upd_frf.png").exists()


def test_frf_linear_limits_and_modes(capsys):
    modes = _run(["modes", "--json"], capsys)
    for damper in ("free", "stuck"):
        out = _run(["frf", "--damper", damper, "--json"], capsys)
        f_n = modes[f"{damper}_hz"][6][0]  # ND = EO = 6
        assert out["peak_frequency_hz"] == pytest.approx(f_n, rel=PEAK_RTOL)


@pytest.mark.slow
def test_optimize_interior_minimum(capsys):
    """H = 3 on a coarse grid (fast); the default run is H = 7 (docs: performance)."""
    out = _run(["optimize", "--cf-range", "30", "3000", "--points", "5", "--harmonics", "3",
                "--grid", "12", "--json"], capsys)
    amp = np.array(out["peak_amplitude"])
    assert out["interior"] and amp.argmin() not in (0, len(amp) - 1)
    assert out["optimum_peak_amplitude"] <= amp.min() * (1 + 1e-6)
    assert out["cf"][0] < out["optimum_cf"] < out["cf"][-1]


def test_a_maximum_at_the_band_end_is_not_called_a_peak(capsys):
    """Far below resonance the largest amplitude is the band's upper end: the result says so
    (a warning on stderr with --json, its key in the JSON), and a band around the resonance
    does not (linear limit: the same curve checks, faster)."""
    off = _run(["frf", "--damper", "free", "--band", "10", "20", "--points", "5", "--json"], capsys)
    assert off["peak_frequency_hz"] == pytest.approx(20.0) and "band's end 20 Hz" in off["band_end_warning"]
    on = _run(["frf", "--damper", "free", "--points", "41", "--json"], capsys)
    assert on["band_end_warning"] is None
    assert on["frequency_hz"][0] < on["peak_frequency_hz"] < on["frequency_hz"][-1]
    # three points: the grid's largest value is its first, the refined peak (426 Hz) inside
    coarse = _run(["frf", "--damper", "free", "--band", "420", "520", "--points", "3", "--json"], capsys)
    assert int(np.argmax(coarse["amplitude"])) == 0 and coarse["band_end_warning"] is None


def test_a_damper_open_over_most_of_the_period_is_said_to_rattle(capsys):
    """CF 0.1 N against F0 30 N: every contact open over ~98 % of the period at the peak (its
    load in short impacts): a warning names F0 and CF; at the default CF 120 N (contacts closed
    throughout) none."""
    light = _run(["frf", "--cf", "0.1", "--harmonics", "3", "--points", "11", "--json"], capsys)
    assert min(light["lift_off"]) > 0.9 and "rattles" in light["lift_off_warning"]
    assert "F0 30 N against CF 0.1 N" in light["lift_off_warning"]
    loaded = _run(["frf", "--harmonics", "3", "--points", "11", "--json"], capsys)
    assert max(loaded["lift_off"]) < 0.9 and loaded["lift_off_warning"] is None


def test_the_rattle_warning_of_surfaces_names_no_time_integration():
    """--check-steady-state integrates point contacts only: a surface result's warning does
    not send the user there; the rule (every contact open over more than 90 %) is the same."""
    from damper.upd_checks import RATTLE_LIFT_OFF
    from damper.upd_frf import response_warnings

    out = {"frequency_hz": [400.0, 450.0, 500.0], "peak_frequency_hz": 450.0, "f0": 300.0, "cf": 20.0,
           "harmonics": 3, "lift_off": [0.95, 0.97]}
    points = response_warnings(out)["lift_off_warning"]
    surfaces = response_warnings(out | {"contact_surfaces": {}})["lift_off_warning"]
    assert "--check-steady-state" in points and "--check-steady-state" not in surfaces
    assert response_warnings(out | {"lift_off": [0.95, RATTLE_LIFT_OFF]})["lift_off_warning"] is None


def test_a_result_s_warnings_go_once_to_stderr_with_json_and_to_stdout_without(capsys):
    from damper.cli.common import print_warnings

    out = {"band_end_warning": None, "lift_off_warning": "warning: rattles", "truncation_warning": "warning: H"}
    print_warnings(out, ("band_end_warning", "lift_off_warning", "missing"), True)
    c = capsys.readouterr()
    assert (c.out, c.err) == ("", "warning: rattles\n")
    print_warnings(out, ("lift_off_warning", "truncation_warning"), False)
    c = capsys.readouterr()
    assert (c.out, c.err) == ("warning: rattles\nwarning: H\n", "")
