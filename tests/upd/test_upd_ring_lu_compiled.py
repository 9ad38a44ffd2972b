"""The compiled block elimination (ring_lu.c) against its numpy reference in ring_lu.py, and
the compiled assembly of the contact blocks (ring_assemble.c) against ring_hb.py's bincount.

Not the same bits: the numpy path's products run numpy's own OpenBLAS on row-major
arrays, the compiled one scipy's on column-major ones, so the sums of each gemm are
ordered differently; the factors then differ by rounding amplified by each blade block's
conditioning (and a near-tie pivot may go the other way), while both solutions are
refined in double to the same residual and must agree to it.
"""
import numpy as np
import pytest

from harmonic_balance.bladed_disk import ring_lu_c
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
from harmonic_balance.bladed_disk.ring_lu import BLOCK_RTOL, BlockRingFactor
from harmonic_balance.bladed_disk.sector import Sector

pytestmark = pytest.mark.skipif(ring_lu_c.lib is None, reason="ring_lu.c is not built")

#: Mistuning factors of the rings below (within 1 +- 3 x 0.02).
PATTERN = np.array([1.0, 1.04, 0.97, 1.02, 0.99])
#: Two solutions of one system, each with |b - J x| <= BLOCK_RTOL |b|: they differ by at most
#: cond(J) BLOCK_RTOL relative; the rings' Jacobians here measure 1e-13 ... 5e-12 (cond ~1e2),
#: 1e-9 leaves margin for the conditioning at other frequencies.
SOLVE_RTOL = 1e-9
#: The contact blocks' projections (I (x) Q)^T dF (I (x) Q) by C loops and by numpy's
#: products (BLAS, maybe fused multiply-adds): each entry a few products, summed in the same
#: order into the pattern, so they differ by a few ulps of the largest: 1e-14 of max |J|
#: (measured 2e-16 at 24 blades).
ASSEMBLY_RTOL = 1e-14


@pytest.fixture(scope="module", params=[3, 4])
def ring(request):
    blades = request.param
    sector = Sector(load_config().with_values(disk__blades=blades, disk__engine_order=1))
    return MistunedRingHB(sector, PATTERN[:blades], 5)


def _states(ring):
    """Dampers stuck (440, 455 Hz) and slipping (448 Hz, 30 times the stuck amplitude)."""
    for f, scale in ((440.0, 1.0), (455.0, 1.0), (448.0, 30.0)):
        w = 2 * np.pi * f
        x = ring.stuck_guess(w)
        x[ring.basis.index(1)[0] * ring.ndof:] *= scale
        yield x, w


def _jacobians(ring):
    """The ring's Jacobians at :func:`_states`."""
    for x, w in _states(ring):
        yield ring(x, w)[1]


@pytest.mark.parametrize("precision", ["mixed", "double"])
def test_compiled_block_solve_equals_the_numpy_block_solve(ring, precision):
    """One factor object per kernel refactoring the same pattern; each solution meets the
    refinement's residual and the two agree to it."""
    shape = (ring.blades, ring.ndof // ring.blades, ring.nb)
    c = BlockRingFactor(*shape, precision, kernel="c")
    ref = BlockRingFactor(*shape, precision, kernel="numpy")
    rng = np.random.default_rng(20261130)
    for J in _jacobians(ring):
        c.factor(J)
        ref.factor(J)
        b = rng.standard_normal(J.shape[0])
        x, y = c.solve(b), ref.solve(b)
        assert np.linalg.norm(b - J @ x) <= BLOCK_RTOL * np.linalg.norm(b)
        assert np.abs(x - y).max() <= SOLVE_RTOL * np.abs(y).max()
    assert c.fallbacks == ref.fallbacks == 0


def test_unknown_block_kernel_is_refused():
    with pytest.raises(ValueError, match="kernel 'fortran'"):
        BlockRingFactor(4, 2, 3, kernel="fortran")


def test_compiled_assembly_equals_the_bincount_assembly(ring, monkeypatch):
    """The Jacobian assembled in C (A's values on the pattern, the contact blocks added)
    against ring_hb's numpy assembly, at stuck and slipping states; R and dR/domega are
    not touched by it (the same bits)."""
    for x, w in _states(ring):
        R1, J1, W1 = ring(x, w)
        with monkeypatch.context() as m:
            m.setattr(ring_lu_c, "lib", None)
            R0, J0, W0 = ring(x, w)
        assert np.array_equal(J0.indices, J1.indices) and np.array_equal(J0.indptr, J1.indptr)
        assert np.array_equal(R0, R1) and np.array_equal(W0, W1)
        assert np.abs(J1.data - J0.data).max() <= ASSEMBLY_RTOL * np.abs(J0.data).max()


@pytest.mark.parametrize("kernel", ["c", "numpy"])
def test_block_solve_refuses_a_matrix_of_right_hand_sides(ring, kernel):
    """The sweeps take one vector; a matrix would be read as a wrong vector by the C call."""
    J = next(_jacobians(ring))
    blk = BlockRingFactor(ring.blades, ring.ndof // ring.blades, ring.nb, kernel=kernel)
    blk.factor(J)
    with pytest.raises(ValueError, match="give one vector"):
        blk.solve(np.ones((J.shape[0], 2)))
