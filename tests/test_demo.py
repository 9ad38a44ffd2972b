"""`make demo` end to end: the default scene through `damper run`, on a small grid.

The Makefile's demo target runs ``damper run examples/scenes/default.toml``; here the
same scene with coarse contact grids and one excitation level runs every stage, writes
its results, and a second run computes nothing and says so.
"""
import json
import math
import re
from pathlib import Path

import pytest

from damper.cli import main as damper

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ROOT / "examples" / "scenes" / "default.toml"


def test_make_demo_runs_the_default_scene():
    target = re.search(r"^demo:.*\n((?:\t.*\n)+)", (ROOT / "Makefile").read_text(), re.M).group(1)
    assert "damper run examples/scenes/default.toml" in target


def test_default_scene_plan_needs_every_stage(tmp_path, capsys):
    assert damper(["run", str(DEFAULT), "--dry-run", "--json", "--cache-dir", str(tmp_path)]) == 0
    acts = {s["name"]: s["action"] for s in json.loads(capsys.readouterr().out)["stages"]}
    needed = ["condense:sphere:z", "condense:cylinder:z", "condense:damper:zx", "normal:sphere",
              "normal:cylinder", "tangential:damper", "loop", "fmu:fmi2", "fmu:fmi3",
              "frf:10N", "frf:20N", "frf:30N", "frf:60N"]
    assert all(acts[n] == "compute" for n in needed)
    # and nothing else: the kinds the scene does not describe (backbone, optimal_load) are idle
    assert sorted(n for n, a in acts.items() if a != "skip") == sorted(needed)
    assert not list(tmp_path.iterdir())                                           # a dry run computes nothing


@pytest.mark.slow
def test_demo_runs_every_stage_on_a_small_scene(tmp_path, capsys):
    text = DEFAULT.read_text().replace("grid = 21", "grid = 7").replace(
        "forces = [10.0, 20.0, 30.0, 60.0]", "forces = [100.0]").replace("harmonics = 5", "harmonics = 3")
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out, cache = tmp_path / "out", tmp_path / "cache"
    assert damper(["run", str(scene), "--out", str(out), "--cache-dir", str(cache)]) == 0
    first = capsys.readouterr().out
    assert "computed 10 stage(s)" in first
    run = json.loads((out / "run.json").read_text())
    fmus = [json.loads((out / f"fmu_fmi{v}" / "result.json").read_text())["data"] for v in (2, 3)]
    # the FMUs validate and dissipate energy; the FRF found a peak inside the sweep
    assert all(not d["problems"] and d["W_after_5_cycles"] > 0 for d in fmus)
    frf = json.loads(Path(run["outputs"]["frf"]).read_text())["data"]
    assert 2 * math.pi * 880 < frf["peak_omega"] < 2 * math.pi * 1300
    curve = json.loads(Path(run["outputs"]["virgin_curve"]).read_text())
    assert abs(curve["T"][-1] - curve["mu"] * curve["N"]) <= 1e-12 * curve["N"]  # ends at gross slip
    for name in ("damper_fmi2.fmu", "damper_fmi3.fmu"):
        assert any(Path(p).name == name for p in run["outputs"]["fmu"])
    assert Path(run["outputs"]["report"]).is_file()
    assert set(run["outputs"]["k_n"]) == {str(out / "normal_sphere" / "result.json"),
                                          str(out / "normal_cylinder" / "result.json")}
    # the second run computes nothing new, says so, and prints the same numbers
    assert damper(["run", str(scene), "--out", str(out), "--cache-dir", str(cache)]) == 0
    second = capsys.readouterr().out
    assert "nothing computed: every stage came from the cache" in second
    numbers = re.compile(r"[-+]?\d+\.\d+(?:e[-+]\d+)?")

    def results(text):
        """The result lines: after the plan, without the build/summary lines that differ."""
        lines = text.splitlines()
        start = next(i for i, ln in enumerate(lines) if i and not ln.startswith("  "))
        return [numbers.findall(ln) for ln in lines[start:]
                if not ln.startswith(("condensed bodies", "computed", "nothing", "results"))]

    assert results(first) == results(second) and len(results(first)) >= 10
