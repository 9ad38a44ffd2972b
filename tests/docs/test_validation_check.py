"""docs/tools/validation_check.py: a run's reference checks against the recorded table."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[2] / "docs" / "tools" / "validation_check.py"
TEST = "tests/x/test_x.py::test_peak"


def record(quantity, error, reference=1.0, bound=1e-3, **extra):
    """A record as refcheck.check writes it (value = reference + error)."""
    return {"test": TEST, "quantity": quantity, "source": "closed form", "kind": "independent",
            "value": reference + error, "reference": reference, "tolerance": f"rel {bound:g}",
            "error": error, "bound": bound, "growth": 10.0, "elements": 1, "passed": True, **extra}


def run_check(tmp_path, run_records, table_records):
    run, table = tmp_path / "run.json", tmp_path / "table.json"
    run.write_text(json.dumps({"records": run_records, "passed_tests": [TEST]}))
    table.write_text(json.dumps({"records": table_records}))
    p = subprocess.run([sys.executable, str(TOOL), str(run), str(table)], capture_output=True, text=True)
    return p.returncode, p.stderr


def test_the_same_errors_pass(tmp_path):
    code, err = run_check(tmp_path, [record("peak [m]", 2e-6)], [record("peak [m]", 2e-6)])
    assert code == 0, err


@pytest.mark.parametrize("factor, code", [(9.0, 0), (11.0, 1)])
def test_an_error_fails_when_it_grows_past_ten_times_the_recorded_one(tmp_path, factor, code):
    got, err = run_check(tmp_path, [record("peak [m]", factor * 2e-6)], [record("peak [m]", 2e-6)])
    assert got == code, err
    assert ("error grew: " + TEST + ": peak [m]" in err) == bool(code)


def test_a_check_states_its_own_growth_factor(tmp_path):
    run = [record("peak [m]", 30 * 2e-6, growth=50.0)]
    assert run_check(tmp_path, run, [record("peak [m]", 2e-6)])[0] == 0
    run = [record("peak [m]", 60 * 2e-6, growth=50.0)]
    assert run_check(tmp_path, run, [record("peak [m]", 2e-6)])[0] == 1


def test_round_off_errors_move_freely_below_the_floor(tmp_path):
    """Recorded 0 (exact on that machine): round-off on another one is not a regression,
    an error above 1e-12 of the reference is."""
    quiet = [record("energy [J]", 3e-14, reference=50.0, bound=50e-13)]
    assert run_check(tmp_path, quiet, [record("energy [J]", 0.0, reference=50.0)])[0] == 0
    loud = [record("energy [J]", 1e-9, reference=50.0, bound=50e-13)]
    assert run_check(tmp_path, loud, [record("energy [J]", 0.0, reference=50.0)])[0] == 1


def test_tables_without_recorded_errors_use_the_values(tmp_path):
    old = record("peak [m]", 2e-6)
    for key in ("error", "bound", "growth", "kind"):
        old.pop(key)
    assert run_check(tmp_path, [record("peak [m]", 5e-6)], [old])[0] == 0
    assert run_check(tmp_path, [record("peak [m]", 5e-5)], [old])[0] == 1


def test_missing_and_stale_checks_fail(tmp_path):
    code, err = run_check(tmp_path, [record("peak [m]", 2e-6)], [record("omega [rad/s]", 2e-6)])
    assert code == 1
    assert "not in the validation table" in err and "no longer checked" in err


def test_a_run_without_any_reference_check_fails(tmp_path):
    # a suite that stopped at collection records nothing: that is no pass
    code, err = run_check(tmp_path, [], [record("peak [m]", 2e-6)])
    assert code == 1 and "recorded no reference check" in err
