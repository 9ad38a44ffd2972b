"""examples/surface_march_resolution.py: the condensed surface's march at other samples and periods."""
import json

import pytest

pytestmark = pytest.mark.slow

#: The march's second period is its steady loop (surface_condensed.PERIODS = 2): a third
#: repeats it, so the two solutions differ by Newton's tolerance only (its residual 1e-8 of
#: the loads: far below 1e-7 of the amplitude), while one period leaves the first one's
#: transient in the loop (UPD-24, CF 120 N, H 7: 2.7e-4).
SAME_LOOP_RTOL = 1e-7
#: What one period leaves (CF 300 N, H 1, 32 samples: +1.35e-3 measured): the test sees
#: that the period count reaches the march.
ONE_PERIOD_MIN = 1e-4


def test_a_third_period_repeats_the_second_one_period_does_not_and_the_rows_are_written(tmp_path, load_example):
    out = tmp_path / "res.json"
    ex = load_example("surface_march_resolution")
    assert ex.main(["--cf", "300", "--harmonics", "1", "--at", "440", "--samples", "32",
                    "--periods", "2,3,1", "--json", str(out)]) == 0
    rec = json.loads(out.read_text())
    two, three, one = rec["rows"]
    assert (two["samples"], two["periods"], three["periods"], one["periods"]) == (32, 2, 3, 1)
    assert three["difference"] == pytest.approx(0.0, abs=SAME_LOOP_RTOL)
    assert abs(one["difference"]) > ONE_PERIOD_MIN
    assert two["amplitude_h1"] > 0 and rec["revision"]


def test_samples_at_or_below_twice_the_harmonics_are_refused(load_example):
    with pytest.raises(SystemExit) as e:
        load_example("surface_march_resolution").main(["--harmonics", "7", "--samples", "14"])
    assert e.value.code == 2


@pytest.mark.parametrize("argv", [["--nodes", "1"], ["--start", "no_such_solution.npy"]])
def test_a_node_count_out_of_bound_or_a_missing_start_is_a_usage_error(argv, load_example, capsys):
    with pytest.raises(SystemExit) as e:
        load_example("surface_march_resolution").main(argv)
    assert e.value.code == 2 and "error:" in capsys.readouterr().err
