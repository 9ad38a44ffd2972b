"""The full ring solver (the reference) resolves every blade's peak on its default grid,
a narrow lightly damped resonance included."""
import numpy as np
import pytest

from damper.mistuning import SampleModel, Study
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.mistuning import LinearRing, draw_factors
from harmonic_balance.bladed_disk.ring_fast import fast_ring_frf
from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
from harmonic_balance.bladed_disk.ring_solve import half_power_width, resolving_points, ring_frf
from harmonic_balance.bladed_disk.sector import Sector

#: The study's default band of the 4-blade disk at H = 5, std 0.02 [Hz]
#: (damper.mistuning.tuned_reference: the friction-damped tuned peak to the stuck one,
#: each with its margin) and the tuned peak's frequency, the sweep's start.
BAND_HZ, F_TUNED_HZ = (425.8440110111613, 502.6050489450446), 448.25685369595925
H = 5
#: Pattern 2 of seed 1: blades 0 and 1 peak at the narrow resonance near 475-478 Hz
#: (contacts stuck, half-power width ~2 Hz), which 41 points (1.9 Hz apart) straddle:
#: the parabolas through the grid put them 7.5 % and 7.1 % high (measured); a dense grid
#: of 801 points agrees with the fast solver to 4e-5.
PATTERN = draw_factors(4, 0.02, 1, 2)
#: Full (resolved grid) against fast solver, per blade: both about 1e-4 from the dense
#: grid's parabolas (measured 4e-5 apart); an unresolved narrow peak is off by percent.
REF_RTOL = 5e-4
#: What the pattern shows on the plain 41-point grid (measured 7.5 %): it matters.
STEPPED_OVER = 0.03
#: The modal half-power width against the damped eigenvalues' decay rate: equal for the
#: ring's damping (measured 1e-9); a non-proportional part would enter as zeta^2 ~ 1e-5.
WIDTH_RTOL = 1e-6


@pytest.fixture(scope="module")
def sector4():
    """Four blades, EO 1: the interblade phase of UPD-24 (EO 6 of 24), a ring of 4."""
    return Sector(load_config().with_values(disk__blades=4, disk__engine_order=1))


def _omega(hz):
    return 2 * np.pi * np.asarray(hz, float)


def test_half_power_width_is_twice_the_decay_rate_of_the_tuned_rings_modes(sector4):
    lo, hi = _omega(BAND_HZ)
    rates = []
    for damper in ("stuck", "free"):
        r = LinearRing(sector4, np.ones(4), damper)
        K, M, C = r.K.toarray(), r.M.toarray(), r.C.toarray()
        n = K.shape[0]
        Minv = np.linalg.inv(M)
        s = np.linalg.eigvals(np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]]))
        s = s[(s.imag > 0) & (np.abs(s) >= lo) & (np.abs(s) <= hi)]
        rates += list(-2 * s.real)    # half-power width 2 zeta omega_r = -2 Re(s_r)
    assert half_power_width(sector4, lo, hi) == pytest.approx(min(rates), rel=WIDTH_RTOL)
    assert half_power_width(sector4, 0.5 * lo, 0.51 * lo) is None   # no mode there


def test_full_solver_resolves_a_narrow_resonance_as_the_fast_solver(sector4):
    lo, hi = _omega(BAND_HZ)
    ring = MistunedRingHB(sector4, PATTERN, H)
    tuned = SectorHB(sector4, H, cf=ring.cf, f0=ring.f0, mu=ring.mu, n_t=ring.basis.n_t)
    start = float(_omega(F_TUNED_HZ))
    fast = fast_ring_frf(ring, (lo, hi), tuned, start_omega=start)
    grid = np.linspace(lo, hi, resolving_points(sector4, lo, hi, 41))
    assert np.diff(grid).max() <= half_power_width(sector4, lo, hi)
    full = ring_frf(MistunedRingHB(sector4, PATTERN, H), grid, tuned, start_omega=start)
    assert full.extra["resolve"]["added"] > 0 and full.extra["resolve"]["unresolved"] == []
    assert np.abs(full.peak_per_blade / fast.peak_per_blade - 1).max() < REF_RTOL
    plain = ring_frf(MistunedRingHB(sector4, PATTERN, H), np.linspace(lo, hi, 41), tuned,
                     start_omega=start, resolve_rtol=None)
    assert np.abs(plain.peak_per_blade / fast.peak_per_blade - 1).max() > STEPPED_OVER


def test_study_grid_of_the_full_solver_is_no_coarser_than_the_narrowest_half_power_width(sector4):
    study = Study(blades=4, engine_order=1, harmonics=H, solver="full")
    om = SampleModel(study, list(BAND_HZ), F_TUNED_HZ).om
    assert om.size >= study.points
    assert np.diff(om).max() <= half_power_width(sector4, om[0], om[-1]) * (1 + 1e-12)
    # the fast solver's band ends only; the study's points as given
    assert SampleModel(Study(blades=4, engine_order=1, harmonics=H), list(BAND_HZ),
                       F_TUNED_HZ).om.size == study.points
