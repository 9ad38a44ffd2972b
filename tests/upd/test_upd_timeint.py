"""Ring time integration (smoke): symmetry of the travelling wave, approach to the HB peak."""
import numpy as np
import pytest
from refcheck import check

from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.timeint import march_ring


@pytest.mark.slow
def test_ring_travelling_wave_symmetry():
    """All blades equal amplitude and phase steps of exactly phi (catches symmetry breaking);
    after 15 periods the amplitude is already within 5 % of the H = 7 HB value at the same
    frequency (0.5232 mm at 448.25 Hz, CF = 120 N; measured -2.6 % after 15 periods,
    -1.8 % after 40: not settled)."""
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.solve import start_point

    sector = Sector(load_config())
    w = 2 * np.pi * 448.25
    r = march_ring(sector, [w], cf=120.0, max_periods=15)
    amp = r["amplitude_blades"][0]
    # the start transient differs per blade (forcing phases): 1.3e-4 after 15 periods,
    # 2e-5 after 40
    assert np.ptp(amp) < 5e-4 * amp.max()
    # phase steps: 8.7e-4 rad off after 15 periods (transient), 1.5e-5 after 40
    assert r["phase_steps"][0] == pytest.approx(np.full(4, sector.cfg.phi), abs=2e-3)
    hb = SectorHB(sector, 7, cf=120.0)
    assert r["amplitude"][0] == pytest.approx(hb.amplitude_h1(start_point(hb, w)), rel=0.05)


@pytest.mark.slow
def test_ring_time_integration_matches_hb_with_lift_off():
    """CF/F0 = 2 (partial lift-off on the flat): the ring TI at the H = 7 peak frequency
    against the sector HB (H = 7). Issue bound 2 %; measured -0.3 % (150 periods,
    651 steps per period; 2x steps change the TI by 2e-5 at CF/F0 = 4)."""
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.solve import start_point

    sector = Sector(load_config())
    w = 2 * np.pi * 434.1279  # H = 7 peak at CF = 60 N
    hb = SectorHB(sector, 7, cf=60.0)
    x = start_point(hb, w)
    assert max(hb.contact_summary(x)["lift_off"]) > 0.1
    r = march_ring(sector, [w], cf=60.0, max_periods=40)
    check("UPD-24 first-harmonic amplitude [m], CF = 60 N (lift-off), H = 7, at the peak", hb.amplitude_h1(x),
          r["amplitude"][0], rtol=0.02, kind="self-consistency", source="time integration of the 4-blade ring")
