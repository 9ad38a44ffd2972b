"""examples/masing_loops.py runs (smoke) and its study reproduces Mindlin-Deresiewicz."""
from __future__ import annotations

import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "masing_loops.py"


def load_example():
    spec = importlib.util.spec_from_file_location("masing_loops", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_masing_loops_example_matches_mindlin_deresiewicz(tmp_path, capsys):
    ex = load_example()
    assert ex.main(["--smoke", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "loops.png").exists() and (tmp_path / "energy.png").exists()
    (row,) = ex.study((64,), (0.6,))
    # 64 chords of the Cattaneo-Mindlin curve: energy within 1e-3 (measured 2.7e-4)
    assert abs(row["err"]) < 1e-3
    assert len(capsys.readouterr().out.splitlines()) == 1 + 2 * 2 + 1   # header, 4 rows, plots
