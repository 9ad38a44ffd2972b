"""The validation record (tests/refcheck.py) of a run on two pytest-xdist workers, as
``make test`` runs, holds the same checks with the same values as a run in one process:
the workers' records are merged by the controller (tests/conftest.py)."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: Two quick files that make reference checks, so each worker gets one.
FILES = ["tests/element/test_element_loops.py", "tests/element/test_element_fourier.py"]


def _record(tmp_path: Path, name: str, *options: str) -> dict:
    path = tmp_path / f"{name}.json"
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_XDIST")}
    env["DAMPER_VALIDATION_JSON"] = str(path)
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *options, *FILES],
                         cwd=ROOT, env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return json.loads(path.read_text())


def test_two_workers_record_the_checks_of_one_process(tmp_path):
    pytest.importorskip("xdist")
    serial = _record(tmp_path, "serial")
    parallel = _record(tmp_path, "parallel", "-n", "2", "--dist", "loadfile")
    assert {r["test"].split("::")[0] for r in serial["records"]} == set(FILES)

    def values(data):
        return sorted(((r["test"], r["quantity"]), r["value"], r["error"]) for r in data["records"])

    assert values(parallel) == values(serial)   # same code, one BLAS thread: bit for bit
    assert parallel["passed_tests"] == serial["passed_tests"]
