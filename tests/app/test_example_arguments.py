"""The example scripts are commands: a bad argument is one line on stderr and exit 2
before any work, a refused input or an unwritable output from the libraries too, never a
traceback (damper.script)."""
import argparse
import subprocess
import sys
from pathlib import Path

import pytest

from damper.script import count, numbers, out_folder, run

ROOT = Path(__file__).resolve().parents[2]


def test_count_takes_integers_at_its_bound_and_refuses_below_or_text():
    assert count(3)("3") == 3
    for text in ("2", "-1", "abc", "1.5"):
        with pytest.raises(argparse.ArgumentTypeError):
            count(3)(text)


def test_numbers_parses_a_comma_list_and_refuses_text_nan_and_values_below_the_bound():
    assert numbers(int, 1)("1,3") == [1, 3]
    assert numbers(float)("1e5,2.5") == [1e5, 2.5]
    for text in ("abc", "1,,2", "nan", "0,1"):
        with pytest.raises(argparse.ArgumentTypeError):
            numbers(int if text != "nan" else float, 1)(text)


def test_out_folder_refuses_an_existing_file_and_takes_a_new_or_existing_folder(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(argparse.ArgumentTypeError):
        out_folder(str(tmp_path / "f"))
    assert out_folder(str(tmp_path)) == tmp_path
    assert out_folder(str(tmp_path / "new")) == tmp_path / "new"


@pytest.mark.parametrize(("error", "code", "word"), [(ValueError("bad grid"), 2, "error"),
                                                      (FileNotFoundError(2, "No such file", "x.json"), 2, "error"),
                                                      (RuntimeError("no convergence"), 3, "failed")])
def test_run_maps_a_refusal_to_one_line_and_its_exit_code(error, code, word, capsys):
    def main():
        raise error
    assert run(main) == code
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f": {word}: " in err[0]


def test_run_returns_main_s_code_and_zero_for_a_result():
    assert run(lambda: 4) == 4
    assert run(lambda: {"peak": 1.0}) == 0


@pytest.mark.parametrize("argv", [["bench_element.py", "--samples", "0"],
                                  ["bench_fmu.py", "--sliders", "abc"],
                                  ["cylinder_approach.py", "--grid", "1"],
                                  ["masing_loops.py", "--smoke", "--out", "{file}"],
                                  ["mistuning_confidence.py", "--quick", "--samples", "0"]])
def test_an_example_given_a_bad_argument_exits_2_with_one_line(argv, tmp_path):
    (tmp_path / "a_file").write_text("x")
    argv = [a.replace("{file}", str(tmp_path / "a_file")) for a in argv]
    p = subprocess.run([sys.executable, str(ROOT / "examples" / argv[0]), *argv[1:]], cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2
    assert "Traceback" not in p.stderr
    assert p.stderr.strip().splitlines()[-1].startswith(f"{argv[0]}: error: ")
    assert not (tmp_path / "out").exists()
