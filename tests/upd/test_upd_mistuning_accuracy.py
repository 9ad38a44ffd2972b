"""``damper upd mistuning`` states the truncation error of its reference, the tuned peak."""
import json
import math

import pytest

from damper.cli import main
from harmonic_balance import accuracy as acc

#: A cheap nonlinear study: four blades, H = 3, one sample (about 2 s).
SMALL = ["upd", "mistuning", "--blades", "4", "--engine-order", "1", "--harmonics", "3",
         "--samples", "1", "--serial"]
#: The record recomputed from the JSON's own numbers: the same formula on the same floats.
SAME = 1e-12


def test_mistuning_json_carries_the_tuned_peaks_truncation_estimate(tmp_path, capsys):
    assert main([*SMALL, "--cache-dir", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    rec = out["truncation_error"]
    assert rec["H_used"] == out["harmonics"] == 3 and rec["H_check"] > 3
    # the estimate is of the tuned peak the amplifications divide by
    c = rec["checks"][0]
    again = acc.estimate([(3, out["tuned_peak"], 2 * math.pi * out["tuned_frequency_hz"]),
                          (c["H"], c["peak_amplitude"], c["peak_omega"])], rec["method"])
    assert rec["peak_amplitude_rel"] == pytest.approx(again["peak_amplitude_rel"], rel=SAME)
    assert (out["truncation_warning"] is not None) == (rec["peak_amplitude_rel"] > acc.WARN_REL)


def test_mistuning_linear_limit_has_no_truncation(tmp_path, capsys):
    assert main([*SMALL, "--damper", "free", "--cache-dir", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["truncation_error"] is None and out["truncation_warning"] is None


def test_mistuning_summary_prints_the_estimate(tmp_path, capsys):
    assert main([*SMALL, "--cache-dir", str(tmp_path)]) == 0
    assert "truncation error (estimate, H = 3 checked at H = 5" in capsys.readouterr().out
