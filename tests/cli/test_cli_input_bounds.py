"""Options the command refuses with one line saying what to change (exit 2, nothing run),
and the edge values it accepts because it handles them right (a tuned mistuning study)."""
import json

import pytest

from damper import limits
from damper.cli import main as damper
from damper.cli.upd import flat_band_line
from damper.mistuning import Study

#: Amplification of a tuned ring (every blade alike) less one: every blade's peak is the
#: tuned peak. Linear limits: up to the round-off of the ring's solve against the sector's.
#: Friction damper: each peak comes from its own curve's refinement (Newton to |R| ~ 3e-9,
#: the peak frequency located to about 1e-8 relative; measured 1.9e-8 at H = 3).
TUNED_AMPLIFICATION_TOL = {"stuck": 1e-9, "nonlinear": 1e-6}

SDOF = ["--model", "sdof", "--mass", "1", "--stiffness", "1", "--damping", "0.01", "--contact-stiffness", "1",
        "--slip-force", "0.05", "--force", "0.05"]


def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_surface_nodes_without_surface_contacts_is_refused_with_the_option_to_add(capsys):
    assert damper(["upd", "frf", "--surface-nodes", "7", "--json"]) == 2
    out, err = capsys.readouterr()
    line = _one_line(err)
    assert "--contacts surface" in line and "--surface-nodes" in line
    assert json.loads(out) == {"error": line, "exit_code": 2}


@pytest.mark.parametrize("mb", [1e300, 1e-300, -1.0, float("nan")])
def test_cache_size_limit_outside_one_byte_to_one_pib_is_refused(tmp_path, capsys, mb):
    assert damper(["cache", "info", "--cache-dir", str(tmp_path / "c"), f"--cache-max-mb={mb}"]) == 2
    assert "--cache-max-mb" in _one_line(capsys.readouterr().err)
    assert not (tmp_path / "c").exists()


def test_cache_size_limit_in_range_is_that_many_mib():
    assert limits.cache_bytes("--cache-max-mb", 4096) == 4096 * 2**20
    assert limits.cache_bytes("--cache-max-mb", limits.MAX_CACHE_MB) == int(limits.MAX_CACHE_MB) * 2**20


def test_until_ci_wider_than_one_is_refused_and_one_is_accepted():
    with pytest.raises(ValueError, match="above 1"):
        Study(until_ci=1e300).check()
    Study(until_ci=limits.MAX_UNTIL_CI).check()


def test_zero_std_runs_the_tuned_disk_once_and_refuses_repeating_it():
    """std 0 draws all factors 1 for every sample: one sample is the tuned-disk check, more
    (or --until-ci, ~80 before its interval closes) would repeat it."""
    Study(std=0, samples=1).check()
    with pytest.raises(ValueError, match=r"--std 0 with 3 samples: .*--samples 1"):
        Study(std=0, samples=3).check()
    with pytest.raises(ValueError, match=r"--until-ci with --std 0: .*give --std > 0"):
        Study(std=0, samples=2000, until_ci=0.01).check()
    Study(std=0.02, samples=3).check()
    Study(std=0.02, samples=2000, until_ci=0.01).check()


def test_max_step_too_small_for_the_point_limit_names_both_options(capsys):
    assert damper(["frf", *SDOF, "--omega", "0.9", "1.3", "--max-step", "1e-300"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "--max-step" in line and "--max-points 2000" in line and f"{1 / 2000:.3g}" in line


def test_backbone_amplitude_above_the_magnitude_bound_is_refused(capsys):
    assert damper(["backbone", *SDOF, "--amplitude", "1e-3", "1e300"]) == 2
    assert "--amplitude" in _one_line(capsys.readouterr().err)


def test_cf_floor_is_a_fraction_of_the_eo_force():
    f0 = 30.0
    limits.check_cf_floor("--cf", limits.MIN_CF_PER_F0 * f0, f0, None)     # at the floor: accepted
    with pytest.raises(ValueError, match="--damper free"):
        limits.check_cf_floor("--cf", 0.5 * limits.MIN_CF_PER_F0 * f0, f0, None)


def test_upd_cf_below_the_floor_is_refused_before_any_work(capsys):
    assert damper(["upd", "frf", "--cf", "1e-3", "--points", "5"]) == 2
    assert "EO force" in _one_line(capsys.readouterr().err)
    assert damper(["upd", "optimize", "--cf-range", "1e-3", "10"]) == 2
    assert "--cf-range" in _one_line(capsys.readouterr().err)
    assert damper(["system", "--cf", "1e-3", "-o", "never_written.ssp"]) == 2   # its ring would rattle too
    assert "EO force" in _one_line(capsys.readouterr().err)


@pytest.mark.parametrize("damper_kind", ["stuck", "nonlinear"])
def test_tuned_study_std_zero_has_amplification_one(tmp_path, damper_kind):
    from damper.cache import Store
    from damper.mistuning import run_study

    study = Study(blades=4, engine_order=1, std=0.0, samples=1, damper=damper_kind, harmonics=3)
    out = run_study(study, Store(tmp_path / "c", max_bytes=10**9), serial=True, echo=lambda t: None)
    amps = [s["amplification"] for s in out["samples"]]
    assert out["failed"] == 0 and len(amps) == 1
    assert all(abs(a - 1.0) < TUNED_AMPLIFICATION_TOL[damper_kind] for a in amps), amps


def test_flat_band_end_outside_the_sweep_is_named_as_beyond_the_range():
    assert flat_band_line(None, (30.0, 3000.0)) is None
    assert flat_band_line([100.0, 200.0], (30.0, 3000.0)) == "peak within 1 % of the optimum for CF 100 ... 200 N"
    assert "below 30 ... 200" in flat_band_line([None, 200.0], (30.0, 3000.0))
    assert "100 ... above 3000" in flat_band_line([100.0, None], (30.0, 3000.0))
    assert "whole CF range" in flat_band_line([None, None], (100.0, 100.001))


@pytest.mark.parametrize("key, line", [("want", "want = []"), ("forces", "forces = []")])
def test_scene_empty_list_is_refused_naming_the_key(key, line):
    from damper.scene import schema

    table = schema.TOP if key == "want" else schema.EXCITATION
    assert "is empty" in schema.check_value(table[key], [])
    assert schema.check_value(table[key], ["frf"] if key == "want" else [30.0]) is None


def test_backbone_decreasing_amplitude_range_is_refused(capsys):
    assert damper(["backbone", *SDOF, "--amplitude", "1e-3", "1e-300"]) == 2
    assert "START < END" in _one_line(capsys.readouterr().err)


def test_output_folder_where_no_folder_can_be_made_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    import tempfile

    def read_only(*args, **kwargs):   # a read-only mount: the permission bits say yes, the write fails
        raise OSError(30, "Read-only file system")

    monkeypatch.setattr(tempfile, "mkdtemp", read_only)
    assert damper(["bench", "--quick", "--stage", "element", "--out", str(tmp_path / "b"), "--json"]) == 2
    out, err = capsys.readouterr()
    assert "read-only" in _one_line(err) and json.loads(out)["exit_code"] == 2
    assert list(tmp_path.iterdir()) == []


def test_surface_nodes_default_applies_only_with_surface_contacts():
    from argparse import Namespace

    from damper.cli.upd import SURFACE_NODES, check_surface_nodes

    with_surfaces = Namespace(contacts="surface", surface_nodes=None)
    check_surface_nodes(with_surfaces)
    assert with_surfaces.surface_nodes == SURFACE_NODES
    given = Namespace(contacts="surface", surface_nodes=9)
    check_surface_nodes(given)
    assert given.surface_nodes == 9
    without = Namespace(contacts="geometry", surface_nodes=None)
    check_surface_nodes(without)
    assert without.surface_nodes is None
