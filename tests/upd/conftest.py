"""Shared fixtures of the UPD tests."""
import pytest

from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector


@pytest.fixture(scope="module")
def sector():
    """The default UPD-24 sector (bundled configuration), one per test module."""
    return Sector(load_config())
