"""``damper fmu``: numbers that would give a broken FMU are refused before anything is written."""
import pytest

from damper import limits
from damper.cli import main as damper


@pytest.fixture(scope="module")
def fx(tmp_path_factory):
    from damper.stress.input_fixtures import make

    return make(tmp_path_factory.mktemp("fx"))


@pytest.mark.parametrize("extra, words", [
    (["--n-ref", "1e-320"], "--n-ref 9.99989e-321 N is outside"),     # N / N_ref overflows at the start
    (["--n-ref", "1e308"], "--n-ref 1e+308 N is outside"),            # F = 0
    (["--k-n", "1e-300"], "--k-n 1e-300 N/m is outside"),             # p_start = N / k_n overflows
    (["--k-n", "1e20"], "--k-n 1e+20 N/m is outside"),
    (["--k-n", "-5e7"], "--k-n must be finite and > 0"),
    (["--k-n", "1e8", "--preload", "1e12"], "--preload 1e+12 N is outside"),
    (["--normal", "{fx}/normal_120.json", "--preload", "1e7"], "covers 0 ... 120 N"),
])
def test_an_fmu_number_out_of_range_is_refused_and_nothing_written(fx, tmp_path, capsys, extra, words):
    out = tmp_path / "d.fmu"
    argv = ["fmu", "--curve", str(fx / "curve.json"), "-o", str(out)] + [a.format(fx=fx) for a in extra]
    assert damper(argv) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_the_ranges_hold_the_nominal_values(fx, tmp_path, capsys):
    """The bounds leave every ordinary contact (the fixture curve at 200 N, a preload inside
    the normal curve, k_n of a steel contact) alone."""
    assert limits.MIN_NORMAL_LOAD < 200.0 < limits.MAX_NORMAL_LOAD
    assert limits.MIN_PENALTY_STIFFNESS < 3e8 < limits.MAX_PENALTY_STIFFNESS
    for extra in (["--normal", str(fx / "normal_120.json"), "--preload", "100"],
                  ["--k-n", "3e8", "--preload", "200"]):
        assert damper(["fmu", "--curve", str(fx / "curve.json"), "-o", str(tmp_path / "p.fmu"), *extra]) == 0
        assert (tmp_path / "p.fmu").stat().st_size > 0
