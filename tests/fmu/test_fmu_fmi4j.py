"""A third importer for the FMI 2 FMU: FMI4j (JVM, Maven Central
info.laht.fmi4j:fmi-import 0.38.0), driven by tests/fmu/fmi4j/Fmi4jCheck.java:
the array API's numbers, the directional derivative, bit-identical rollback.

Skipped when Java or Maven is missing or Maven cannot resolve the artifact.
FMI4j 0.38 passes an uninitialized FMUstate to fmi2GetFMUstate; the FMU copes
(it only reuses states it handed out), which this test exercises.
"""
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from fmu_helpers import N_CURVE, U_SLIP, curve_table

from fmu_src.element import IwanElement

HERE = Path(__file__).resolve().parent / "fmi4j"
#: Same C core and arithmetic: agreement to round-off.
EXACT_TOL = 1e-12
#: Maven may need to download FMI4j on a fresh machine.
MAVEN_TIMEOUT_S = 600


@pytest.fixture(scope="module")
def fmi4j_classpath(tmp_path_factory):
    if not all(shutil.which(t) for t in ("java", "javac", "mvn")):
        pytest.skip("FMI4j check needs java, javac and mvn")
    out = tmp_path_factory.mktemp("fmi4j")
    cp_file = out / "cp.txt"
    proc = subprocess.run(["mvn", "-q", "-B", "-f", str(HERE / "pom.xml"),
                           "dependency:build-classpath", f"-Dmdep.outputFile={cp_file}"],
                          capture_output=True, text=True, timeout=MAVEN_TIMEOUT_S)
    if proc.returncode != 0 or not cp_file.exists():
        pytest.skip(f"Maven could not resolve FMI4j: {proc.stdout[-500:]}")
    classes = out / "classes"
    subprocess.run(["javac", "-d", str(classes), "-cp", cp_file.read_text().strip(),
                    str(HERE / "Fmi4jCheck.java")], check=True)
    return f"{classes}:{cp_file.read_text().strip()}"


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_fmi4j_equals_array_api(fmus, fmi4j_classpath, tmp_path):
    k = np.arange(150)
    u = 1.3 * U_SLIP * np.sin(0.21 * k) * (1.0 + 0.4 * np.sin(0.9 * k))
    N = N_CURVE * (1.0 + 0.25 * np.sin(0.13 * k))
    lines = (f"{float(a)!r} {float(b)!r}\n" for a, b in zip(u, N))
    (tmp_path / "in.txt").write_text("".join(lines))
    subprocess.run(["java", "-cp", fmi4j_classpath, "Fmi4jCheck", str(fmus[2]),
                    str(tmp_path / "in.txt"), str(tmp_path / "out.txt")],
                   check=True, capture_output=True, timeout=120)
    lines = (tmp_path / "out.txt").read_text().split("\n")
    FW = np.array([[float(x) for x in line.split()] for line in lines[: u.size]])
    tail = dict(line.split() for line in lines[u.size:] if line)
    uc, Tc = curve_table()
    ref = IwanElement.from_curve(uc, Tc, N_CURVE).series(u, N)
    assert np.max(np.abs(FW[:, 0] - ref.F)) <= EXACT_TOL * np.max(np.abs(ref.F))
    assert np.max(np.abs(FW[:, 1] - ref.W)) <= EXACT_TOL * ref.W[-1]
    assert abs(float(tail["dFdu"]) - ref.kt[-1]) <= EXACT_TOL * abs(ref.kt[-1])
    assert tail["rollback"] == "1"
