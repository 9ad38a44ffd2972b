"""docs/tools/record.py: the recorded command names no folder of the machine it ran on."""
import importlib.util
import json
import shlex
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[2] / "docs" / "tools"


@pytest.fixture
def record():
    spec = importlib.util.spec_from_file_location("record", TOOLS / "record.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_paths_inside_the_repository_are_relative_and_outside_ones_named(record, tmp_path):
    root = tmp_path / "repo"
    command = [f"{root}/.venv/bin/damper", "bench", "--pyharm", "/opt/peers/pyharm/bin/python",
               f"--nlvib={tmp_path}/NLvib", "--out", "out/bench", f"{root}/docs/../out/x.json", "/tmp/y", "0.5"]
    assert record.portable(command, root) == [
        ".venv/bin/damper", "bench", "--pyharm", "PYHARM", "--nlvib=NLVIB", "--out", "out/bench",
        "out/x.json", "PATH", "0.5"]


def test_the_committed_data_names_no_folder_of_a_machine(record):
    for path in sorted((TOOLS.parent / "data").glob("*.json")):
        command = json.loads(path.read_text()).get("command", "")
        assert not any(arg.startswith("/") or "=/" in arg for arg in shlex.split(command)), (path.name, command)
