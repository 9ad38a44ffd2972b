"""`make demo` end to end on a small scene: every stage runs and writes its results."""
import json

SMALL_SCENE = """
[contact]
body = "cylinder"
diameter = 5.0e-3
length = 1.2e-3
force = 120.0
mu = 0.5
grid = 7

[structure]
m_tip = 0.5
m_platform = 0.05
k_blade = 4.0e7
k_disk = 4.0e7
zeta = 0.002

[response]
forces = [100.0]
harmonics = 3
f_min = 880.0
f_max = 1300.0
loop_force_amplitude = 40.0
"""


def test_demo_runs_every_stage_on_a_small_scene(tmp_path, monkeypatch, load_example):
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cache"))
    demo = load_example("demo")
    scene = tmp_path / "scene.toml"
    scene.write_text(SMALL_SCENE)
    out = tmp_path / "out"
    assert demo.main(["--out", str(out), "--scene", str(scene)]) == 0
    summary = json.loads((out / "demo_summary.json").read_text())
    # the FMUs validate and dissipate energy; the FRF found a peak inside the sweep
    assert all(not v["problems"] and v["W_after_5_cycles"] > 0 for v in summary["fmu"].values())
    peak = summary["frf"]["100"]
    assert 2 * 3.141592653589793 * 880 < peak["peak_omega"] < 2 * 3.141592653589793 * 1300
    curve = json.loads((out / "curve.json").read_text())
    assert abs(curve["T"][-1] - curve["mu"] * curve["N"]) <= 1e-12 * curve["N"]  # ends at gross slip
    for name in ("normal/normal_validation.json", "damper_fmi2.fmu", "damper_fmi3.fmu", "frf_100N.json"):
        assert (out / name).exists(), name
