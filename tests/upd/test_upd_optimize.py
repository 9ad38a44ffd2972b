"""Optimal-load curve: the parallel load grid gives exactly the serial run's numbers."""
import numpy as np
import pytest

from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.optimize import load_curve
from harmonic_balance.bladed_disk.sector import Sector


@pytest.mark.slow
def test_parallel_load_grid_equals_serial():
    # tiny case: H = 1, 8 frequency points, 4 loads (2 chunks of 2); the chunks do the
    # same arithmetic in a spawned worker as in this process, so equality is exact
    sector = Sector(load_config())
    omegas = 2 * np.pi * np.linspace(400.0, 500.0, 8)
    cfs = np.geomspace(60.0, 600.0, 4)
    serial = load_curve(sector, cfs, 1, omegas, workers=1)[0]
    parallel = load_curve(sector, cfs, 1, omegas, workers=2)[0]
    assert len(serial) == 4
    assert serial == parallel
