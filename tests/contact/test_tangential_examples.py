"""Smoke runs of the tangential examples (tiny grids): they run, print and save."""
import pytest


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_virgin_curves_example_smoke(tmp_path, capsys, load_example):
    assert load_example("virgin_curves").main(["--smoke", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "sphere CNF" in out and "cylinder CND" in out and "Masing" in out and "eq. 2.14" in out
    assert (tmp_path / "virgin_curves.png").exists()
    assert len(list(tmp_path.glob("*.json"))) == 4


def test_bench_tangential_smoke(capsys, load_example):
    assert load_example("bench_tangential").main(["--smoke"]) == 0
    rows = [r.split() for r in capsys.readouterr().out.splitlines()[1:]]
    assert [r[:3] for r in rows] == [["bem", "9", "cold"], ["halfspace", "5", "cold"],
                                     ["halfspace", "5", "cached"]]
    # the cached run reads the condensed model instead of building it (the BEM has no cache)
    assert [r[-1] for r in rows] == ["-", "miss", "hit"]
