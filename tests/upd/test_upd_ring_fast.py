"""Fast mistuned-ring solver (``ring_fast``) against the full-grid reference (``ring_solve``),
the linear ring (dampers sliding) and the tuned sector; the ring LU back ends."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import minimize_scalar

from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.mistuning import LinearRing
from harmonic_balance.bladed_disk.ring_fast import fast_ring_frf, hermite_peaks
from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
from harmonic_balance.bladed_disk.ring_lu import BlockRingFactor, PardisoFactor, SuperLUFactor
from harmonic_balance.bladed_disk.ring_solve import RingSolver, ring_frf
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf

#: Per-blade peaks against the reference: the required accuracy (the fast solver's
#: non-worst blades come from cubic Hermite interpolation between continuation points).
PEAK_RTOL = 1e-3
#: The worst blade's peak (the amplification): both solvers locate its frequency to
#: PEAK_XTOL = 1e-6 relative, so the amplitudes agree to ~1e-9; 1e-6 leaves margin.
WORST_RTOL = 1e-6
#: The same linear system factored by two LU codes (round-off of a 420-unknown solve).
LU_RTOL = 1e-9
#: Tangents solved on two LU codes' factors of the same Jacobian (measured: 2e-11; the
#: Jacobian's condition number magnifies round-off).
TANGENT_RTOL = 1e-8
PATTERN = (1.02, 0.985, 1.0, 0.995)


@pytest.fixture(scope="module")
def sector4():
    """Four blades, EO 1: UPD-24's interblade phase on a ring of 4."""
    return Sector(load_config().with_values(disk__blades=4, disk__engine_order=1))


def exact_blade_peaks(ring, omegas, tuned, start):
    """Reference per-blade peaks: the full solver's grid, then Brent's search of every
    blade's own amplitude between the grid neighbours of its grid maximum."""
    c = ring_frf(ring, omegas, tuned, start_omega=start, refine=False)
    solver = RingSolver(ring, tuned)
    peaks = np.empty(ring.blades)
    for j in range(ring.blades):
        i = int(c.amplitude[:, j].argmax())
        assert 0 < i < c.omega.size - 1, "a blade's peak at the band's end: widen the band"
        res = minimize_scalar(lambda w, j=j: -ring.amplitudes(solver.at(w, c.omega, c.x))[j],
                              bounds=(c.omega[i - 1], c.omega[i + 1]), method="bounded",
                              options={"xatol": 1e-7 * c.omega[i]})
        peaks[j] = -res.fun
    return peaks


def test_fast_ring_equals_full_ring_with_friction(sector4):
    """Friction damper (CF/F0 = 4), a mistuned four-blade ring at H = 3: every blade's
    peak equals the reference's exactly refined one to PEAK_RTOL, the worst to WORST_RTOL."""
    H = 3
    tuned = SectorHB(sector4, H)
    om = 2 * np.pi * np.linspace(430.0, 485.0, 56)
    t = frf(tuned, om)
    ring = MistunedRingHB(sector4, PATTERN, H)
    ref = exact_blade_peaks(ring, om, tuned, t.peak_omega)
    c = fast_ring_frf(ring, (om[0], om[-1]), tuned, start_omega=t.peak_omega)
    assert not c.extra["truncated"]
    assert np.abs(c.peak_per_blade / ref - 1).max() < PEAK_RTOL
    assert c.peak == pytest.approx(ref.max(), rel=WORST_RTOL)
    assert c.worst == int(ref.argmax())
    # the converged points solve the ring's residual to the reference's tolerance
    tol = RingSolver(ring, tuned).tol
    for w, x in zip(c.omega[::5], c.x[::5]):
        assert np.linalg.norm(ring(x, w, jac=False)) <= tol


def test_fast_ring_tangents_are_those_of_the_converged_points(sector4):
    """A point taken when a short Newton step lands (its residual alone checked) gets the
    tangent of the Jacobian the step was solved with: it equals -J^-1 dR/domega with J
    evaluated at the point itself (SuperLU) to TANGENT_RTOL, at every point."""
    H = 3
    tuned = SectorHB(sector4, H)
    om = 2 * np.pi * np.linspace(430.0, 485.0, 56)
    ring = MistunedRingHB(sector4, PATTERN, H)
    c = fast_ring_frf(ring, (om[0], om[-1]), tuned, start_omega=frf(tuned, om).peak_omega)
    assert c.extra["landed"] > 0
    for w, x, xp in zip(c.omega, c.x, c.extra["tangents"]):
        _, J, Rw = ring(x, w)
        exact = SuperLUFactor()
        exact.factor(J)
        t = exact.solve(-Rw)
        assert np.linalg.norm(xp - t) <= TANGENT_RTOL * np.linalg.norm(t)


def test_fast_ring_sliding_limit_equals_linear_ring(sector4):
    """Friction that carries nothing (mu = 0), the normal load never lost (CF/F0 = 120):
    the fast HB's per-blade peaks equal those of the linear mistuned ring with the
    dampers sliding (an independent sparse solve per frequency)."""
    H, f0, cf, state, mu = 3, 1.0, 120.0, "sliding", 0.0
    om = 2 * np.pi * np.linspace(380.0, 520.0, 141)
    lin = LinearRing(sector4, PATTERN, state, f0)
    ref, wref = lin.peaks(om)
    band = (wref.min() * 0.97, wref.max() * 1.03)
    ring = MistunedRingHB(sector4, PATTERN, H, cf=cf, f0=f0, mu=mu)
    tuned = SectorHB(sector4, H, cf=cf, f0=f0, mu=mu)
    c = fast_ring_frf(ring, band, tuned, start_omega=float(np.median(wref)))
    assert np.abs(c.peak_per_blade / ref - 1).max() < PEAK_RTOL
    assert c.peak == pytest.approx(ref.max(), rel=WORST_RTOL)


def test_fast_ring_without_mistuning_is_the_tuned_sector(sector4):
    """kappa = 1: every blade's peak is the tuned sector's (its continuation's refined peak)."""
    H = 3
    tuned = SectorHB(sector4, H)
    om = 2 * np.pi * np.linspace(430.0, 470.0, 41)
    t = frf(tuned, om)
    c = fast_ring_frf(MistunedRingHB(sector4, np.ones(4), H), (om[0], om[-1]), tuned,
                      start_omega=t.peak_omega)
    assert c.peak_per_blade == pytest.approx(np.full(4, t.peak_amplitude), rel=WORST_RTOL)


def test_hermite_peaks_of_a_cubic_are_exact():
    """The interpolant of a cubic's values and slopes is the cubic: its maximum exactly."""
    w = np.array([0.0, 0.7, 1.5, 2.0])
    a = lambda x: 1.0 + x - 0.9 * x**2 + 0.1 * x**3  # noqa: E731
    da = lambda x: 1.0 - 1.8 * x + 0.3 * x**2  # noqa: E731
    x_max = (1.8 - np.sqrt(1.8**2 - 1.2)) / 0.6
    pk, wk = hermite_peaks(w, a(w)[:, None], da(w)[:, None])
    assert wk[0] == pytest.approx(x_max, rel=1e-12) and pk[0] == pytest.approx(a(x_max), rel=1e-12)


def test_ring_lu_backends_solve_the_same_system(sector4):
    """PARDISO (pattern analysed once, refactored for a second Jacobian) and SuperLU."""
    try:
        pard = PardisoFactor()
    except (ImportError, OSError):
        pytest.skip("pypardiso is not installed")
    ring = MistunedRingHB(sector4, PATTERN, 5)
    rng = np.random.default_rng(20261127)
    for f in (440.0, 455.0):
        w = 2 * np.pi * f
        x = ring.stuck_guess(w)
        _assert_solves_as_superlu(pard, ring(x, w)[1], rng)


@pytest.mark.parametrize("precision", ["mixed", "double"])
@pytest.mark.parametrize("blades", [3, 4])
def test_block_elimination_solves_the_ring_jacobian_as_superlu(blades, precision):
    """The blade-by-blade block LU on the ring's Jacobians (dampers stuck and slipping; three
    blades: the border is both neighbours' neighbour) against SuperLU, one factor object
    refactoring the same pattern; single-precision factors refined in double, or double."""
    sector = Sector(load_config().with_values(disk__blades=blades, disk__engine_order=1))
    ring = MistunedRingHB(sector, PATTERN[:blades], 5)
    blk = BlockRingFactor(blades, sector.n_dof, ring.nb, precision)
    rng = np.random.default_rng(20261128)
    for f, scale in ((440.0, 1.0), (455.0, 1.0), (448.0, 30.0)):
        w = 2 * np.pi * f
        x = ring.stuck_guess(w)
        x[ring.basis.index(1)[0] * ring.ndof:] *= scale   # larger vibration: the dampers slip
        _assert_solves_as_superlu(blk, ring(x, w)[1], rng)
    assert blk.fallbacks == 0


def test_block_elimination_falls_back_to_superlu_at_a_singular_blade_block():
    """A cyclic block-tridiagonal matrix whose first blade block is zero (the whole is
    regular through its couplings): the block LU cannot pivot across blades, so the
    factor hands the matrix to SuperLU and still solves it."""
    blades, n_dof, nb = 4, 2, 3
    m, rng = n_dof * nb, np.random.default_rng(20261129)
    perm = BlockRingFactor(blades, n_dof, nb).perm      # blade-major -> ring index
    A = np.zeros((blades * m, blades * m))
    for i in range(blades):
        j = (i + 1) % blades
        A[i * m:(i + 1) * m, i * m:(i + 1) * m] = 0.0 if i == 0 else 4 * np.eye(m) + rng.random((m, m))
        A[i * m:(i + 1) * m, j * m:(j + 1) * m] = np.eye(m)
        A[j * m:(j + 1) * m, i * m:(i + 1) * m] = np.eye(m)
    J = np.empty_like(A)
    J[np.ix_(perm, perm)] = A
    blk = BlockRingFactor(blades, n_dof, nb)
    blk.factor(sp.csc_matrix(J))
    b = rng.standard_normal(J.shape[0])
    assert blk.fallbacks == 1
    assert np.abs(J @ blk.solve(b) - b).max() <= LU_RTOL * np.abs(b).max()


def _assert_solves_as_superlu(fac, J, rng):
    """``fac`` factors J and solves a random right-hand side as SuperLU does, to LU_RTOL."""
    slu = SuperLUFactor()
    slu.factor(J)
    fac.factor(J)
    b = rng.standard_normal(J.shape[0])
    y1, y2 = slu.solve(b), fac.solve(b)
    assert np.abs(y1 - y2).max() <= LU_RTOL * np.abs(y1).max()
