"""`damper bench --quick`: every stage gives rows of the documented shape, errors against
their references are small where the physics says they must be."""
import json

import pytest

from damper.cli import main

ROW_KEYS = {"case", "size", "error", "time_s", "memory_mb", "cached"}


@pytest.mark.slow
def test_bench_quick_report(tmp_path, capsys):
    code = main(["bench", "--quick", "--json", "--out", str(tmp_path)])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    stages = out["stages"]
    assert set(stages) == {"contact", "tangential", "element", "fmu", "hb", "surface"}
    for name, rows in stages.items():
        assert rows, name
        for r in rows:
            assert ROW_KEYS <= set(r), (name, r)
            assert r["time_s"] > 0 and r["memory_mb"] > 0
    # cached contact runs reproduce the cold numbers exactly (same condensed matrices)
    cold = {r["size"]: r["error"] for r in stages["contact"] if not r["cached"]}
    warm = {r["size"]: r["error"] for r in stages["contact"] if r["cached"]}
    assert cold == warm and cold
    # more sliders -> a smaller loop-energy error (Masing on a finer Mindlin table)
    errs = [r["error"] for r in sorted(stages["element"], key=lambda r: r["size"])]
    assert errs == sorted(errs, reverse=True)
    # the FMU's element is rate independent: a step that hits the reversal points
    # (4 or 64 a cycle) dissipates the exact Masing energy (measured 2e-15); 6 a cycle misses them
    fmu = {r["size"]: r["error"] for r in stages["fmu"]}
    assert fmu[4] < 1e-12 and fmu[64] < 1e-12 and fmu[6] > 1e-2
    # harmonic balance converges to time integration with H (measured with exact friction
    # links 1.5e-2, 1.1e-3, 1.2e-4: H = 7's truncation; H = 21 is within 7e-6 of the 1024-
    # step time integration, which 4096 steps move by 5e-6. The sampled AFT's 2e-5 at H = 7
    # was its sampling error cancelling the truncation)
    hb = {r["size"]: r["error"] for r in stages["hb"] if r["case"] == "harmonics"}
    assert hb[1] > hb[3] > hb[7] and hb[7] < 2e-4
    assert any(r.get("default") for r in stages["hb"])
    # the accuracy rows (tests/bench/test_bench_accuracy.py checks their numbers)
    acc = [r for r in stages["hb"] if r["case"].startswith("accuracy ")]
    assert acc and all(r["estimate"] is not None and r["error"] > 0 for r in acc)
    assert out["stamp"]["cores"] >= 1 and "numpy" in out["stamp"]["versions"]
    html = (tmp_path / "bench.html").read_text()
    assert html.count("data:image/png;base64,") == 6 and "<th>true error</th>" in html
