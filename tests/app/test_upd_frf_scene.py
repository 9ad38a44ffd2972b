"""The upd_frf stage kind: the UPD sector's forced response at one CF, the record of ``damper upd frf``."""
import json

import numpy as np
import pytest

from damper.cache import Store
from damper.cli import main
from damper.run.runner import run_scene
from damper.scene import SceneError, parse_scene
from harmonic_balance.surface import MAX_NODES, MIN_NODES

QUIET = {"echo": lambda text: None}

#: The stage and the command solve the same model from the same start with the same code:
#: every number of the record agrees to round-off (measured: bit-identical).
ROUND_OFF = 1e-12

#: Keys of the record that measure the run, not the result.
TIMINGS = ("time_s", "cpu_s", "truncation_check_cpu_s")

UPD = "want = [\"upd_frf\"]\n[upd]\nharmonics = 1\ngrid = 5\nband = [440.0, 480.0]\ncf = 150.0\n"


def _without_timings(value):
    if isinstance(value, dict):
        return {k: _without_timings(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [_without_timings(v) for v in value]
    return value


def _assert_same(a, b, path=""):
    """Equal structure, strings and None; numbers within ROUND_OFF."""
    if isinstance(a, dict):
        assert sorted(a) == sorted(b), path
        for k in a:
            _assert_same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _assert_same(x, y, f"{path}[{i}]")
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        assert np.isclose(a, b, rtol=ROUND_OFF, atol=0.0), (path, a, b)
    else:
        assert a == b, (path, a, b)


def test_scene_result_is_the_record_of_upd_frf_with_the_same_options(tmp_path, capsys):
    scene, store = parse_scene(UPD), Store(tmp_path / "cache")
    rec = run_scene(scene, store, tmp_path / "out", **QUIET)
    assert rec.computed == ["upd_frf"]
    stage = rec.results["upd_frf"].data
    assert main(["upd", "frf", "--harmonics", "1", "--points", "5", "--band", "440", "480", "--cf", "150",
                 "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    _assert_same(_without_timings(cli), _without_timings(stage))
    written = json.loads((tmp_path / "out" / "upd_frf" / "result.json").read_text())["data"]
    _assert_same(_without_timings(written), _without_timings(stage))
    assert (tmp_path / "out" / "upd_frf" / "upd_frf.png").stat().st_size > 0
    assert run_scene(scene, store, tmp_path / "out", **QUIET).computed == []   # cached


def test_scalars_and_lines_are_the_records_peak(tmp_path):
    from damper.run.upd_frf_stages import UPDFRF

    rec = run_scene(parse_scene(UPD), Store(tmp_path / "cache"), tmp_path / "out", **QUIET)
    stage, result = rec.plan["upd_frf"], rec.results["upd_frf"]
    o, sc = result.data, UPDFRF().scalars(stage, result)
    assert (sc["peak_frequency_Hz"], sc["peak_amplitude_m"]) == (o["peak_frequency_hz"], o["peak_amplitude"])
    assert sc["harmonics_H"] == 1 and sc["truncation_error_rel"] == o["truncation_error"]["peak_amplitude_rel"]
    assert f"{o['peak_frequency_hz']:.4f} Hz" in UPDFRF().lines(stage, result)[0]


@pytest.mark.parametrize("edit, key, words", [
    ("surface_nodes = 7\n", "upd.surface_nodes", 'goes with contacts = "surface"'),
    ('surface_model = "nodes"\n', "upd.surface_model", 'goes with contacts = "surface"'),
    (f'contacts = "surface"\nsurface_nodes = {MIN_NODES - 1}\n', "upd.surface_nodes", f"must be >= {MIN_NODES}"),
    (f'contacts = "surface"\nsurface_nodes = {MAX_NODES + 1}\n', "upd.surface_nodes", f"must be <= {MAX_NODES}"),
    ('contacts = "surface"\naccuracy = 0.01\n', "upd.accuracy", "fixed harmonics"),
    ("band = [480.0, 440.0]\n", "upd.band", "high > low"),
    ("cf = 0.001\n", "upd.cf", "is below"),
])
def test_upd_frf_refusals_name_the_key(edit, key, words):
    given = {line.split(" =")[0] for line in edit.splitlines()}   # the edit replaces these keys
    text = "\n".join(line for line in UPD.splitlines() if line.split(" =")[0] not in given) + "\n" + edit
    with pytest.raises(SceneError) as err:
        parse_scene(text, "bad.toml")
    assert f"{key}: " in str(err.value) and words in str(err.value), str(err.value)


def test_node_dof_surfaces_in_optimal_load_are_refused():
    """optimal_load walks the loads with the condensed model (its unknowns the same at every load)."""
    with pytest.raises(SceneError) as err:
        parse_scene(UPD.replace('["upd_frf"]', '["optimal_load"]') + 'contacts = "surface"\nsurface_model = "nodes"\n',
                    "bad.toml")
    assert "upd.surface_model: " in str(err.value) and 'surface_model = "condensed"' in str(err.value)


#: The [upd] table of a surface optimal_load: UPD's keys but grid, which a surface walk refuses.
OPTIMAL_SURFACE = (UPD.replace('["upd_frf"]', '["optimal_load"]').replace("grid = 5\n", "")
                   + 'contacts = "surface"\n')


def test_surface_optimal_load_stage_key_holds_the_node_count():
    from damper.run.backbone_stages import OptimalLoad

    data = parse_scene(OPTIMAL_SURFACE).data
    (stage,) = OptimalLoad().instances(data)
    assert (stage.params["contacts"], stage.params["surface_nodes"], stage.params["surface_model"]) == \
        ("surface", 5, "condensed")


def test_a_grid_in_a_surface_optimal_load_is_refused_unless_upd_frf_uses_it():
    """The walk searches each peak by Brent's method (``upd optimize --contacts surface`` refuses
    --grid); with upd_frf wanted too the grid is that curve's."""
    with pytest.raises(SceneError) as err:
        parse_scene(OPTIMAL_SURFACE + "grid = 20\n", "bad.toml")
    assert "upd.grid: " in str(err.value) and "drop grid" in str(err.value), str(err.value)
    both = parse_scene(OPTIMAL_SURFACE.replace('["optimal_load"]', '["optimal_load", "upd_frf"]') + "grid = 20\n")
    assert both.data["upd"]["grid"] == 20
    assert "grid" in parse_scene(OPTIMAL_SURFACE).data["upd"]   # the default, not written: accepted


@pytest.mark.parametrize("edit, key, words", [
    ("cf_range = [300.0, 1e12]\n", "upd.cf_range", "outside [1e-06, 1e+09] N"),   # the geometry's load bound
    ('config = "upd_axial.toml"\n', "upd.contacts", "contacts = toml or geometry"),
])
def test_surface_optimal_load_faces_are_checked_at_load(tmp_path, edit, key, words):
    """The faces ``upd optimize --contacts surface`` checks before its walk (a planar sector, the
    geometry at both ends of the range), refused with the scene's keys before any stage."""
    from damper.stress.input_fixtures import upd_files

    for name, content in upd_files().items():
        (tmp_path / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(SceneError) as err:
        parse_scene(OPTIMAL_SURFACE + edit, "bad.toml", base=tmp_path)
    assert f"{key}: " in str(err.value) and words in str(err.value), str(err.value)


def _walk_that_stops(sector, surfaces_at, cf_range, points, H, f0=None, estimate=None, on_load=None, **kw):
    """A stand-in for surface_peak.optimal_load_surface: its estimate, two loads, then the stop
    warning (the walk's own text is tested in tests/upd/test_upd_surface_peak_search.py)."""
    estimate(1234, 600, 0.5)
    loads = [{"cf": cf, "peak_hz": 470.0, "peak_amplitude_h1": a, "nodes": 60, "evaluations": 100,
              "cpu_s": 10.0, "start": "stand-in"} for cf, a in ((3000.0, 5e-3), (1000.0, 4e-3))]
    for r in loads:
        on_load(r)
    return {"cf": [1000.0, 3000.0], "peak_amplitude": [4e-3, 5e-3], "peak_frequency_hz": [470.0, 470.0],
            "harmonics": H, "optimum_cf": 1000.0, "optimum_peak_amplitude": 4e-3, "method": "grid",
            "interior": False, "time_s": 1.0, "warning": "the walk stopped at 300 N (stand-in)",
            "surface_model": {"model": "condensed", "evaluations": 200, "cpu_s": 20.0, "time_s": 21.0,
                              "first_guess_hz": 470.0, "loads": loads}}


def test_surface_optimal_load_prints_the_estimate_the_loads_and_the_stop_warning(tmp_path, capsys, monkeypatch):
    """As ``upd optimize --contacts surface`` prints them: the estimate and a line per load on
    standard error while the stage runs, the stop warning among the stage's lines (again when
    the result comes from the cache)."""
    from harmonic_balance.bladed_disk import surface_peak

    monkeypatch.setattr(surface_peak, "optimal_load_surface", _walk_that_stops)
    scene = tmp_path / "s.toml"
    scene.write_text(OPTIMAL_SURFACE.replace("cf = 150.0\n", "") + "cf_range = [300.0, 3000.0]\npoints = 3\n")
    argv = ["run", str(scene), "--cache-dir", str(tmp_path / "cache"), "--out"]
    assert main(argv + [str(tmp_path / "out")]) == 0
    captured = capsys.readouterr()
    err = captured.err.splitlines()
    first = [i for i, line in enumerate(err) if "building the faces at 5 nodes per side" in line]
    estimate = [i for i, line in enumerate(err) if "about 1234 residual evaluations" in line
                and "~5 min more if the optimum lies inside" in line]
    loads = [i for i, line in enumerate(err) if line.startswith("  CF 3000 N: peak 470.000 Hz")]
    assert first and estimate and loads and first[0] < estimate[0] < loads[0], captured.err
    assert "   warning: the walk stopped at 300 N (stand-in)" in captured.out.splitlines(), captured.out
    assert "2 loads searched, 200 evaluations" in captured.out
    assert main(argv + [str(tmp_path / "again")]) == 0
    again = capsys.readouterr()
    assert "about 1234" not in again.err and "warning: the walk stopped at 300 N" in again.out


def test_surface_defaults_are_filled_in_for_the_stage_key():
    u = parse_scene(UPD + 'contacts = "surface"\n').data["upd"]
    assert (u["surface_nodes"], u["surface_model"]) == (5, "condensed")


def test_run_of_a_refused_scene_exits_2_with_one_line(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(UPD + "surface_nodes = 7\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "upd.surface_nodes" in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


def test_contacts_errors_of_the_model_are_refused_at_load(tmp_path):
    (tmp_path / "mu0.toml").write_text("[damper]\nmu = 0.0\n")
    text = UPD + 'config = "mu0.toml"\ncontacts = "surface"\n'
    with pytest.raises(SceneError) as err:
        parse_scene(text, "bad.toml", base=tmp_path)
    assert "upd.contacts: " in str(err.value) and "mu > 0" in str(err.value), str(err.value)


@pytest.mark.slow   # ~40 s CPU each run (the path in CF from the open load, 43 evaluations at 109 nodes)
def test_surface_scene_result_is_the_record_of_upd_frf_contacts_surface(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cli_cache"))   # the command's condensations
    band = 'band = [400.0, 405.0]\ngrid = 3\ncontacts = "surface"\nsurface_nodes = 5\n'
    text = "\n".join(line for line in UPD.splitlines() if line.split(" =")[0] not in ("band", "grid", "cf"))
    rec = run_scene(parse_scene(text + "\n" + band), Store(tmp_path / "cache"), tmp_path / "out", **QUIET)
    stage = rec.results["upd_frf"].data
    assert stage["surface_model"]["nodes_per_side"] == 5 and stage["contact_points"] == ["left", "flat"]
    assert main(["upd", "frf", "--contacts", "surface", "--surface-nodes", "5", "--harmonics", "1",
                 "--points", "3", "--band", "400", "405", "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    _assert_same(_without_timings(cli), _without_timings(stage))
