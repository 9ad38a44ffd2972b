"""The sector's truncation check starts from the peak it checks, whatever the report grid.

A stuck damper (CF 1e6 N on UPD-24) is a linear spring: every harmonic set gives the
same first harmonic, so the truncation error is nil, and its resonance is sharp enough
that a 10-point grid's points all lie far down its flanks.
"""
import numpy as np
import pytest

from harmonic_balance.bladed_disk.accuracy import peak_to_accuracy, truncation_error
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.solve import frf

#: CF [N] at which every UPD-24 contact sticks (the nearly linear limit) and F0 [N].
STUCK_CF, F0 = 1e6, 30.0
#: A coarse report grid: its highest point lies ~0.9 Hz from the stuck peak, whose
#: amplitude there is 23 % lower.
COARSE = 10
#: Relative truncation estimate a linear (stuck) peak may show: the peak searches' own
#: tolerances (1e-6 in frequency at both levels; measured 1.2e-6 on the coarse grid, 1e-9
#: on 41 points), far below the 1 % that warns.
STUCK_TOL = 1e-4
#: Relative agreement of a peak found from the coarse grid with the fine grid's: the same
#: peak searches' tolerances.
SAME_PEAK_TOL = 1e-5


def _band(sector, points):
    lo, hi = sector.cfg["load.band_hz"]
    return 2 * np.pi * np.linspace(lo, hi, points)


def test_stuck_damper_has_no_truncation_error_on_a_coarse_grid(sector):
    hb = SectorHB(sector, 7, cf=STUCK_CF, f0=F0)
    c = frf(hb, _band(sector, COARSE))
    rec = truncation_error(hb, c)
    assert rec["peak_amplitude_rel"] < STUCK_TOL
    # the check's peak is the curve's, not the grid's highest point
    assert rec["checks"][0]["peak_omega"] == pytest.approx(c.peak_omega, rel=SAME_PEAK_TOL)
    assert not np.any(np.isclose(c.omega, rec["checks"][0]["peak_omega"], rtol=SAME_PEAK_TOL))


def test_peak_to_accuracy_on_a_coarse_grid_reports_the_fine_grids_peak(sector):
    fine = frf(SectorHB(sector, 7, cf=STUCK_CF, f0=F0), _band(sector, 41))
    _, _, rec = peak_to_accuracy(sector, _band(sector, COARSE), 1e-3, 7, cf=STUCK_CF, f0=F0)
    assert rec["accuracy"]["met"]
    assert rec["accuracy"]["peak_amplitude"] == pytest.approx(fine.peak_amplitude, rel=SAME_PEAK_TOL)
    assert rec["accuracy"]["peak_omega"] == pytest.approx(fine.peak_omega, rel=SAME_PEAK_TOL)


def test_with_peak_inserts_the_refined_peak_in_frequency_order():
    from harmonic_balance.accuracy import with_peak

    xs = [np.full(2, float(k)) for k in range(4)]
    om = np.array([1.0, 2.0, 3.0, 4.0])
    pts, w, i = with_peak(xs, om, 1, np.full(2, 9.0), 2.5)
    assert list(w) == [1.0, 2.0, 2.5, 3.0, 4.0] and i == 2 and pts[2][0] == 9.0
    assert [p[0] for p in pts[:2] + pts[3:]] == [0.0, 1.0, 2.0, 3.0]
    # a peak on a grid point, or a folded branch's own (non-monotone) points: unchanged
    assert with_peak(xs, om, 1, np.full(2, 9.0), 2.0)[2] == 1
    folded = np.array([1.0, 3.0, 2.0, 4.0])
    pts, w, i = with_peak(xs, folded, 1, np.full(2, 9.0), 2.5)
    assert len(pts) == 4 and list(w) == list(folded) and i == 1
