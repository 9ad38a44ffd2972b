"""One set of compile flags for the three builds of the C core (CMake, pip, FMU)."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

from fmu_src import fmu_build

ROOT = Path(fmu_build.__file__).resolve().parents[1]


def test_pip_extension_uses_the_shared_flags():
    ext = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["ext-modules"]
    (iwan,) = [e for e in ext if e["name"] == "fmu_src._iwan"]
    assert tuple(iwan["extra-compile-args"]) == fmu_build.shared_cflags()


def test_fmu_build_and_cmake_read_the_same_file():
    flags = fmu_build.shared_cflags()
    assert "-std=c99" in flags and any(f.startswith("-O") for f in flags)
    assert fmu_build.CFLAGS[: len(flags)] == flags
    cmake = (ROOT / "CMakeLists.txt").read_text()
    assert re.search(r"file\(STRINGS \S*fmu_src/core/cflags.txt DAMPER_CFLAGS", cmake)
    assert "add_compile_options(${DAMPER_CFLAGS}" in cmake
    # no other optimisation or standard flag sneaks in through CMake's build types
    assert 'set(CMAKE_C_FLAGS_RELEASE "")' in cmake
    subdirs = "".join(p.read_text() for p in (ROOT / "fmu_src").glob("*/CMakeLists.txt"))
    assert not re.search(r"-O[0-3s]|-std=", subdirs)


def test_cmake_compile_lines_carry_the_shared_flags():
    """The configured build (make cbuild) really compiles with them (flags.make of a target)."""
    import pytest

    made = list((ROOT / "build" / "c").rglob("iwan_core.dir/flags.make"))
    if not made:
        pytest.skip("C build not configured (make cbuild)")
    line = next(ln for ln in made[0].read_text().splitlines() if ln.startswith("C_FLAGS"))
    for flag in fmu_build.shared_cflags():
        assert flag in line.split(), (flag, line)
    assert "-O3" not in line
