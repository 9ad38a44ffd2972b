"""Packaging: one source of truth for the interface, our own model-description checks
(what fmpy's validator misses), the CLI's handling of bad curves."""
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmu_helpers import MU, N_CURVE, VR, Slave, curve_table

from contact_core.curve import VirginCurve, write_curve
from damper.cli import main as damper_main
from fmu_src import fmu_build, fmu_xml
from fmu_src.element import IwanElement


def _model_description(path) -> ET.Element:
    with zipfile.ZipFile(path) as zf:
        return ET.fromstring(zf.read("modelDescription.xml"))


def test_committed_vr_header_is_the_generated_one():
    assert fmu_build.header_is_current(), "run python -m fmu_src.fmu_build --write-header"


def test_test_value_references_match_the_table():
    assert VR == {v.name: v.vr for v in fmu_xml.VARIABLES}


def _variables(root, version):
    """(name, vr, causality, unit) per variable, in ModelVariables order."""
    out = []
    for sv in root.find("ModelVariables"):
        if sv.tag is ET.Comment:
            continue
        unit = sv.find("Real").get("unit") if version == 2 else sv.get("unit")
        out.append((sv.get("name"), int(sv.get("valueReference")), sv.get("causality"), unit))
    return out


@pytest.mark.parametrize("version", [2, 3])
def test_model_description_references_are_consistent(fmus, version):
    """Unique value references, units defined; outputs depend on the inputs (and,
    while initializing, on the parameters), dependencies never point elsewhere."""
    root = _model_description(fmus[version])
    variables = _variables(root, version)
    vrs = [v[1] for v in variables]
    assert len(set(vrs)) == len(vrs)
    defined = {u.get("name") for u in root.find("UnitDefinitions")}
    assert all(v[3] and v[3] in defined for v in variables)
    structure = root.find("ModelStructure")
    # FMI 2 refers to variables by 1-based index, FMI 3 by value reference
    key = (lambda i, v: i) if version == 2 else (lambda i, v: v[1])
    ids = {c: {key(i, v) for i, v in enumerate(variables, 1) if v[2] == c}
           for c in ("input", "output", "parameter")}
    if version == 2:
        outs = [int(r.get("index")) for r in structure.find("Outputs")]
        out_deps = [r.get("dependencies") for r in structure.find("Outputs")]
        inits = [int(r.get("index")) for r in structure.find("InitialUnknowns")]
        init_deps = [r.get("dependencies") for r in structure.find("InitialUnknowns")]
    else:
        outs = [int(r.get("valueReference")) for r in structure.iter("Output")]
        out_deps = [r.get("dependencies") for r in structure.iter("Output")]
        inits = [int(r.get("valueReference")) for r in structure.iter("InitialUnknown")]
        init_deps = [r.get("dependencies") for r in structure.iter("InitialUnknown")]
    assert sorted(outs) == sorted(ids["output"]) == sorted(inits)
    for deps in out_deps:  # direct feedthrough from u and N, nothing else
        assert {int(d) for d in deps.split()} == ids["input"]
    for deps in init_deps:
        assert {int(d) for d in deps.split()} == ids["input"] | ids["parameter"]


@pytest.mark.parametrize("version", [2, 3])
def test_fmu_carries_curve_sources_and_binary(fmus, version):
    with zipfile.ZipFile(fmus[version]) as zf:
        names = set(zf.namelist())
        curve = zf.read("resources/curve.txt").decode().split("\n")
    platform = fmu_build.PLATFORM[version]
    assert f"binaries/{platform}/damper.so" in names
    assert {f"sources/{n}" for n in fmu_build.c_sources(version)} <= names
    u, T = curve_table()
    table = np.array([[float(x) for x in line.split()] for line in curve[4:] if line])
    assert np.array_equal(table[:, 0], u) and np.array_equal(table[:, 1], T)


def test_cli_writes_an_fmu(tmp_path, capsys):
    u, T = curve_table(11)
    write_curve(VirginCurve(u=u, T=T, N=N_CURVE, mu=0.5), tmp_path / "c.json")
    out = tmp_path / "x.fmu"
    assert damper_main(["fmu", "--curve", str(tmp_path / "c.json"), "--fmi-version", "3",
                        "-o", str(out)]) == 0
    assert _model_description(out).get("fmiVersion") == "3.0"
    with zipfile.ZipFile(out) as zf:  # the source curve file travels along (provenance)
        assert zf.read("resources/curve.json").decode() == (tmp_path / "c.json").read_text()


@pytest.mark.parametrize("change", ["not_concave", "no_N", "truncated"])
def test_cli_refuses_a_bad_curve_and_writes_nothing(tmp_path, capsys, change):
    u, T = curve_table(11)
    path = tmp_path / "c.json"
    if change == "not_concave":
        T = T.copy()
        T[5] = 0.5 * T[5]  # a dent: slopes no longer non-increasing
    write_curve(VirginCurve(u=u, T=T, N=None if change == "no_N" else N_CURVE), path)
    if change == "truncated":
        path.write_text(path.read_text()[:40])
    out = tmp_path / "x.fmu"
    assert damper_main(["fmu", "--curve", str(path), "-o", str(out)]) == 2
    assert "error" in capsys.readouterr().err
    assert list(tmp_path.glob("*.fmu*")) == [] and not any(tmp_path.glob(".x.fmu*"))


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_concave_fit_makes_the_fmu_follow_the_fitted_element(tmp_path):
    """--fit concave: the FMU runs the same majorant as the array API with fit="concave"."""
    u, T = curve_table(11)
    T[5] *= 0.5
    out = fmu_build.build_fmu(u, T, N_CURVE, tmp_path / "fit.fmu", fit="concave")
    hist = np.array([0.0, 0.4, 1.2, -0.7, 0.9]) * u[-1]
    ref = IwanElement.from_curve(u, T, N_CURVE, fit="concave").series(hist)
    s = Slave(out, 2).initialize()
    F = s.run(hist)[0]
    s.close()
    # same C code and one code path for step and series (two builds of it): the
    # the required 1e-12
    assert np.max(np.abs(F - ref.F)) <= 1e-12 * np.max(np.abs(ref.F))


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
@pytest.mark.parametrize("mu", [MU, None])
def test_cli_fmu_continues_the_curve_past_its_end_like_damper_loop(tmp_path, mu):
    """A file with tail "flat" (gross slip): the FMU stays at mu N past the end, as the
    loop CLI's element; with tail "slope" the last slope goes on. Both CLIs read the
    file's tail (schema 2; contact_core.curve decides it for version 1 files)."""
    from damper.cli.loop import build_element

    u, T = curve_table(11)                          # T[-1] = MU N_CURVE exactly
    curve = VirginCurve(u=u, T=T, N=N_CURVE, mu=mu, tail="flat" if mu is not None else "slope")
    write_curve(curve, tmp_path / "c.json")
    out = tmp_path / "c.fmu"
    assert damper_main(["fmu", "--curve", str(tmp_path / "c.json"), "-o", str(out)]) == 0
    hist = np.array([0.0, 0.5, 1.5, 3.0, -0.2, -4.0, 2.5]) * u[-1]   # far past both ends
    s = Slave(out, 2).initialize()
    F = s.run(hist)[0]
    s.close()
    el, tail = build_element(curve, "reject", 1.0)
    assert tail == (mu is not None)
    ref = el.series(hist).F
    assert np.max(np.abs(F - ref)) <= 1e-12 * np.max(np.abs(ref))
    beyond = np.abs(hist) >= u[-1]
    if mu is not None:      # at gross slip: |F| = mu N wherever the motion went past the end
        np.testing.assert_allclose(np.abs(F[beyond][:3]), MU * N_CURVE, rtol=1e-12)
    else:                   # last slope continued: the force keeps rising past mu N
        assert F[3] > 1.5 * MU * N_CURVE


def test_package_data_ships_every_file_the_packager_copies():
    """A non-editable install must hold the C sources damper fmu copies into an FMU
    (pyproject [tool.setuptools.package-data] globs against fmu_build's file lists)."""
    import fnmatch
    import tomllib
    from pathlib import Path

    root = Path(fmu_build.__file__).resolve().parents[1]
    globs = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"]["fmu_src"]
    needed = {f"core/{n}" for n in fmu_build.CORE_SOURCES + fmu_build.CORE_HEADERS}
    for v in (2, 3):
        needed |= {f"fmi/{n}" for n in fmu_build.c_sources(v) if n not in fmu_build.CORE_SOURCES}
        needed |= {f"fmi/headers/{n}" for n in fmu_build._FMI_HEADERS[v] + ("LICENSE.txt",)}
    needed |= {f"fmi/{n}" for n in fmu_build._WRAPPER_HEADERS + ("model_passthrough.c",)}
    missing = sorted(n for n in needed if not any(fnmatch.fnmatch(n, g) for g in globs))
    assert not missing, f"add to package-data: {missing}"
    assert all((root / "fmu_src" / n).is_file() for n in needed)
