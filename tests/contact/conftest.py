"""Shared fixtures of the contact tests: one condensation cache per test session.

Condensed models are built once per session into a temporary cache folder, so
the tests of one model share its FE stage (and the cache itself is exercised).
"""
from __future__ import annotations

import pytest

from contact_core.cache import DiskCache
from contact_core.condense import condense
from contact_core.spec import ContactSpec

#: The small models the normal tests use (a few seconds each to condense).
SPHERE_R = 0.01
CYL_R, CYL_L = 2.5e-3, 1.2e-3
FLAT_W, FLAT_L = 1.2e-3, 5e-3
SPECS = {
    "sphere_real": ContactSpec(body="sphere", radius=SPHERE_R, model="real", grid=21),
    "sphere_halfspace": ContactSpec(body="sphere", radius=SPHERE_R, model="halfspace", grid=21),
    "cylinder_real": ContactSpec(body="cylinder", radius=CYL_R, length=CYL_L, model="real", grid=15),
    "flat": ContactSpec(body="flat", width=FLAT_W, length=FLAT_L, grid=9),
}


@pytest.fixture(scope="session")
def specs():
    """The named small models (ContactSpec by name)."""
    return SPECS


@pytest.fixture(scope="session")
def contact_cache(tmp_path_factory):
    """A DiskCache in a fresh temporary folder, shared by the session."""
    return DiskCache(tmp_path_factory.mktemp("damper_cache"))


@pytest.fixture(scope="session")
def condensed(contact_cache):
    """``condensed(name)`` -> CondensedContact of SPECS[name], built once per session."""
    built = {}

    def get(name):
        if name not in built:
            built[name] = condense(SPECS[name], cache=contact_cache)
        return built[name]

    return get
