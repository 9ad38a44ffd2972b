"""The hb stage's rows of harmonic balance against time integration (damper.bench.hb_steady):
one row per model, the converged HB peak against the time integration from rest, and the
steady-state flag."""
import pytest

from damper.bench import hb_steady, report


@pytest.mark.slow
def test_quick_row_compares_the_converged_hb_with_the_time_integration_from_rest():
    lines = []
    rows = hb_steady.bench_rows(True, lines.append)
    assert lines[0] == hb_steady.HEAD and len(rows) == 1
    r = rows[0].as_dict()
    assert r["case"] == "steady sdof soft" and r["model"] == "sdof soft"
    # the soft oscillator has one steady state: the two peaks agree within their errors
    assert r["states_differ"] is False and r["beyond_errors"] is False
    assert r["error"] == pytest.approx(abs(r["hb_peak"] / r["ti_peak"] - 1))
    assert r["error"] < r["hb_error"] + r["ti_error"] + hb_steady.TI_PEAK_TOL
    assert r["check"]["states_rel"] < 1e-6 and r["check"]["stuck_links"] == []
    assert r["ti_omega"] == pytest.approx(r["hb_omega"], rel=hb_steady.TI_REL)
    text = report.table_text("hb", [r])
    assert "which steady state" in text and "same" in text.splitlines()[-2]
    md = report.markdown({"stamp": {"date_utc": "-", "revision": "-", "cores": 1, "machine": "-",
                                    "load_average": [0.0], "sparse_solvers": []},
                          "stages": {"hb": [r]}})
    assert "| sdof soft |" in md and "| same |" in md


def test_rows_cover_every_model_class_once():
    keys = hb_steady.models(False)
    assert "chain5" in keys and "upd24" in keys and "sdof soft" in keys
    assert len(keys) == len(set(keys))   # up and down share a row
