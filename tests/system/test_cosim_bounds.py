"""``damper cosim``: bounded work, a diverging coupling reported as a failure, libcosim's log
kept off the JSON on stdout, an archive's missing FMU named before libcosim starts."""
import ctypes
import json
import zipfile

import pytest
from failure_output import no_result

from damper import limits
from damper.cli import main
from damper.cosim import MAX_ENERGY_RESIDUAL, _stdout_to_stderr


def _cli(argv, capsys):
    code = main(argv)
    cap = capsys.readouterr()
    return code, cap.out, cap.err


@pytest.mark.parametrize("extra, words", [
    (["--frequency-hz", "1e-300"], "steps a period"),           # the period overflows
    (["--frequency-hz", "1e-3"], "steps a period"),
    (["--frequency-hz", "1e12"], "above the limit"),
    (["--frequency-hz", "448", "--periods", "1000000000000"], f"above the limit {limits.MAX_COSIM_PERIODS}"),
    (["--frequency-hz", "448", "--periods", "50000"], "steps, above the limit"),   # 50000 x ~2400 steps
    (["--frequency-hz", "448", "--tol", "10"], "--tol must be a relative change"),   # "settled", 15 % off
])
def test_unbounded_work_is_refused_before_libcosim_starts(ring_ssp, capsys, extra, words):
    code, out, err = _cli(["cosim", str(ring_ssp), *extra, "--json"], capsys)
    assert code == 2 and no_result(out, err, 2) and words in err and len(err.splitlines()) == 1


def test_an_fmu_missing_from_the_archive_is_named(ring_ssp, tmp_path, capsys):
    broken = tmp_path / "broken.ssp"
    with zipfile.ZipFile(ring_ssp) as src, zipfile.ZipFile(broken, "w") as dst:
        for item in src.infolist():
            if item.filename != "resources/damper.fmu":
                dst.writestr(item, src.read(item.filename))
    code, out, err = _cli(["cosim", str(broken), "--frequency-hz", "448", "--json"], capsys)
    assert code == 2 and no_result(out, err, 2) and "resources/damper.fmu" in err and "does not hold" in err


def test_c_level_output_inside_the_engine_block_goes_to_stderr(capfd):
    """libcosim's log sink writes to file descriptor 1; inside the block it reaches stderr."""
    libc = ctypes.CDLL(None)
    with _stdout_to_stderr():
        libc.puts(b"engine log line")
    print("json", flush=True)
    cap = capfd.readouterr()
    assert cap.out == "json\n" and "engine log line" in cap.err


def test_a_diverging_coupling_is_a_failure_not_a_result(ring_ssp, capsys):
    """--force with a step 13 times the coupling limit: the response grows by orders of
    magnitude a period; exit 3 with the step to change, nothing on stdout."""
    pytest.importorskip("libcosimpy", reason="libcosimpy (PyPI) is a test dependency")
    code, out, err = _cli(["cosim", str(ring_ssp), "--frequency-hz", "448", "--step", "1e-4", "--periods", "20",
                           "--force", "--json"], capsys)
    assert code == 3 and no_result(out, err, 3)
    assert "grew" in err and "use a smaller --step" in err and len(err.splitlines()) == 1


def test_a_step_above_the_limit_that_misses_the_energy_balance_is_a_failure(ring_ssp, capsys):
    """--force at 1.4 times the coupling limit: no blow-up, but the last period's energy
    balance misses more than the excitation's work (measured 1.17): exit 3."""
    pytest.importorskip("libcosimpy", reason="libcosimpy (PyPI) is a test dependency")
    code, out, err = _cli(["cosim", str(ring_ssp), "--frequency-hz", "448", "--step", "1e-5", "--periods", "12",
                           "--tol", "0", "--force", "--json"], capsys)
    assert code == 3 and no_result(out, err, 3) and "energy balance is off" in err
    # the default step passes the same check by orders of magnitude
    code, out, err = _cli(["cosim", str(ring_ssp), "--frequency-hz", "448", "--periods", "8", "--tol", "0",
                           "--json"], capsys)
    assert code == 0 and abs(json.loads(out)["energy"]["relative_residual"]) < 1e-3 * MAX_ENERGY_RESIDUAL
