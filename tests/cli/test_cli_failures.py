"""Failures of the ``damper`` command as a program reading its output sees them: with
``--json`` one JSON object on stdout (the error and the exit code) besides the one line on
stderr; two outputs naming one path refused before anything is written."""
import json

import pytest

from damper.cli import main as damper
from damper.stress import input_fixtures as fx

CURVE = fx.curves()["curve.json"]


@pytest.fixture
def curve(tmp_path):
    path = tmp_path / "c.json"
    path.write_text(CURVE)
    return str(path)


def _stderr_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_json_refusal_prints_one_error_object_with_the_message_and_exit_code(curve, capsys):
    code = damper(["loop", "--curve", curve, "--amplitude", "2e-6", "--N", "nan", "--json"])
    out, err = capsys.readouterr()
    assert code == 2
    assert json.loads(out) == {"error": _stderr_line(err), "exit_code": 2}


def test_json_command_line_refusal_prints_one_error_object(curve, capsys):
    with pytest.raises(SystemExit) as stop:
        damper(["loop", "--curve", curve, "--amplitude", "2e-6", "--json", "--wobble"])
    out, err = capsys.readouterr()
    assert stop.value.code == 2
    obj = json.loads(out)
    assert obj["exit_code"] == 2 and obj["error"] == _stderr_line(err) and "--wobble" in obj["error"]


def test_refusal_without_json_prints_nothing_on_stdout(curve, capsys):
    assert damper(["loop", "--curve", curve, "--amplitude", "2e-6", "--N", "nan"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and "--N" in _stderr_line(err)


def test_json_error_object_after_an_earlier_command_of_the_same_process(curve, capsys):
    assert damper(["loop", "--curve", curve, "--amplitude", "2e-6", "--json"]) == 0
    capsys.readouterr()
    assert damper(["loop", "--curve", curve, "--amplitude", "2e-6", "--N", "-1", "--json"]) == 2
    assert json.loads(capsys.readouterr().out)["exit_code"] == 2


@pytest.mark.parametrize("first, second", [("--out", "--normal-curve"), ("--out", "--plot")])
def test_two_outputs_naming_one_path_are_refused_before_any_work(tmp_path, monkeypatch, capsys, first, second):
    monkeypatch.chdir(tmp_path)
    code = damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "100", "--grid", "5",
                   "--model", "halfspace", "--no-cache", first, "r.json", second, "./r.json"])
    assert code == 2
    assert "same path" in _stderr_line(capsys.readouterr().err)
    assert list(tmp_path.iterdir()) == []


def test_frequency_below_the_static_limit_is_refused_with_the_limit(capsys):
    from damper.limits import MIN_OMEGA

    code = damper(["frf", "--model", "sdof", "--mass", "1", "--stiffness", "1", "--damping", "0.01",
                   "--contact-stiffness", "1", "--slip-force", "0.05", "--force", "0.05", "--omega", "1e-300", "1"])
    assert code == 2
    assert f"below the limit {MIN_OMEGA:g} rad/s" in _stderr_line(capsys.readouterr().err)


@pytest.mark.parametrize("option", ["--cf", "--f0"])
@pytest.mark.parametrize("value", ["1e300", "1e-160"])
def test_upd_load_beyond_the_magnitude_limits_is_refused_not_failed(option, value, capsys):
    """1e300 N overflowed in the harmonic balance (exit 3 with advice about harmonics); 1e-160 N
    underflowed the energy per cycle to zero (a traceback dividing by it)."""
    from damper.limits import MAX_MAGNITUDE, MIN_LOAD

    assert damper(["upd", "frf", option, value, "--points", "5"]) == 2
    assert f"in [{MIN_LOAD:g}, {MAX_MAGNITUDE:g}] N" in _stderr_line(capsys.readouterr().err)


def test_config_bound_is_printed_as_a_number_not_its_digits(tmp_path, capsys):
    cfg = tmp_path / "u.toml"
    cfg.write_text("[blade]\nbeta = 1e300\n")
    assert damper(["upd", "modes", "--config", str(cfg)]) == 2
    line = _stderr_line(capsys.readouterr().err)
    assert "blade.beta: must be less than or equal to 1e+100" in line and "0000000000" not in line


@pytest.mark.parametrize("extra, option", [(["--N", "1e300", "--scale", "1e300"], "--N"),
                                           (["--N", "1e-300"], "--N"), (["--scale", "1e300"], "--scale")])
def test_loop_normal_load_and_friction_scale_outside_their_range_are_refused(curve, capsys, extra, option):
    """N and the scale multiply every slip force: 1e300 each overflowed into a JSON encoding error."""
    assert damper(["loop", "--curve", curve, "--amplitude", "2e-6", *extra]) == 2
    line = _stderr_line(capsys.readouterr().err)
    assert line.startswith(f"damper loop: error: {option} ") and "is outside [" in line


def test_a_non_finite_result_is_a_solver_failure_naming_its_key():
    from damper.cli.common import dumps

    with pytest.raises(RuntimeError, match=r"loop\.T\[1\] is not a finite number"):
        dumps({"N": 1.0, "loop": {"T": [0.0, float("inf")]}})
