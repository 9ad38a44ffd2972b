"""UPD config: defaults, overrides, refused input (CLI exit 2, no traceback)."""
import pytest
from failure_output import no_result

from damper.cli import main
from harmonic_balance.bladed_disk.config import load_config


def test_default_numbers():
    cfg = load_config()
    assert (cfg.blades, cfg.engine_order, cfg.ring_blades) == (24, 6, 4)
    pts = cfg.contact_points()
    assert [p.kn for p in pts] == [1e8, 5e7, 5e7]
    assert [p.kt for p in pts] == pytest.approx([8e7, 4e7, 4e7])


def test_override_and_unknown_key(tmp_path):
    f = tmp_path / "u.toml"
    f.write_text("[load]\ncf = 60.0\n")
    assert load_config(f).cf == 60.0
    f.write_text("[load]\ncff = 60.0\n")
    with pytest.raises(ValueError, match="load.cff: unknown key"):
        load_config(f)
    f.write_text("[damper]\nmu = -1\n")
    with pytest.raises(ValueError, match="damper.mu"):
        load_config(f)


@pytest.mark.parametrize("argv", [["frf", "--cf", "-1"], ["frf", "--band", "500", "400"],
                                  ["modes", "--config", "/nonexistent.toml"],
                                  ["optimize", "--cf-range", "100", "10"]])
def test_cli_refuses_bad_input(argv, capsys):
    assert main(["upd", *argv]) == 2
    cap = capsys.readouterr()
    assert "error" in cap.err and no_result(cap.out, cap.err, 2)


def test_upd_file_bounds_the_blades_as_the_mistuned_ring_does():
    """disk.blades in a UPD file is bounded like `upd mistuning --blades` (the same ring)."""
    from damper.limits import MAX_RING_BLADES
    from harmonic_balance.bladed_disk.config_model import MAX_BLADES

    assert MAX_BLADES == MAX_RING_BLADES
