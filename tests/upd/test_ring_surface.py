"""The UPD ring with contact surfaces (bladed_disk.ring_surface) unrolled from the sector.

The ring's time integration starts from its own frictionless prestress; by cyclic symmetry
of the static load every sector of the ring must sit where the cyclic sector model's
statics put it (the same surfaces, the cyclic couplings unrolled onto the neighbours).
"""
import numpy as np
import pytest

from damper.cache import Store
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.ring_surface import surface_ring_model
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.surface_hb import SurfaceSectorHB
from harmonic_balance.contact import frictionless_statics

NODES = 5
#: Both statics are linear solves per contact set on the same matrices: round-off.
STATIC_RTOL = 1e-8


@pytest.fixture(scope="module")
def surface_hb(tmp_path_factory):
    store = Store(tmp_path_factory.mktemp("ring_surface_cache"))
    cfg = load_config(None)
    return SurfaceSectorHB(Sector(cfg), build_surfaces(cfg, NODES, store=store), H=1, cf=120.0)


def test_every_ring_sector_sits_at_the_cyclic_sector_statics(surface_hb):
    ring = surface_ring_model(surface_hb)
    x, _ = frictionless_statics(ring)
    n, nr = surface_hb.model.n, surface_hb.sector.cfg.ring_blades
    assert ring.n == n * nr
    scale = np.abs(surface_hb.x_static).max()
    for j in range(nr):
        assert np.allclose(x[n * j:n * (j + 1)], surface_hb.x_static, rtol=0, atol=STATIC_RTOL * scale)


def test_ring_contacts_are_the_sector_nodes_on_every_sector(surface_hb):
    ring = surface_ring_model(surface_hb)
    nodes = [e for e in surface_hb.model.elements if e.name.startswith(("left node", "flat node"))]
    ring_nodes = [e for e in ring.elements if e.name.startswith(("left node", "flat node"))]
    assert len(ring_nodes) == surface_hb.sector.cfg.ring_blades * len(nodes)
    assert not any(e.kinematics.cyclic for e in ring.elements)
