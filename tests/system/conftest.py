"""UPD-24's blade and damper FMUs and its ring archive, built once per session."""
from __future__ import annotations

import pytest
from upd_system_loads import CF, F0

from harmonic_balance.bladed_disk import fmus
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector


@pytest.fixture(scope="session")
def sector():
    return Sector(load_config())


@pytest.fixture(scope="session")
def specs(sector):
    st = fmus.statics(sector, CF)
    return fmus.blade_spec(sector, CF, st), fmus.damper_spec(sector, CF, st)


@pytest.fixture(scope="session")
def system_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("system")


@pytest.fixture(scope="session")
def part_fmus(specs, system_dir):
    """{("blade"|"damper", version): path}."""
    from fmu_src.blade_fmu import build_blade_fmu
    from fmu_src.upd_fmu import build_damper_fmu

    b, d = specs
    out = {}
    for v in (2, 3):
        out["blade", v] = build_blade_fmu(b, system_dir / f"blade{v}.fmu", F0=F0, frequency=440.0,
                                          fmi_version=v)
        out["damper", v] = build_damper_fmu(d, system_dir / f"damper{v}.fmu", fmi_version=v)
    return out


@pytest.fixture(scope="session")
def ring_ssp(system_dir):
    from damper.ring_system import build_ring

    path = system_dir / "ring.ssp"
    build_ring(load_config(), CF, F0, path)
    return path
