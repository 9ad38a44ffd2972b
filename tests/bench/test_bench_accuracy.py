"""The hb stage's accuracy rows (damper.bench.hb_accuracy.bench_rows): per model, H and
accuracy target the engine's truncation-error estimate beside the true error, and the
report's tables that show both."""
import json

import pytest

from damper.bench import hb_accuracy, report
from harmonic_balance.bench_models import sdof
from harmonic_balance.frf import compute_frf

#: The row's peak and the engine's are the same computation: equal to round-off.
SAME_PEAK_RTOL = 1e-12
#: Round-off of the relative error recomputed from the row's two peaks.
ERROR_RTOL = 1e-9


@pytest.fixture(scope="module")
def quick_rows():
    lines = []
    rows = [r.as_dict() for r in hb_accuracy.bench_rows(True, lines.append)]
    return rows, lines


def test_quick_accuracy_rows_cover_each_h_and_target(quick_rows):
    rows, lines = quick_rows
    models = {r["model"] for r in rows}
    assert models == set(hb_accuracy.BENCH_QUICK_MODELS)
    for model in models:
        mine = [r for r in rows if r["model"] == model]
        assert sorted(r["size"] for r in mine if r["target"] is None) == list(hb_accuracy.HS[:2])
        assert [r["target"] for r in mine if r["target"] is not None] == list(hb_accuracy.TOLS[:1])
    assert lines[0] == hb_accuracy.table_lines([])[0] and len(lines) == 1 + len(rows)
    json.dumps(rows)   # the bench JSON holds them as they are


def test_accuracy_row_error_is_its_peak_against_the_reference(quick_rows):
    for r in quick_rows[0]:
        assert r["case"] == f"accuracy {r['model']}" + (" target" if r["target"] is not None else "")
        assert r["error"] == r["true_error"] > 0
        assert r["error"] == pytest.approx(abs(r["peak_amplitude"] / r["reference_amplitude"] - 1), rel=ERROR_RTOL)
        assert r["ratio"] == pytest.approx(r["estimate"] / r["true_error"])
        assert r["time_s"] > 0 and r["memory_mb"] > 0


def test_accuracy_row_peak_is_the_engines_peak_at_that_h(quick_rows):
    case = sdof(1.0)
    r = next(r for r in quick_rows[0] if r["model"] == case.name and r["size"] == 3 and r["target"] is None)
    ref = compute_frf(case.model(), 3, case.band, stability="off")
    assert r["peak_amplitude"] == pytest.approx(ref.peak_amplitude, rel=SAME_PEAK_RTOL)


def test_more_harmonics_bring_the_peak_closer_to_the_reference(quick_rows):
    """Truncation error falls with H (the reference is the same peak at REFERENCE_H)."""
    for model in hb_accuracy.BENCH_QUICK_MODELS:
        err = {r["size"]: r["error"] for r in quick_rows[0] if r["model"] == model and r["target"] is None}
        assert err[3] > err[7]


def test_an_accuracy_target_met_by_its_estimate_is_met_in_truth(quick_rows):
    for r in (r for r in quick_rows[0] if r["target"] is not None):
        assert r["estimate"] <= r["target"] and r["true_error"] <= r["target"]


def test_report_shows_estimate_and_true_error_of_accuracy_rows(quick_rows, tmp_path):
    rows = quick_rows[0]
    stamp = {"date_utc": "2026-01-01T00:00:00Z", "revision": "abc", "cores": 2, "machine": "x86_64",
             "load_average": [1.0, 1.0, 1.0], "sparse_solvers": ["scipy"]}
    _, html = report.write(tmp_path, {"stamp": stamp, "quick": True, "stages": {"hb": rows}})
    page = html.read_text()
    assert page.count("<th>true error</th>") == 1 and page.count("data:image/png;base64,") == 1
    text = report.table_text("hb", rows)
    md = (tmp_path / "bench.md").read_text()
    for r in rows:
        assert r["setting"] in text and f"| {r['estimate']:.2e} | {r['true_error']:.2e} |" in md


def test_accuracy_row_flags_follow_the_goals(quick_rows):
    for r in quick_rows[0]:
        floor = max(hb_accuracy.TRUE_FLOOR, hb_accuracy.REFERENCE_MARGIN * (r["reference_error"] or 0.0))
        if r["ratio"] is not None and r["true_error"] >= floor:
            assert r["ratio_ok"] == (1 / hb_accuracy.RATIO_BAND <= r["ratio"] <= hb_accuracy.RATIO_BAND)
        if r["target"] is not None:
            assert r["target_met"] == (r["true_error"] <= r["target"]) and r["engine_met"] is not None
    default = [r for r in quick_rows[0] if r["default"] is not None]
    assert [r["setting"].split(" -> ")[0] for r in default] == [hb_accuracy.DEFAULT_FRF]


@pytest.mark.parametrize("true, est, verdict, flag", [
    (0.005, 0.002, "ok", ""), (0.02, 0.03, "warned", "D~"), (0.02, 0.005, "FAIL", "R D!")])
def test_default_row_is_ok_within_one_percent_else_warned_or_failed(true, est, verdict, flag):
    ref = 1.0
    r = hb_accuracy._row("m", "H 7", ref * (1 + true), {"peak_amplitude_rel": est}, ref, 1.0, 7,
                         default_of="H 7")
    assert r["default"] == verdict and r["flags"] == flag
    assert hb_accuracy.goals([r])["default"] == {"rows": 1, "failing": ["m / H 7"] if verdict == "FAIL" else []}


def test_target_row_missed_by_the_engines_limit_is_flagged_t():
    r = hb_accuracy._row("m", "tol 0.001 -> H 27", 1.01, {"peak_amplitude_rel": 0.012}, 1.0, 1.0, 27, 1e-3,
                         {"met": False})
    assert r["target_met"] is False and r["engine_met"] is False and r["flags"] == "t"


@pytest.mark.parametrize("true, judged", [(2e-4, None), (4e-4, True)])
def test_a_true_error_within_the_references_own_error_is_not_judged(true, judged):
    # reference error 1e-4: below REFERENCE_MARGIN times it the true error is not measured
    ref_error = 1e-4
    assert ref_error * hb_accuracy.REFERENCE_MARGIN == pytest.approx(3e-4)
    r = hb_accuracy._row("m", "H 7", 1.0 + true, {"peak_amplitude_rel": true}, 1.0, 1.0, 7, ref_error=ref_error)
    assert r["ratio_ok"] is judged and r["reference_error"] == ref_error
    assert r["flags"] == ("u" if judged is None else "")


def test_accuracy_row_records_the_levels_its_estimate_came_from(quick_rows):
    for r in quick_rows[0]:
        hs = [lv[0] for lv in r["levels"]]
        assert len(hs) >= 2 and hs == sorted(hs) and hs[0 if r["target"] is None else -1] == r["size"]
        assert r["levels"][0][1] == r["peak_amplitude"] or r["target"] is not None
