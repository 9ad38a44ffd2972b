"""The blade and damper FMUs under our own C importer, plain and under valgrind.

``fmu_src/fmi/test_model_harness.c`` loads an FMU's FMI 2 and FMI 3 binaries side by
side and drives them through the C API: the versions agree to the bit, refused calls
(NaN and infinite inputs among them) leave the serialized state byte-identical, rollback
and deserialization into a fresh instance continue bit-identically, corrupted states are
refused, Reset repeats the run, truncated or non-finite resources are refused at
instantiation. Under valgrind's memcheck an invalid access, a use of uninitialised
memory or a definite leak fails the run (the friction FMUs' harnesses do the same in
ctest).

These FMUs come from Python (the blade's modal decomposition, the damper's prestress,
a variable table generated per FMU), so the harness is compiled here against the table
each FMU carries (its ``sources/fmu_vars.h``), with ``-Werror``, from the session's
FMUs (``part_fmus``) instead of in the CMake build.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description

from fmu_src import fmu_build

HARNESS_SOURCES = ("test_model_harness.c", "harness_api.c")
#: Steps of the drive and their size [s]: 300 steps of 10 us, 1.3 periods at FREQUENCY,
#: 3 to 4 of the damper's substeps each (its stability limit is ~3.2 us).
STEPS, H = 300, 1.0e-5
#: Frequency of the drive [Hz], near the sector's first blade-mode peak (~448 Hz).
FREQUENCY = 440.0
#: Drive amplitudes by unit: platform and neighbour motion of 2 um, beyond the contacts'
#: slip distance (mu N / k_t ~ 0.4 um at the prestress) and their penetration (~0.6 um),
#: so the damper sticks, slips and lifts off; forces half the prestress contact force
#: (60 N). Rate inputs (``*_rate``, ``v_*``) are the derivatives of their partners.
AMPLITUDE = {"m": 2.0e-6, "N": 30.0}
#: Parameters are set to this fraction of their start values (set in Initialization Mode).
PARAMETER_FACTOR = 0.9
VALGRIND = ("valgrind", "--error-exitcode=1", "--leak-check=full",
            "--errors-for-leak-kinds=definite", "-q")


def _partner(name: str) -> str:
    """The input whose derivative ``name`` is (``F_x_rate`` -> ``F_x``, ``v_a`` -> ``q_a``)."""
    if name.endswith("_rate"):
        return name[: -len("_rate")]
    if name.startswith("v_"):
        return "q_" + name[2:]
    raise ValueError(f"input {name} has no unit with a drive amplitude and no partner")


def drive_text(md) -> str:
    """The harness's drive file for the FMU of model description ``md``: sinusoids about
    every input's start value (a phase each), rate inputs consistent with their partners."""
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    params = [v for v in md.modelVariables if v.causality == "parameter"]
    w, t = 2 * np.pi * FREQUENCY, H * np.arange(STEPS)
    waves = {v.name: (float(v.start), AMPLITUDE[v.unit], 0.7 * i)
             for i, v in enumerate(inputs) if v.unit in AMPLITUDE}
    cols = []
    for v in inputs:
        if v.name in waves:
            x0, a, phase = waves[v.name]
            cols.append(x0 + a * np.sin(w * t + phase))
        else:
            _, a, phase = waves[_partner(v.name)]
            cols.append(a * w * np.cos(w * t + phase))
    rows = np.column_stack(cols)
    lines = ["damper-drive 1", f"h {H!r}", f"parameters {len(params)}"]
    lines += [f"{v.name} {PARAMETER_FACTOR * float(v.start)!r}" for v in params]
    lines += [f"inputs {len(inputs)} " + " ".join(v.name for v in inputs), f"steps {STEPS}"]
    lines += [" ".join(repr(float(x)) for x in row) for row in rows]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module", params=["blade", "damper"])
def harness(request, part_fmus, tmp_path_factory):
    """(command without the runner, scratch dir) of one model's harness."""
    model = request.param
    root = tmp_path_factory.mktemp(f"harness_{model}")
    dirs = []
    for v in (2, 3):
        d = root / f"fmi{v}"
        with zipfile.ZipFile(part_fmus[model, v]) as z:
            z.extractall(d)
        dirs.append(d)
    exe = root / "fmu_model_harness"
    cc = os.environ.get("CC", "cc")
    fmi = fmu_build.FMI_DIR
    cmd = [cc, *fmu_build.shared_cflags(), "-Werror", f"-I{dirs[0] / 'sources'}", f"-I{fmi}",
           f"-I{fmi / 'headers'}", *[str(fmi / s) for s in HARNESS_SOURCES], "-o", str(exe),
           "-ldl", "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    drive = root / "drive.txt"
    drive.write_text(drive_text(read_model_description(str(part_fmus[model, 2]))))
    return [str(exe), str(dirs[0]), str(dirs[1]), str(drive)], root


def _run(cmd: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600)


def test_harness(harness):
    cmd, root = harness
    proc = _run([*cmd, str(root / "scratch")])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert ", 0 failures" in proc.stdout


def test_harness_under_valgrind(harness):
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind not installed: the memory check of the blade and damper FMUs "
                    "did not run")
    cmd, root = harness
    proc = _run([*VALGRIND, *cmd, str(root / "scratch_valgrind")])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert ", 0 failures" in proc.stdout
