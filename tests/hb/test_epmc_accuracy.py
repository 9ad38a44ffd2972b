"""Truncation error of a backbone (EPMC): points re-solved with more harmonics."""
import json

import numpy as np
import pytest
from failure_output import no_result
from scipy.interpolate import CubicSpline

from damper.cli import main
from harmonic_balance.epmc import compute_backbone
from harmonic_balance.epmc_accuracy import backbone_to_accuracy, truncation_error
from harmonic_balance.model import sdof_model

#: The goal for an error estimate: within a factor 3 of the true error (measured 0.5-2.2
#: on this oscillator at H = 3, 5, 7 for omega and the damping ratio).
ESTIMATE_FACTOR = 3.0
#: Reference: odd harmonics to 41, whose own error (~1e-7 in omega, ~5e-6 in D, from the
#: estimate's H^-1.7 decay) is below a tenth of the errors tested at H <= 7 (>= 8e-5 in D,
#: >= 1.2e-5 in omega); its backbone on fine steps, interpolated in log a by a cubic spline.
REFERENCE = "odd:41"
SDOF = sdof_model(1.0, 1.0, 0.0, 1.0, 0.05, 0.1)
CLI = ["backbone", "--model", "sdof", "--slip-force", "0.05", "--amplitude", "1e-3", "10"]


@pytest.fixture(scope="module")
def reference():
    ref = compute_backbone(SDOF, REFERENCE, (1e-3, 10), ds_max=0.02)
    z = np.log10(ref.a)
    return CubicSpline(z, ref.omega), CubicSpline(z, ref.damping_ratio)


@pytest.mark.parametrize("harmonics", ["odd:3", "odd:5", "odd:7"])
def test_backbone_estimate_is_within_a_factor_3_of_the_true_error(reference, harmonics):
    bb = compute_backbone(SDOF, harmonics, (1e-3, 10))
    rec = truncation_error(SDOF, harmonics, bb)
    assert rec["H_check"] > rec["H_used"] and len(rec["points"]) == 3
    for key, name, spline in (("omega_rel", "omega", reference[0]),
                              ("damping_ratio_rel", "damping_ratio", reference[1])):
        true = max(abs(p[name] / spline(np.log10(p["modal_amplitude"])) - 1) for p in rec["points"])
        assert true / ESTIMATE_FACTOR <= rec[key] <= true * ESTIMATE_FACTOR


def test_backbone_json_carries_the_estimate_and_warns_above_one_percent(capsys):
    # a stiff link at H = 1: the describing function misses the damping by far more than 1 %
    assert main([*CLI, "--contact-stiffness", "100", "--harmonics", "1", "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    rec = out["truncation_error"]
    assert rec["H_used"] == 1 and rec["H_check"] == 3 and "EPMC" in rec["method"]
    assert rec["damping_ratio_rel"] > 0.01
    assert out["truncation_warning"] and "warning: estimated truncation error" in cap.err


def test_backbone_summary_prints_the_estimate(capsys):
    assert main([*CLI, "--contact-stiffness", "1", "--harmonics", "odd:7"]) == 0
    text = capsys.readouterr().out
    assert "truncation error (estimate, H = 7 checked at H = 11" in text and "warning" not in text


@pytest.mark.parametrize("target", [1e-3, 1e-4])
def test_backbone_accuracy_raises_h_until_the_true_error_is_below_the_target(reference, target):
    bb, rec = backbone_to_accuracy(SDOF, "1", (1e-3, 10), target)
    a = rec["accuracy"]
    assert a["met"] and a["message"] is None and a["H_sequence"][-1] == rec["H_used"]
    assert max(rec["omega_rel"], rec["damping_ratio_rel"]) <= target
    for name, spline in (("omega", reference[0]), ("damping_ratio", reference[1])):
        true = max(abs(p[name] / spline(np.log10(p["modal_amplitude"])) - 1) for p in rec["points"])
        assert true <= target


@pytest.mark.parametrize("tol", ["0.5", "1e-7", "nan"])
def test_backbone_refuses_an_accuracy_outside_its_range(capsys, tol):
    assert main([*CLI, "--contact-stiffness", "1", "--accuracy", tol]) == 2
    cap = capsys.readouterr()
    assert "--accuracy" in cap.err and no_result(cap.out, cap.err, 2)
