"""The backbone stage kind: planned only when wanted, no contact or FE stage with a Jenkins
element, the contact stages when the element comes from a contact; checked against the
stuck and free linear modes of the 2-DOF model."""
import numpy as np
import pytest
from apphelpers import SMALL, plan_actions

from damper.cache import Store
from damper.run.runner import plan_scene, run_scene
from damper.scene import SceneError, parse_scene

QUIET = {"echo": lambda text: None}
#: Relative gap between the first backbone point (a = 1e-7, stuck) and the stuck linear
#: eigenfrequency: measured 6e-7 (harmonic balance at H = 1 and the continuation tolerance).
STUCK_RTOL = 1e-6
#: Same for the damping ratio against the stuck mode's modal damping ratio: measured 1.6e-6.
DAMPING_RTOL = 2.5e-6
KT, FS = 3.85e7, 60.0
JENKINS = f"""
[backbone]
element = "jenkins"
contact_stiffness = {KT}
slip_force = {FS}
amplitude = [1.0e-7, 1.0e-4]
harmonics = 1
"""
ONLY_BACKBONE = SMALL.read_text().replace(
    'want = ["virgin_curve", "k_t", "loop", "frf", "report"]', 'want = ["backbone"]') + JENKINS


M = np.diag([0.5, 0.05])
K = np.array([[4e7, -4e7], [-4e7, 8e7]])          # the small scene's structure, element removed


def _mode1(kt: float) -> tuple[float, np.ndarray]:
    """First eigenfrequency [rad/s] and mode of the 2-DOF model with kt on the platform."""
    w2, phi = np.linalg.eig(np.linalg.solve(M, K + np.diag([0.0, kt])))
    i = int(np.argmin(w2.real))
    return float(np.sqrt(w2[i].real)), phi[:, i].real


def _omega1(kt: float) -> float:
    return _mode1(kt)[0]


def _stuck_damping_ratio(zeta: float = 0.002) -> float:
    """Modal damping ratio of the stuck mode under the scene's Rayleigh C = beta K, beta =
    2 zeta / omega_1(free): phi^T C phi / (2 omega phi^T M phi)."""
    beta = 2 * zeta / _omega1(0.0)
    w, phi = _mode1(KT)
    return float(phi @ (beta * K) @ phi / (2 * w * phi @ M @ phi))


@pytest.mark.slow                                           # ~5 s: one EPMC backbone
def test_only_backbone_runs_no_contact_fe_element_or_frf_stage(tmp_path):
    scene = parse_scene(ONLY_BACKBONE)
    store = Store(tmp_path)
    rec = run_scene(scene, store, tmp_path / "out", **QUIET)
    assert rec.computed == ["backbone"]
    acts = plan_actions(rec.plan)
    for name in ("condense:damper:zx", "tangential:damper", "loop", "fmu:fmi2", "frf:30N"):
        assert acts[name] == "skip", name
    bb = rec.results["backbone"].data
    assert bb["status"] == "complete"
    w = np.asarray(bb["omega"])
    assert w[0] == pytest.approx(_omega1(KT), rel=STUCK_RTOL)
    # slipping lowers the frequency towards the mode without the element, never below it
    assert _omega1(0.0) < w[-1] < w[0]
    d = np.asarray(bb["damping_ratio"])
    assert d[0] == pytest.approx(_stuck_damping_ratio(), rel=DAMPING_RTOL)
    assert d.max() > 10 * d[0] and d[-1] < d.max()           # friction damping rises and falls
    te = bb["truncation_error"]   # the estimate re-solves points with more harmonics
    assert te["H_check"] > te["H_used"] and len(te["points"]) >= 2 and te["omega_rel"] is not None
    assert (tmp_path / "out" / "backbone" / "backbone.png").stat().st_size > 0
    again = run_scene(scene, store, tmp_path / "out", **QUIET)
    assert again.computed == []


def test_backbone_with_the_contact_element_plans_the_contact_stages(tmp_path):
    text = SMALL.read_text().replace('want = ["virgin_curve", "k_t", "loop", "frf", "report"]',
                                     'want = ["backbone"]') + "\n[backbone]\namplitude = [1e-7, 1e-4]\n"
    plan = plan_scene(parse_scene(text), Store(tmp_path))
    acts = plan_actions(plan)
    assert acts["backbone"] == acts["tangential:damper"] == acts["condense:damper:zx"] == "compute"
    assert "condense:damper:z" not in acts and "normal:damper" not in acts   # no normal result wanted
    assert acts["loop"] == acts["frf:30N"] == "skip"
    assert plan.stages[[s.name for s in plan.stages].index("backbone")].deps == ("tangential:damper",)


@pytest.mark.parametrize("edit, key, words", [
    (("slip_force = 60.0\n", ""), "backbone.slip_force", "missing"),
    (("amplitude = [1.0e-7, 1.0e-4]", "amplitude = [1.0e-4, 1.0e-7]"), "backbone.amplitude", "end > start"),
    (('element = "jenkins"', 'element = "spring"'), "backbone.element", "must be one of"),
    (("harmonics = 1\n", "harmonics = 1\naccuracy = 0.5\n"), "backbone.accuracy", "must be < 0.5"),
])
def test_malformed_backbone_table_names_the_key(edit, key, words):
    text = ONLY_BACKBONE.replace(*edit)
    assert text != ONLY_BACKBONE
    with pytest.raises(SceneError) as err:
        parse_scene(text, "bad.toml")
    assert f"{key}: " in str(err.value) and words in str(err.value), str(err.value)


def test_backbone_without_structure_or_backbone_table_is_refused():
    with pytest.raises(SceneError) as err:
        parse_scene("want = [\"backbone\"]\n" + JENKINS, "bad.toml")
    assert "structure: missing: needed for backbone" in str(err.value)
    with pytest.raises(SceneError) as err:
        parse_scene(ONLY_BACKBONE.replace(JENKINS, ""), "bad.toml")
    assert "backbone: missing: needed for backbone" in str(err.value)


def test_example_backbone_scene_parses_and_plans_one_stage(tmp_path):
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "backbone.toml"
    plan = plan_scene(parse_scene(path.read_text(), str(path)), Store(tmp_path))
    assert [s.name for s in plan.stages if s.action == "compute"] == ["backbone"]


#: Target of the scene's backbone run to an accuracy: the Jenkins backbone's H = 3 start
#: misses it (measured), so H is raised at least once.
BB_TARGET = 1e-3


@pytest.mark.slow                                           # ~5-10 s: two or three EPMC backbones
def test_backbone_accuracy_in_a_scene_raises_h_until_both_estimates_meet_it(tmp_path):
    scene = parse_scene(ONLY_BACKBONE.replace("harmonics = 1\n", f"harmonics = 1\naccuracy = {BB_TARGET}\n"))
    rec = run_scene(scene, Store(tmp_path), tmp_path / "out", **QUIET)
    bb = rec.results["backbone"].data
    te = bb["truncation_error"]
    a = te["accuracy"]
    assert a["target"] == BB_TARGET and a["met"] and a["H_sequence"][-1] == te["H_used"] == bb["harmonics"]
    assert max(te["omega_rel"], te["damping_ratio_rel"]) <= BB_TARGET
    assert a["H_sequence"][0] >= 3   # the start is raised to MIN_START_HARMONIC
    lines = scene_kind_lines(rec, "backbone")
    assert any(f"accuracy {BB_TARGET:g}: met" in line for line in lines), lines
    assert len(a["H_sequence"]) >= 2 and a["message"] is None   # measured: H = 3, 8, 20


def scene_kind_lines(rec, name):
    """The printed lines of the stage ``name`` of a run record."""
    stage = next(s for s in rec.plan.stages if s.name == name)
    return stage.kind.lines(stage, rec.results[name])
