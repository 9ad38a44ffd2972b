"""examples/upd_surface_peak.py runs (smoke) and reports a maximum of what it solved."""
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.slow

SCRIPT = Path(__file__).resolve().parents[2] / "examples" / "upd_surface_peak.py"


def _example():
    spec = importlib.util.spec_from_file_location("upd_surface_peak", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_quick_run_reports_the_largest_solved_amplitude_and_a_ring_march(tmp_path):
    out = tmp_path / "peak.json"
    ex = _example()
    assert ex.main(["--quick", "--cf", "600", "--ti", "--json", str(out)]) == 0
    rec = json.loads(out.read_text())
    case = rec["cases"][0]
    surf = case["surface"][0]
    amps = [a for _, a in surf["points"]]
    # the reported peak is the best point solved (in quick mode the only one)
    assert surf["peak_amplitude_h1"] == pytest.approx(max(amps), rel=1e-12)
    assert case["point_error"] == pytest.approx(
        case["point"]["peak_amplitude_h1"] / surf["peak_amplitude_h1"] - 1, rel=1e-12)
    ring = surf["ring"]["from_hb_state"]
    assert ring["periods"] == 1 and np.isfinite(ring["amplitude_h1"]) and ring["amplitude_h1"] > 0
    assert rec["revision"]
    rows = ex.table([out]).splitlines()
    assert len(rows) == 3 and rows[2].startswith("| 600 | nodes, 1 | 5 |") and "(fixed)" in rows[2]


@pytest.mark.parametrize("extra", [["--model", "condensed", "--dashpots", "bodies"], ["--at", "-5"],
                                   ["--cf-steps", "0"]])
def test_contradictory_options_are_refused_before_any_solve(extra, capsys):
    with pytest.raises(SystemExit) as exc:
        _example().main(["--quick"] + extra)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and ("--dashpots inputs" in err or "--at must be" in err
                                    or "--cf-steps must be" in err)


def test_a_fixed_frequency_is_not_held_against_the_point_peak(tmp_path):
    """--at solves one frequency, not the surface's peak: no point-model error is reported."""
    out = tmp_path / "at.json"
    ex = _example()
    assert ex.main(["--quick", "--cf", "600", "--at", "470", "--json", str(out)]) == 0
    case = json.loads(out.read_text())["cases"][0]
    assert case["surface"][0]["peak_hz"] == 470.0 and not case["surface"][0]["searched"]
    assert "point_error" not in case
    row = ex.table([out]).splitlines()[2]
    assert "470.00 (fixed)" in row and row.split(" | ")[6].endswith(", -")
