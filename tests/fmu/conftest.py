"""FMUs built once per test session into a temporary folder."""
from __future__ import annotations

import pytest
from fmu_helpers import N_CURVE, curve_table

from fmu_src.fmu_build import build_fmu


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def fmus(fmu_dir):
    """{2: path, 3: path} of the friction-element FMUs for the test curve."""
    u, T = curve_table()
    return {v: build_fmu(u, T, N_CURVE, fmu_dir / f"damper{v}.fmu", fmi_version=v,
                         description="test curve (Cattaneo-Mindlin)")
            for v in (2, 3)}
