"""The library's peak search and load step (harmonic_balance.bladed_disk.surface_peak,
load_path.warm_path) on the point-contact sector, where an independent curve is cheap:
the search is the same for any sector model."""
import numpy as np
import pytest

from harmonic_balance.bladed_disk import load_path
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import SolverError, frf, solve_point, start_point
from harmonic_balance.bladed_disk.surface_peak import PEAK_XTOL, surface_peak

H = 1
#: The search maximises the same first-harmonic amplitude as the curve's refinement
#: (solve.PEAK_XTOL 1e-6): its amplitude error is second order in PEAK_XTOL = 1e-4
#: relative to the resonance's width (~1e-2), (1e-2)^2 = 1e-4 at most. Measured 5e-6 (CF 120 N)
#: and 3e-6 (600 N).
PEAK_AMPLITUDE_RTOL = 1e-4
#: Its frequency is first order in the search's tolerance. Measured 1.5e-5 and 4.4e-5.
PEAK_FREQUENCY_RTOL = 2 * PEAK_XTOL
#: Two Newton solutions of the same equations (|R| < solve.TOL_REL CF) agree far below this.
SAME_SOLUTION_RTOL = 1e-6


@pytest.fixture(scope="module")
def sector():
    return Sector(load_config(None))


@pytest.mark.parametrize("cf", [120.0, 600.0])
def test_bracketed_search_finds_the_curves_refined_peak(sector, cf):
    hb = SectorHB(sector, H, cf=cf)
    band = sector.cfg["load.band_hz"]
    c = frf(hb, 2 * np.pi * np.linspace(band[0], band[1], 40))
    f_curve = c.peak_omega / (2 * np.pi)
    pk = surface_peak(hb, 0.98 * f_curve)   # started 2 % off: the bracket walks uphill
    assert pk["peak_amplitude_h1"] == pytest.approx(c.peak_amplitude, rel=PEAK_AMPLITUDE_RTOL)
    assert pk["peak_hz"] == pytest.approx(f_curve, rel=PEAK_FREQUENCY_RTOL)
    assert pk["peak_amplitude_h1"] == pytest.approx(max(a for _, a in pk["points"]), rel=1e-12)


def test_halved_load_steps_reach_the_direct_solution(sector):
    """warm_path from 600 N to 150 N (through 300 N) ends on the solution Newton finds at 150 N
    from its own start."""
    omega = 2 * np.pi * 440.0

    def make(c):
        return SectorHB(sector, H, cf=c)
    x600 = start_point(make(600.0), omega)
    x = load_path.warm_path(make, omega, x600, 600.0, 150.0)
    direct = solve_point(make(150.0), omega, start_point(make(150.0), omega))
    hb = make(150.0)
    assert hb.amplitude_h1(x) == pytest.approx(hb.amplitude_h1(direct), rel=SAME_SOLUTION_RTOL)


class _Walk:
    """A stand-in walk whose peak search fails below ``floor`` [N]."""

    def __init__(self, floor):
        self.floor = floor

    def peak(self, cf, f_guess=None):
        if cf < self.floor:
            raise SolverError(f"no peak at {cf:g} N")
        return {"peak_amplitude_h1": 1.0 / cf, "peak_hz": 450.0}


def test_a_walk_stops_at_the_first_load_that_fails_after_enough_loads():
    """The lowest loads fail first (the damper near its floor): the walk keeps what it solved
    and says where it stopped; a failure before MIN_WALKED loads is the command's error."""
    from harmonic_balance.bladed_disk.surface_peak import MIN_WALKED, _walk_down

    cfs = np.geomspace(30.0, 3000.0, 8)
    peaks, stopped = _walk_down(_Walk(50.0), cfs, 450.0)
    assert len(peaks) == 7 and stopped[0] == pytest.approx(30.0) and "no peak at 30 N" in stopped[1]
    assert [p["peak_amplitude_h1"] for p in peaks] == pytest.approx(1.0 / cfs[1:])   # ascending CF
    assert _walk_down(_Walk(0.0), cfs, 450.0)[1] is None
    with pytest.raises(SolverError):
        _walk_down(_Walk(cfs[-MIN_WALKED] * 1.01), cfs, 450.0)


@pytest.mark.parametrize("solved, open_path_tried", [(1, True), (2, False)])
def test_the_open_load_path_is_the_last_resort_of_the_first_loads_only(monkeypatch, solved, open_path_tried):
    """Once MIN_WALKED loads are solved, a load whose warm start and halved steps fail is
    the walk's stop, not a path from its open load that retraces the loads walked."""
    from harmonic_balance.bladed_disk import surface_peak
    from harmonic_balance.newton import NewtonError

    assert surface_peak.MIN_WALKED == 2
    tried = []

    def no_newton(*a, **k):
        raise NewtonError("stand-in: no convergence", np.zeros(3), 40, 1.0)

    def no_warm_path(*a, **k):
        raise SolverError("stand-in: halved steps failed")

    def open_path(make, w, cf):
        tried.append(cf)
        return np.zeros(3), {"loads": [cf]}

    monkeypatch.setattr(surface_peak, "solve_point", no_newton)
    monkeypatch.setattr(surface_peak.load_path, "warm_path", no_warm_path)
    monkeypatch.setattr(surface_peak.load_path, "first_point", open_path)
    walk = surface_peak.SurfaceWalk.__new__(surface_peak.SurfaceWalk)
    walk.solved = {100.0 * 2 ** i: (2800.0, np.zeros(3)) for i in range(solved)}
    first = walk._first(None, None, 30.0, {"how": None})
    if open_path_tried:
        assert first(2800.0).shape == (3,) and tried == [30.0]
    else:
        with pytest.raises(SolverError, match="halved steps failed"):
            first(2800.0)
        assert tried == []
