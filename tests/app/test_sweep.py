"""damper sweep: a Dask local cluster with two workers gives the serial numbers and runs
the shared stages once (counted from what the cache was asked to compute)."""
import json

import pytest
from apphelpers import SMALL

from damper.cache import Store
from damper.cli import main as damper
from damper.cli.sweep import specs_from
from damper.sweep import run_sweep, variants

QUIET = {"echo": lambda text: None}


def test_variants_grid_zip_and_parsing():
    assert variants([("a", [1, 2]), ("b", [3, 4])]) == [{"a": 1, "b": 3}, {"a": 1, "b": 4},
                                                         {"a": 2, "b": 3}, {"a": 2, "b": 4}]
    assert variants([("a", [1, 2]), ("b", [3, 4])], grid=False) == [{"a": 1, "b": 3}, {"a": 2, "b": 4}]
    assert specs_from([("param", "x.y"), ("range", ["0", "1", "3"]), ("param", "z"), ("values", ["2", "[1]"])]) \
        == [("x.y", [0.0, 0.5, 1.0]), ("z", [2, [1]])]
    for bad in ([("values", ["1"])], [("param", "a")], [("param", "a"), ("range", ["0", "1", "x"])]):
        with pytest.raises(ValueError):
            specs_from(bad)


def test_bad_sweep_value_fails_before_any_work(tmp_path, capsys):
    cache = tmp_path / "cache"
    code = damper(["sweep", str(SMALL), "--param", "contact.damper.mu", "--values", "0.5", "-1",
                   "--serial", "--cache-dir", str(cache), "--out", str(tmp_path / "o")])
    assert code == 2 and "contact.damper.mu: must be > 0" in capsys.readouterr().err
    assert not cache.exists() and not (tmp_path / "o").exists()


@pytest.mark.slow
def test_dask_two_workers_equal_serial_and_shared_stages_run_once(tmp_path):
    specs = [("contact.damper.mu", [0.5, 0.6])]
    serial = run_sweep(SMALL, specs, Store(tmp_path / "c1"), tmp_path / "s1", serial=True, **QUIET)
    dask = run_sweep(SMALL, specs, Store(tmp_path / "c2"), tmp_path / "s2", workers=2, **QUIET)
    assert dask.rows == serial.rows                       # the same numbers, bit for bit
    assert [r["contact.damper.mu"] for r in dask.rows] == [0.5, 0.6]
    assert dask.rows[0]["tangential:damper.u_gross_slip_m"] < dask.rows[1]["tangential:damper.u_gross_slip_m"]
    # condensation shared by both variants; everything else once per variant; each key computed once
    assert dask.shared == ["condense:damper:zx"]
    names = [v["stage"] for v in dask.computations.values()]
    assert sorted(names) == sorted(["condense:damper:zx"] + 2 * ["tangential:damper", "loop", "frf:30N"])
    assert all(v["count"] == 1 for v in dask.computations.values())
    table = json.loads((tmp_path / "s2" / "sweep.json").read_text())
    assert table["rows"] == json.loads(json.dumps(serial.rows))
    assert (tmp_path / "s2" / "sweep.csv").read_text().count("\n") == 3 and (tmp_path / "s2" / "sweep.png").exists()
    again = run_sweep(SMALL, specs, Store(tmp_path / "c2"), None, serial=True, **QUIET)
    assert again.computations == {} and again.rows == serial.rows      # all from the cache


@pytest.mark.parametrize("argv", [["--values", "0.5", "0.5"], ["--range", "0.5", "0.5", "3"]])
def test_a_variant_given_twice_is_refused_before_any_run(argv, capsys):
    assert damper(["sweep", "nowhere.toml", "--param", "contact.damper.mu", *argv, "--serial"]) == 2
    assert "given twice" in capsys.readouterr().err


def test_zipped_variants_may_repeat_one_parameter_but_not_a_whole_variant():
    from damper.cli.sweep import check_distinct_variants

    check_distinct_variants([("a", [1.0, 1.0]), ("b", [2.0, 3.0])], zipped=True)
    with pytest.raises(ValueError, match="given twice"):
        check_distinct_variants([("a", [1.0, 1.0]), ("b", [2.0, 2.0])], zipped=True)
