"""The HTML report shows each stage's warnings, escaped (stand-in results, no solve)."""
from pathlib import Path
from types import SimpleNamespace

from damper.report.html import render
from damper.run.contact_stages import Normal
from damper.run.graph import Kind, Result, Stage


class _Kind(Kind):
    name = "standin"

    def scalars(self, stage, result):
        return {"peak_m": 1.0e-5}


def _record(results: dict) -> SimpleNamespace:
    kind = _Kind()
    stages = [Stage(name, kind, {}, action="compute", reason="test") for name in results]
    scene = SimpleNamespace(data={"title": "warnings"}, source="w.toml", hash=lambda: "0" * 12)
    return SimpleNamespace(scene=scene, plan=SimpleNamespace(stages=stages, want=["report"]),
                           provenance={"git": {"commit": "abc"}, "created": "now"},
                           times={n: 0.1 for n in results}, results=results, outputs={})


def test_the_report_lists_each_stages_warnings_escaped():
    results = {
        "optimal_load:a": Result({"warning": "the walk stopped at 30 N <b>&</b>", "truncation_warning": None}),
        "upd_frf:b": Result({"band_end_warning": "warning: the largest amplitude lies at the band's end",
                             "lift_off_warning": "", "truncation_warning": "H too small"}),
        "tangential:c": Result({"warnings": ["grid corrected"]}),
        "frf:quiet": Result({"truncation_warning": None, "warnings": []}),
    }
    page = render(_record(results), Path("."))
    assert "the walk stopped at 30 N &lt;b&gt;&amp;&lt;/b&gt;" in page and "<b>&</b>" not in page
    # the result's own "warning:" prefix is not doubled
    assert "<li>warning: the largest amplitude lies at the band&#x27;s end</li>" in page
    assert "<li>warning: H too small</li>" in page and "<li>warning: grid corrected</li>" in page
    assert page.count("<li>warning:") == 4                       # none for None, "" or an empty list
    quiet = page.split("<h3>frf:quiet</h3>")[1].split("</table>")[0]
    assert "warning" not in quiet
    assert "warnings</b> in optimal_load:a, upd_frf:b, tangential:c" in page   # the pointer at the top


def test_an_under_resolved_normal_contact_warns_in_the_report():
    stage = Stage("normal:damper", Normal(), {})
    assert Normal().warnings(stage, Result({"under_resolved": False})) == []
    (text,) = Normal().warnings(stage, Result({"under_resolved": True}))
    assert text.startswith("under-resolved:") and "refine grid" in text
