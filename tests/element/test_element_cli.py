"""``damper loop``: JSON output, force-amplitude mode, exit codes."""
from __future__ import annotations

import json

import numpy as np
import pytest
from elcases import MU, N_SPHERE, cattaneo_table, mindlin_deresiewicz_energy
from failure_output import no_result

from damper.cli import main

#: Cattaneo-Mindlin table of 128 segments: Mindlin-Deresiewicz energy to ~1e-3 (see
#: test_mindlin_deresiewicz_energy_error_falls_with_refinement).
MD_RTOL = 5e-3


def write_curve(path, u, T, **extra):
    path.write_text(json.dumps({"u": list(map(float, u)), "T": list(map(float, T)), **extra}))
    return str(path)


@pytest.fixture()
def sphere_curve(tmp_path):
    u, T = cattaneo_table(128)
    # the file ends at gross slip (T = mu N) without the flat tail: mu and N say so
    return write_curve(tmp_path / "curve.json", u[:-1], T[:-1], N=N_SPHERE, mu=MU)


def run_json(capsys, *argv):
    assert main(["loop", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_loop_json_force_amplitude_mode_gives_mindlin_deresiewicz(capsys, sphere_curve, tmp_path):
    T_amp = 0.6 * MU * N_SPHERE
    out = run_json(capsys, "--curve", sphere_curve, "--force-amplitude", str(T_amp),
                   "--samples", "128", "--plot", str(tmp_path / "plots"))
    assert out["force_amplitude"] == pytest.approx(T_amp, rel=1e-12)
    assert out["energy_per_cycle"] == pytest.approx(mindlin_deresiewicz_energy(T_amp), rel=MD_RTOL)
    u, F = np.array(out["u"]), np.array(out["F"])
    assert u.shape == F.shape == (128,)
    assert out["displacement_amplitude"] == pytest.approx(u.max())
    assert out["gross_slip_tail"] and out["gross_slip_force"] == pytest.approx(MU * N_SPHERE)
    assert (tmp_path / "plots" / "loop.png").stat().st_size > 1000


def test_loop_amplitude_mode_matches_the_force_mode(capsys, sphere_curve):
    a = run_json(capsys, "--curve", sphere_curve, "--force-amplitude", "20")["displacement_amplitude"]
    out = run_json(capsys, "--curve", sphere_curve, "--amplitude", repr(a))
    assert out["force_amplitude"] == pytest.approx(20.0, rel=1e-10)


def test_curve_with_only_u_and_T_works(capsys, tmp_path):
    path = write_curve(tmp_path / "c.json", [0, 1e-6, 3e-6], [0, 10, 15])
    out = run_json(capsys, "--curve", path, "--amplitude", "2e-6", "--samples", "8")
    # slopes 1e7 then 2.5e6: Jenkins (k = 7.5e6, fs = 7.5) + spring: W = 4 fs (a - fs/k)
    assert out["energy_per_cycle"] == pytest.approx(4 * 7.5 * (2e-6 - 1e-6), rel=1e-12)
    assert out["N_ref"] == 1.0 and out["gross_slip_force"] is None


@pytest.mark.parametrize("content", [
    '{"u": [0, 1e-6, 2e-6], "T": [0, 1, 5]}',           # not concave
    '{"u": [0, 1e-6], "T": [0]}',                         # lengths differ
    '{"u": [0, 1e-6, 2e-6], "T": [0, 1',                  # truncated JSON
])
def test_bad_curve_exits_with_code_2(tmp_path, capsys, content):
    path = tmp_path / "bad.json"
    path.write_text(content)
    assert main(["loop", "--curve", str(path), "--amplitude", "1e-6", "--json"]) == 2
    cap = capsys.readouterr()
    assert no_result(cap.out, cap.err, 2)


def test_force_above_gross_slip_and_bad_numbers_exit_with_code_2(sphere_curve, capsys):
    assert main(["loop", "--curve", sphere_curve, "--force-amplitude", "51"]) == 2
    assert "gross-slip" in capsys.readouterr().err
    assert main(["loop", "--curve", sphere_curve, "--amplitude=-1e-6"]) == 2
    assert main(["loop", "--curve", sphere_curve, "--amplitude", "1e-6", "--samples", "2"]) == 2
    assert main(["loop", "--curve", sphere_curve, "--amplitude", "nan"]) == 2


def test_flat_tail_appends_one_flat_segment():
    """flat_tail: the table the element (and the FMU's curve.txt) uses for tail="flat"."""
    from fmu_src.element import flat_tail

    u2, T2 = flat_tail([0.0, 1e-6, 2e-6], [0.0, 30.0, 50.0])
    np.testing.assert_array_equal(u2, [0.0, 1e-6, 2e-6, 4e-6])
    np.testing.assert_array_equal(T2, [0.0, 30.0, 50.0, 50.0])
