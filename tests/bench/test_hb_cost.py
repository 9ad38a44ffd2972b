"""The hb stage's cost rows (damper.bench.hb_cost): one row per case and H, with the
curve's own figures, and the peak the engine reports for the same model and H."""
import pytest

from damper.bench import hb_cost
from harmonic_balance.bench_models import chain5
from harmonic_balance.frf import compute_frf

#: The row's peak and the engine's are the same computation: equal to round-off.
SAME_PEAK_RTOL = 1e-12


@pytest.mark.slow
def test_cost_rows_report_each_curve_with_its_peak():
    lines = []
    rows = hb_cost.run(True, lines.append, harmonics={"chain5": (3,)})
    assert len(rows) == 1 and lines[0] == hb_cost.HEAD
    r = rows[0].as_dict()
    assert r["case"] == "cost chain5 up" and r["size"] == 3 and r["error"] is None
    assert r["points"] > 10 and r["evaluations"] >= r["points"]
    assert r["time_s"] > 0 and r["time_per_point_s"] == pytest.approx(r["time_s"] / r["points"])
    case = chain5()
    ref = compute_frf(case.model(), 3, case.band)
    assert r["peak_amplitude"] == pytest.approx(ref.peak_amplitude, rel=SAME_PEAK_RTOL)
    assert r["peak_omega"] == pytest.approx(ref.peak_omega, rel=SAME_PEAK_RTOL)
