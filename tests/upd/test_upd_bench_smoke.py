"""Smoke run of examples/bench_upd.py --quick (the full benchmark runs by hand)."""
import pytest


@pytest.mark.slow
def test_bench_upd_quick(tmp_path, load_example, capsys):
    bench = load_example("bench_upd")
    rows = bench.main(["--quick", "--out", str(tmp_path)])
    assert (tmp_path / "bench_upd.json").exists() and (tmp_path / "bench_upd.png").exists()
    assert "case | size | error | time" in capsys.readouterr().out
    assert rows["optimize"]["interior"]
    r = rows["ti"][0]
    # 3 periods only: the TI is far from settled; it must still be finite and of the
    # same order as HB (measured -8 % at 3 periods)
    assert abs(r["H3"]["err_vs_ti"]) < 0.5
