"""The plan and the cache: only the stages a scene needs run, and only when their
inputs or code changed (on a coarse 7x7 contact grid)."""
import json

import pytest
from apphelpers import SMALL, plan_actions

from damper.cache import Store
from damper.cli import main as damper
from damper.run.runner import plan_scene, run_scene
from damper.scene import parse_scene

pytestmark = pytest.mark.slow
TEXT = SMALL.read_text()
QUIET = {"echo": lambda text: None}


def test_k_n_only_runs_no_tangential_fmu_or_harmonic_balance(tmp_path):
    scene = parse_scene(TEXT.replace('want = ["virgin_curve", "k_t", "loop", "frf", "report"]', 'want = ["k_n"]'))
    store = Store(tmp_path / "cache")
    rec = run_scene(scene, store, tmp_path / "out", **QUIET)
    acts = plan_actions(rec.plan)
    assert rec.computed == ["condense:damper:z", "normal:damper"]
    for name in ("condense:damper:zx", "tangential:damper", "loop", "fmu:fmi2", "frf:30N"):
        assert acts[name] == "skip", name
    assert set(rec.results) == {"condense:damper:z", "normal:damper"}
    assert store.info()["entries"] == 3          # the condensed matrices, the condense and normal stages
    assert json.loads((tmp_path / "out" / "run.json").read_text())["outputs"] == {
        "k_n": str(tmp_path / "out" / "normal_damper" / "result.json")}


def test_second_run_computes_nothing(small_run):
    store, out, first = small_run
    assert first.computed == ["condense:damper:zx", "tangential:damper", "loop", "frf:30N"]
    writes = store.writes
    rec = run_scene(first.scene, store, out, **QUIET)
    assert rec.computed == [] and store.writes == writes
    acts = plan_actions(rec.plan)
    assert acts["condense:damper:zx"] == "skip"        # nobody computing needs the FE matrices
    assert all(acts[n] == "cached" for n in ("tangential:damper", "loop", "frf:30N"))
    for name in first.results:                         # the same numbers, from the cache
        if name in rec.results:
            assert rec.results[name].data == first.results[name].data


def test_changing_mu_recomputes_the_tangential_stage_and_what_follows_not_the_condensation(small_run):
    store, out, first = small_run
    scene = parse_scene(TEXT.replace("mu = 0.5", "mu = 0.55"))
    writes = store.writes
    rec = run_scene(scene, store, out.parent / "mu", **QUIET)
    acts = plan_actions(rec.plan)
    assert acts["condense:damper:zx"] == "cached"
    assert rec.computed == ["tangential:damper", "loop", "frf:30N"]
    assert store.writes - writes == 3                  # no condensation entry written
    assert rec.results["tangential:damper"].data["k_t"] == first.results["tangential:damper"].data["k_t"]
    assert rec.results["tangential:damper"].data["mu"] == 0.55


def test_changing_the_structural_damping_reruns_only_the_forced_response(small_run):
    store, out, first = small_run
    scene = parse_scene(TEXT.replace("zeta = 0.002", "zeta = 0.003"))
    rec = run_scene(scene, store, out.parent / "zeta", **QUIET)
    assert rec.computed == ["frf:30N"]
    assert plan_actions(rec.plan)["tangential:damper"] == "cached"
    more = rec.results["frf:30N"].data["peak_amplitude"]
    assert more < first.results["frf:30N"].data["peak_amplitude"]   # more damping, lower peak


def test_force_recomputes_a_stage_and_its_dependants(small_run):
    store, out, first = small_run
    plan = plan_scene(first.scene, store, force=["tangential:damper"])
    acts = plan_actions(plan)
    assert [n for n, a in acts.items() if a == "compute"] == ["tangential:damper", "loop", "frf:30N"]
    assert acts["condense:damper:zx"] == "cached"
    assert "forced" in plan["loop"].reason and "tangential:damper" in plan["loop"].reason
    with pytest.raises(ValueError, match="no such stage"):
        plan_scene(first.scene, store, force=["tangential:other"])


def test_dry_run_json_prints_the_plan_and_writes_nothing(small_run, tmp_path, capsys):
    store, _, _ = small_run
    out = tmp_path / "out"
    assert damper(["run", str(SMALL), "--dry-run", "--json", "--out", str(out),
                   "--cache-dir", str(store.folder)]) == 0
    plan = json.loads(capsys.readouterr().out)
    assert set(plan) == {"stages"}
    assert {s["name"]: s["action"] for s in plan["stages"]}["tangential:damper"] == "cached"
    assert all(set(s) == {"name", "action", "reason"} and s["reason"] for s in plan["stages"])
    assert not out.exists()


def test_run_json_outputs_times_and_provenance(small_run, tmp_path, capsys):
    store, _, first = small_run
    out = tmp_path / "out"
    assert damper(["run", str(SMALL), "--json", "--out", str(out), "--cache-dir", str(store.folder)]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert set(rec["outputs"]) == {"virgin_curve", "k_t", "loop", "frf", "report"}
    assert set(rec["times"]) == {"tangential:damper", "loop", "frf:30N"}
    from contact_core.curve import read_curve

    curve = read_curve(rec["outputs"]["virgin_curve"])
    assert curve.T[-1] == pytest.approx(curve.mu * curve.N, rel=1e-12)     # ends at gross slip
    prov = json.loads((out / "frf_30N" / "result.json").read_text())["provenance"]
    assert prov["from_cache"] and prov["scene_hash"] == first.scene.hash()
    assert prov["inputs"]["structure"]["zeta"] == 0.002 and len(prov["code_version"]) == 16
    assert rec["provenance"]["git"]["commit"] is None or len(rec["provenance"]["git"]["commit"]) == 40


def test_structure_from_a_matrices_file_equals_the_bundled_model(small_run, tmp_path):
    import math

    import numpy as np

    store, out, first = small_run
    M, K = np.diag([0.5, 0.05]), np.array([[4e7, -4e7], [-4e7, 8e7]])
    beta = 2 * 0.002 / math.sqrt(min(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    np.savez(tmp_path / "blade.npz", M=M, K=K, C=beta * K, force=np.array([1.0, 0.0]), response_dof=0)
    structure = ('[structure]\nmodel = "matrices"\nmatrices = "blade.npz"\nelement_dofs = [1]\n')
    head, tail = TEXT.split("[structure]")
    text = head + structure + tail[tail.index("[excitation]"):]
    scene = parse_scene(text, "m.toml", base=tmp_path)
    rec = run_scene(scene, store, tmp_path / "out", **QUIET)
    assert rec.computed == ["frf:x30"]                   # the element and curve come from the cache
    assert rec.results["frf:x30"].data["peak_amplitude"] == first.results["frf:30N"].data["peak_amplitude"]
    np.savez(tmp_path / "blade.npz", M=M, K=K, C=2 * beta * K, force=np.array([1.0, 0.0]), response_dof=0)
    again = plan_scene(parse_scene(text, "m.toml", base=tmp_path), store)
    assert plan_actions(again)["frf:x30"] == "compute"   # new file content, new key
    with pytest.raises(ValueError, match=r"m.toml:\d+: structure.matrices: cannot read"):
        parse_scene(text, "m.toml", base=tmp_path / "elsewhere")


def test_a_loop_amplitude_above_mu_n_is_refused_before_any_stage_by_key_and_line(small_run, tmp_path, capsys):
    store, _, _ = small_run
    bad = tmp_path / "bad.toml"
    bad.write_text(TEXT.replace("loop_force_amplitude = 40.0", "loop_force_amplitude = 70.0"))  # mu N = 60 N
    writes = len(store.entries())
    code = damper(["run", str(bad), "--out", str(tmp_path / "out"), "--cache-dir", str(store.folder)])
    err = capsys.readouterr().err
    assert code == 2 and "bad.toml:16: element.loop_force_amplitude: 70 N is not below the gross-slip force" in err
    assert "Traceback" not in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists() and len(store.entries()) == writes   # nothing written
