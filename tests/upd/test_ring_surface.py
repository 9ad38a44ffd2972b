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


#: Both sides evaluate the same trigonometric sums: round-off.
START_ATOL = 1e-12


def test_ring_start_puts_each_sector_at_the_sector_motion_shifted_by_its_phase(surface_hb):
    from harmonic_balance.bladed_disk.ring_surface import ring_start
    from harmonic_balance.fourier import FourierBasis

    cfg, basis, n = surface_hb.sector.cfg, surface_hb.basis, surface_hb.model.n
    x = np.random.default_rng(20261128).standard_normal(basis.nb * n)
    assert basis.harmonics[0] == 0   # the series below starts with the mean
    ns = 64
    ring = ring_start(surface_hb, x)(ns)
    sector = FourierBasis(basis.harmonics, ns).E @ x.reshape(basis.nb, n)
    theta = 2 * np.pi * np.arange(ns) / ns
    for j in range(cfg.ring_blades):
        # sector j at theta is the sector at theta + j phi: evaluate the series there
        shifted = np.stack([np.ones(ns)] + [f(h * (theta + j * cfg.phi)) for h in basis.harmonics[1:]
                                            for f in (np.cos, np.sin)], axis=1)
        want = shifted @ x.reshape(basis.nb, n)
        assert np.allclose(ring[:, n * j:n * (j + 1)], want, atol=START_ATOL * np.abs(x).sum())
    assert np.allclose(ring[:, :n], sector, atol=START_ATOL * np.abs(x).sum())


def test_ring_start_from_the_sector_dofs_alone_leaves_the_nodes_to_the_march(surface_hb):
    from harmonic_balance.bladed_disk.ring_surface import ring_start

    basis, n, n_s = surface_hb.basis, surface_hb.model.n, surface_hb.sector.n_dof
    x = np.random.default_rng(20261129).standard_normal((basis.nb, n))
    x_sec = x[:, :n_s].ravel()
    full, part = ring_start(surface_hb, x.ravel())(16), ring_start(surface_hb, x_sec)(16)
    assert np.allclose(part[:, :n_s], full[:, :n_s], rtol=0, atol=START_ATOL * np.abs(x).sum())
    assert not np.any(part[:, n_s:n])
    with pytest.raises(ValueError, match="DOFs per harmonic"):
        ring_start(surface_hb, x[:, :n_s - 1].ravel())


def _dense_statics(model, max_iter=100):
    """The active-set statics with each contact's full (n, n) outer product (the plain form of
    contact.frictionless_statics, which adds the products on the contact's DOFs only)."""
    from harmonic_balance.contact import _static_parts

    Klin, rows = _static_parts(model)
    f0 = np.real(model.forcing.get(0, np.zeros(model.n))).astype(float)
    active = np.ones(len(rows), dtype=bool)
    for _ in range(max_iter):
        A, b = Klin.copy(), f0.copy()
        for on, (_, el, _, qn, tn) in zip(active, rows):
            if on:
                A += el.k_n * np.outer(tn, qn)
                b -= el.k_n * el.preload * tn
        x = np.linalg.solve(A, b)
        new = np.array([el.preload + qn @ x > 0.0 for _, el, _, qn, _ in rows], dtype=bool)
        if np.array_equal(new, active):
            return x, active
        active = new
    raise AssertionError("no contact set")


@pytest.mark.parametrize("which", ["sector", "ring"])
def test_statics_on_the_contacts_dofs_equals_the_dense_assembly(surface_hb, which):
    """Same matrix entries added in the same order: equal to round-off of the solve (1e-12),
    and the same contacts closed (some open, so the active set is exercised)."""
    model = surface_hb.model if which == "sector" else surface_ring_model(surface_hb)
    x_ref, active = _dense_statics(model)
    x, _ = frictionless_statics(model)
    assert 0 < active.sum() <= active.size
    assert np.allclose(x, x_ref, rtol=0, atol=1e-12 * np.abs(x_ref).max())


def test_the_statics_solve_refuses_a_singular_matrix_and_solves_a_well_conditioned_one():
    """The condition check of the statics (LAPACK's 1-norm estimate against SINGULAR_COND):
    a rank-deficient matrix, an exactly zero one and cond 1e14 refused; cond 1e11 solved."""
    from harmonic_balance.contact import SINGULAR_COND, _solve_checked

    for A in (np.ones((2, 2)), np.zeros((3, 3)), np.diag([1.0, 1e-14])):
        with pytest.raises(ValueError, match="frictionless statics is singular"):
            _solve_checked(A, np.ones(len(A)))
    A = np.diag([1.0, 1e-11])
    assert np.linalg.cond(A) < SINGULAR_COND
    assert np.allclose(_solve_checked(A, np.ones(2)), [1.0, 1e11], rtol=1e-15)
