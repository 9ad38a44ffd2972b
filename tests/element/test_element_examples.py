"""examples/masing_loops.py runs (smoke) and its study reproduces Mindlin-Deresiewicz."""
from __future__ import annotations


def test_masing_loops_example_matches_mindlin_deresiewicz(tmp_path, capsys, load_example):
    ex = load_example("masing_loops")
    assert ex.main(["--smoke", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "loops.png").exists() and (tmp_path / "energy.png").exists()
    (row,) = ex.study((64,), (0.6,))
    # 64 chords of the Cattaneo-Mindlin curve: energy within 1e-3 (measured 2.7e-4)
    assert abs(row["err"]) < 1e-3
    assert len(capsys.readouterr().out.splitlines()) == 1 + 2 * 2 + 1   # header, 4 rows, plots
