"""What the UPD damper's CF floor (damper.limits.MIN_CF_PER_F0) guards: below it the
damper rattles and damps through its contact dashpots alone, a response that no longer
changes with the load and is not that of the blades without a damper."""
import numpy as np
import pytest

from damper import limits
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import linear_response, peak_of
from harmonic_balance.bladed_disk.solve import energy_balance, frf

F0 = 30.0
#: A CF far below the floor (0.03 N at F0 = 30 N) whose start solve converges (many
#: loads just below the floor find no start: limits.MIN_CF_PER_F0).
BELOW = 1e-4
#: Relative agreement of the peaks at and far below the floor: measured 1e-4 (the
#: friction's share of the work, < 1e-5, and the peak searches' tolerances).
SAME_PEAK = 1e-3
#: Least share of the work per cycle the contact dashpots take at the floor (measured 0.86).
DASHPOT_SHARE = 0.8
#: The damper-free peak is several times the rattling one (measured 7.2).
FREE_OVER_RATTLING = 5.0


def _peak(sector, cf):
    lo, hi = sector.cfg["load.band_hz"]
    hb = SectorHB(sector, 7, cf=cf, f0=F0)
    return hb, frf(hb, 2 * np.pi * np.linspace(lo, hi, 41))


def test_below_the_cf_floor_the_damper_rattles_on_its_dashpots_not_the_free_limit(sector):
    floor = limits.MIN_CF_PER_F0 * F0
    hb, at = _peak(sector, floor)
    _, below = _peak(sector, BELOW)
    assert below.peak_amplitude == pytest.approx(at.peak_amplitude, rel=SAME_PEAK)
    e = energy_balance(hb, at.peak_x, at.peak_omega)
    assert e["W_dashpot"] > DASHPOT_SHARE * e["W_ext"]
    lo, hi = sector.cfg["load.band_hz"]
    r = sector.response
    _, free = peak_of(lambda om: abs(linear_response(sector, om, "free", F0)[0, r]),
                      2 * np.pi * lo, 2 * np.pi * hi, 41)
    assert free > FREE_OVER_RATTLING * at.peak_amplitude


def test_cf_floor_message_says_what_the_damper_does_below_it():
    f0 = 30.0
    with pytest.raises(ValueError) as err:
        limits.check_cf_floor("--cf", 0.5 * limits.MIN_CF_PER_F0 * f0, f0, None)
    msg = str(err.value)
    assert "dashpots" in msg and "free limit" not in msg
    assert f"at least {limits.MIN_CF_PER_F0 * f0:g} N" in msg and "--damper free" in msg
