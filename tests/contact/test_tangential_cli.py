"""``damper tangential``: JSON output, curve file, plots and exit codes (BEM model, small grids)."""
import json

import numpy as np
import pytest

from contact_core.curve import read_curve
from damper.cli import main

SPHERE = ["tangential", "--body", "sphere", "--radius", "0.01", "--mu", "0.5", "--grid", "13",
          "--model", "bem"]
CYLINDER = ["tangential", "--body", "cylinder", "--diameter", "5e-3", "--length", "1.2e-3",
            "--mu", "0.5", "--grid", "13", "--model", "bem"]


def run_json(capsys, argv):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_has_the_interface_keys(capsys):
    out = run_json(capsys, SPHERE + ["--force", "200"])
    for key in ("u", "T", "k_t", "normal_force", "mu", "stick_fraction", "iterations"):
        assert key in out
    assert len(out["u"]) == len(out["T"]) == len(out["stick_fraction"])
    assert out["normal_force"] == pytest.approx(200.0)
    assert out["T"][-1] == pytest.approx(0.5 * 200.0, rel=1e-9)  # ends at gross slip
    assert out["stick_fraction"][0] == 1.0 and out["stick_fraction"][-1] == 0.0
    assert out["load_case"] == "CNF" and out["k_t"] > 0
    # the total is the points' sum; none at u = 0, then 1 to 3 warm-started active-set
    # iterations a point (contact_core.qp; measured 1-2)
    per_point = out["iterations_per_point"]
    assert out["iterations"] == sum(per_point) and per_point[0] == 0
    assert all(1 <= it <= 3 for it in per_point[1:]), per_point


@pytest.mark.slow
def test_out_writes_a_curve_file_and_plots(tmp_path, capsys):
    curve_path, plots = tmp_path / "curve.json", tmp_path / "plots"
    assert main(CYLINDER + ["--force", "120", "--out", str(curve_path), "--plot", str(plots)]) == 0
    curve = read_curve(curve_path)
    assert curve.load_case == "CNF" and curve.mu == 0.5 and curve.N == pytest.approx(120.0)
    assert curve.geometry["body"] == "cylinder" and curve.geometry["radius"] == 2.5e-3
    assert curve.provenance["command"].startswith("damper ")
    assert sorted(p.name for p in plots.iterdir()) == ["stick_slip_maps.png", "traction.png",
                                                       "virgin_curve.png"]


def test_constant_normal_displacement(capsys):
    out = run_json(capsys, CYLINDER + ["--approach", "5e-6"])
    assert out["load_case"] == "CND" and out["approach"] == pytest.approx(5e-6)
    assert out["T"][-1] == pytest.approx(0.5 * out["normal_force"], rel=1e-9)


@pytest.mark.slow
def test_force_control_and_loop(capsys, tmp_path):
    out = run_json(capsys, SPHERE + ["--force", "200", "--tangential-force", "50",
                                     "--loop-amplitude", "1e-6", "--plot", str(tmp_path)])
    assert (tmp_path / "loop.png").exists()
    assert out["force_control"]["T"] == pytest.approx(50.0, rel=1e-9)
    assert 0 < out["force_control"]["stick_fraction"] < 1
    loop = out["loop"]
    assert loop["W_direct"] == pytest.approx(loop["W_masing"], rel=0.02)
    assert np.max(loop["u"]) == pytest.approx(1e-6)


@pytest.mark.parametrize("extra", [
    ["--force", "200", "--mu", "-0.5"],            # negative friction coefficient
    ["--force", "nan"],                            # non-finite input
    ["--force", "200", "--mu", "inf"],
    ["--force", "200", "--tangential-force", "101"],  # above mu N = 100 N
    ["--force", "200", "--loop-amplitude", "nan"],
    ["--force=-5"],
    ["--approach=-1e-6"],
])
def test_bad_input_exits_with_code_2(extra, capsys, tmp_path):
    out = tmp_path / "curve.json"
    assert main(SPHERE + extra + ["--out", str(out)]) == 2
    assert "error" in capsys.readouterr().err
    assert not out.exists()  # nothing half-written


def test_cylinder_without_length_is_refused(capsys):
    argv = ["tangential", "--body", "cylinder", "--radius", "2.5e-3", "--force", "10", "--mu", "0.5"]
    assert main(argv) == 2
    assert "--length" in capsys.readouterr().err


def test_bem_refuses_the_flat_face(capsys):
    argv = ["tangential", "--body", "flat", "--width", "1.2e-3", "--length", "5e-3", "--force", "500",
            "--mu", "0.5", "--model", "bem"]
    assert main(argv) == 2
    assert "sphere and cylinder" in capsys.readouterr().err


def test_eccentricity_needs_a_flat_face(capsys):
    assert main(SPHERE + ["--force", "200", "--eccentricity", "1e-5"]) == 2
    assert "flat face" in capsys.readouterr().err


def test_a_contact_on_one_node_is_refused(capsys):
    # 1 mN on a zone sized for 2000 MPa: the contact falls inside one grid cell
    # (explicit --p-design: by default such a load now gets a zone of its own)
    assert main(SPHERE + ["--force", "1e-3", "--p-design", "2e9"]) == 2
    assert "too few" in capsys.readouterr().err


def test_a_coarse_contact_is_flagged(capsys):
    argv = [a if a != "13" else "5" for a in SPHERE]
    out = run_json(capsys, argv + ["--force", "200"])
    assert out["warnings"] and "grid nodes across" in out["warnings"][0]
