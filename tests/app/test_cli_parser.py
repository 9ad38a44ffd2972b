"""The ``damper`` command line: parser errors are one line, negative numbers are values."""
import pytest

from damper.cli import SUBCOMMANDS, build_parser
from damper.cli import main as damper


def _parser_error(capsys, argv):
    with pytest.raises(SystemExit) as info:
        damper(argv)
    err = capsys.readouterr().err
    return info.value.code, err


@pytest.mark.parametrize("command", [[name] for name in SUBCOMMANDS] + [["upd", "mistuning"], ["upd", "frf"],
                                                                          ["cache", "clear"]])
def test_a_parser_error_is_one_line_naming_the_command(capsys, command):
    code, err = _parser_error(capsys, [*command, "--no-such-option"])
    assert code == 2
    assert len(err.splitlines()) == 1 and "usage:" not in err
    prog = "damper " + " ".join(command) if command != ["cache", "clear"] else "damper cache"
    assert err.startswith(f"{prog}: error: ") and f"(see {prog} --help)" in err


@pytest.mark.parametrize("argv, words", [
    (["upd", "mistuning", "--seed", "1.5"], "invalid int value: '1.5'"),
    ([], "required: COMMAND"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
])
def test_a_bad_value_or_missing_command_is_one_line(capsys, argv, words):
    code, err = _parser_error(capsys, argv)
    assert code == 2 and len(err.splitlines()) == 1 and words in err


@pytest.mark.parametrize("text", ["-5e7", "-5E+7", "-1e-3", "-.5", "-2.", "-7", "-inf"])
def test_a_negative_number_is_read_as_a_value(text):
    args = build_parser().parse_args(["fmu", "--curve", "c.json", "-o", "d.fmu", "--k-n", text])
    assert args.k_n == float(text)


def test_a_negative_stiffness_reaches_the_range_check(tmp_path, capsys):
    from damper.stress.input_fixtures import make

    fx = make(tmp_path / "fx")
    code = damper(["fmu", "--curve", str(fx / "curve.json"), "-o", str(tmp_path / "d.fmu"), "--k-n", "-5e7"])
    err = capsys.readouterr().err
    assert code == 2 and "--k-n must be finite and > 0" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "d.fmu").exists()
