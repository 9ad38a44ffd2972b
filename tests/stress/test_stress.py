"""`damper stress --quick`: no crash, hang, NaN, wrong number or unexplained failure."""
import json

import numpy as np
import pytest
from processes import gone_after_kill

from damper.cli import main
from damper.stress import checks, runner
from damper.stress.cases import Case


@pytest.mark.slow
def test_stress_quick_has_no_unexplained_failure(tmp_path, capsys):
    code = main(["stress", "--quick", "--json", "--out", str(tmp_path)])
    out = json.loads(capsys.readouterr().out)
    rows = out["cases"]
    assert rows and {r["stage"] for r in rows} == {"inputs", "normal", "tangential", "loop", "fmu", "frf"}
    assert sum(r["stage"] == "inputs" for r in rows) >= 150
    for r in rows:
        assert set(r) >= {"stage", "case", "outcome", "message", "worst_residual", "time_s"}
        assert r["outcome"] not in ("crash", "hang", "nan"), r
        assert r["ok"] or r["known"], r
    # the expected refusals were refused with a message
    refused = [r for r in rows if r["expected"] == "clear_error"]
    assert refused and all(r["outcome"] == "clear_error" and r["message"] for r in refused)
    assert code == 0
    md = (tmp_path / "stress.md").read_text()        # the input stage by command, then every row
    assert md.startswith("| command | cases |") and "\n| stage | case |" in md


def test_classify_detects_each_failure_kind():
    case = Case("loop", "x", [], timeout=1.0)
    assert runner.classify(case, None, "", "")[0] == "hang"
    assert runner.classify(case, 1, "", "Traceback (most recent call last):\n  boom")[0] == "crash"
    assert runner.classify(case, -11, "", "")[0] == "crash"
    assert runner.classify(case, 2, "", "damper loop: error: --samples must be >= 4")[0] == "clear_error"
    good = {"u": [0.0, 1e-6], "F": [0.0, 50.0], "gross_slip_force": 100.0, "displacement_amplitude": 1e-6,
            "energy_per_cycle": 1e-5}
    assert runner.classify(case, 0, json.dumps(good), "")[0] == "converged"
    too_big = dict(good, F=[0.0, 100.5])  # |F| above the slip force
    assert runner.classify(case, 0, json.dumps(too_big), "")[0] == "wrong"
    assert checks.check("loop", dict(good, energy_per_cycle=float("nan")), {})[0] == "nan"


def test_fmu_check_uses_trapezoid_slack():
    base = {"max_abs_F": 100.0, "min_dW": 0.0, "W": 1e-4, "slip_force": 100.0, "work_scale": 1e-4,
            "stored_bound": 2.5e-4}
    assert checks.check("fmu", dict(base, stored=-1e-6, slack=2e-6), {})[0] == "converged"
    assert checks.check("fmu", dict(base, stored=-1e-5, slack=2e-6), {})[0] == "wrong"
    assert np.isfinite(checks.fmu(dict(base, stored=0.0, slack=0.0), {})[0])


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_a_hang_is_detected_and_killed(tmp_path):
    from damper.bench.common import run_child

    pid_file = tmp_path / "hung.pid"
    r = run_child([], timeout=5.0, python_code=f"import os, time; open({str(pid_file)!r}, 'w')"
                                             f".write(str(os.getpid())); time.sleep(60)")
    # the time limit ended it (no exit code), and the hung child is gone (its whole group
    # got SIGKILL), not waited on for its 60 s
    assert r.code is None and gone_after_kill(int(pid_file.read_text()))
