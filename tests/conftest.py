"""Fixtures shared by every test folder."""
import importlib.util
import os
from pathlib import Path

# One BLAS thread in this process and every child, as the ``damper`` command runs (its
# cli module sets the same): bit-for-bit comparisons between an in-process run and a
# subprocess or Dask worker then hold whatever the machine's core count, and whether or
# not pytest is started through the Makefile (which sets it too).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pytest  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

threadpool_limits(limits=int(os.environ["OPENBLAS_NUM_THREADS"]), user_api="blas")  # numpy may be loaded already

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture
def load_example():
    """``load_example(name)``: import ``examples/<name>.py`` (not a package) as a module."""
    def load(name: str):
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    return load


# The validation table (docs/validation.md): every refcheck.check of this run, written to
# $DAMPER_VALIDATION_JSON with the tests that passed and the run's stamp (make validation).
# Under pytest-xdist (make test runs `-n 2`) each worker holds the checks of its own tests:
# it hands them to the controller (workeroutput), which merges them and writes the one file.
_PASSED: list[str] = []


def pytest_runtest_logreport(report):
    # on the xdist controller too: it replays every worker's reports through this hook
    if report.when == "call" and report.passed:
        _PASSED.append(report.nodeid)


@pytest.hookimpl(optionalhook=True)   # an xdist hook: unknown without the plugin
def pytest_testnodedown(node, error):
    """Controller: collect a finished worker's reference checks."""
    import json

    import refcheck

    records = json.loads(getattr(node, "workeroutput", {}).get("refcheck_records", "[]"))
    refcheck.RECORDS.extend(records)
    refcheck.RECORDS.sort(key=lambda r: r["test"])   # stable: a test's checks keep their order


def pytest_sessionfinish(session, exitstatus):
    import json
    import sys

    import refcheck

    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:   # an xdist worker: the controller writes the file
        workeroutput["refcheck_records"] = json.dumps(refcheck.RECORDS)
        return
    path = os.environ.get("DAMPER_VALIDATION_JSON")
    if not path:
        return
    from damper.bench.common import stamp

    data = {"command": os.environ.get("DAMPER_VALIDATION_COMMAND", " ".join(["pytest", *sys.argv[1:]])),
            "exit_code": int(exitstatus), "stamp": stamp(), "passed_tests": sorted(_PASSED),
            "records": refcheck.RECORDS}
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(path + ".tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(path)
