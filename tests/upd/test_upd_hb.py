"""Nonlinear UPD sector HB: statics, homogeneity, energy balance, linear limits."""
import numpy as np
import pytest
from refcheck import check

from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import linear_response, peak_of
from harmonic_balance.bladed_disk.solve import energy_balance, frf, start_point, sweep

#: Closed-form statics vs the linear solve: round-off, measured 6.7e-16 (revision
#: a12e5f1); 1e-12 leaves room for other BLAS builds and thread counts.
STATIC_RTOL = 1e-12
#: Mean contact loads of a stuck HB solution against the statics: round-off, measured
#: 4.4e-16 (a12e5f1); 200x for other platforms.
STATIC_MEAN_RTOL = 1e-13
#: Energy balance per cycle and homogeneity (amplitude / F0 at (F0, CF) and (3 F0, 3 CF))
#: hold to the Newton tolerance: |R| < solve.TOL_REL max(F0, CF) = 1e-10 is what the
#: solver guarantees. Measured 1.0e-15 and 1.1e-15 (a12e5f1; 3e-12 at an earlier
#: revision): quadratic convergence usually overshoots the stopping test, but one
#: iteration fewer on another platform may not, so the bound is the stopping tolerance.
ENERGY_RTOL = 1e-10
HOMOG_RTOL = 1e-10
#: HB peak frequency at the linear limits (CF -> infinity, mu = 0) against the linear
#: FRF's: both peaks are located by Brent's method to a relative 1e-6 (solve.PEAK_XTOL)
#: and 1e-10: measured 1.0e-7 and 3.7e-7 (a12e5f1); 1e-5, 27x the larger.
LIMIT_OMEGA_RTOL = 1e-5
#: Peak amplitudes at the linear limits: flat at the peak, so the frequency error enters
#: squared; measured 9.6e-10 (CF = 3e5 N, the remaining slip) and 7.1e-11 (mu = 0)
#: (a12e5f1); 1e-7, 100x the larger.
LIMIT_AMP_RTOL = 1e-7
#: Growth of these peak errors the validation check lets pass (refcheck.GROWTH is 10):
#: a peak's position is set by the searches' tolerances, within which it may move by
#: more than 10x on another platform (and the amplitude's error with its square).
SEARCH_GROWTH = 100.0


def test_frictionless_statics_closed_form(sector):
    cf = 120.0
    g = np.radians(45.0)
    st = SectorHB(sector, 1, cf=cf).static
    expect = [cf / (2 * np.cos(g)), cf / (4 * np.cos(g)), cf / (4 * np.cos(g))]
    check("UPD-24 frictionless static contact loads N [N], CF = 120 N", st["N"], expect, rtol=STATIC_RTOL,
          source="statics: CF / (2 cos g), CF / (4 cos g)")


def test_zeroth_harmonic_reproduces_statics(sector):
    """Fully stuck small vibration: the mean contact loads are the frictionless ones."""
    hb = SectorHB(sector, 3, cf=120.0, f0=1e-3)
    w = 2 * np.pi * 450
    x = start_point(hb, w)
    s = hb.contact_summary(x)
    assert s["normal_load_mean"] == pytest.approx(hb.static["N"], rel=STATIC_MEAN_RTOL)
    assert max(s["lift_off"]) == 0.0


def test_homogeneity(sector):
    w = 2 * np.pi * np.array([430.0, 445.0, 460.0])
    amps = []
    for k in (1.0, 3.0):
        hb = SectorHB(sector, 3, cf=120.0 * k, f0=30.0 * k)
        xs = sweep(hb, w)
        amps.append(np.array([hb.amplitude_h1(x) for x in xs]) / hb.f0)
    assert amps[1] == pytest.approx(amps[0], rel=HOMOG_RTOL)


@pytest.mark.parametrize("cf, band", [(60.0, (425.0, 440.0)), (120.0, (440.0, 455.0)),
                                      (600.0, (468.0, 480.0))])
def test_energy_balance(sector, cf, band):
    """Near each load's peak, where the contacts slip (60 N: partial lift-off)."""
    hb = SectorHB(sector, 5, cf=cf)
    w = 2 * np.pi * np.linspace(*band, 6)
    xs = sweep(hb, w)
    for x, om in zip(xs, w):
        e = energy_balance(hb, x, om)
        assert abs(e["imbalance"]) < ENERGY_RTOL
        assert e["W_friction"] > 0 and e["W_struct"] > 0 and e["W_dashpot"] > 0
        # the C core's sampled-loop area agrees with the Galerkin friction work to the
        # AFT quadrature error (measured <= 2e-5 relative)
        assert e["W_friction_loops"] == pytest.approx(e["W_friction"], rel=1e-4)


def _linear_peak(sector, damper):
    return peak_of(lambda om: abs(linear_response(sector, om, damper)[0, sector.response]),
                   2 * np.pi * 380, 2 * np.pi * 520)


def test_high_cf_tends_to_stuck(sector):
    w_l, a_l = _linear_peak(sector, "stuck")
    hb = SectorHB(sector, 3, cf=3e5)
    c = frf(hb, 2 * np.pi * np.linspace(470, 490, 21))
    lin = "linear FRF of the stuck sector"
    check("UPD-24 HB peak frequency [rad/s], CF = 3e5 N (stuck limit)", c.peak_omega, w_l, rtol=LIMIT_OMEGA_RTOL,
          kind="self-consistency", source=lin, growth=SEARCH_GROWTH)
    check("UPD-24 HB peak amplitude [m], CF = 3e5 N (stuck limit)", c.peak_amplitude, a_l, rtol=LIMIT_AMP_RTOL,
          kind="self-consistency", source=lin, growth=SEARCH_GROWTH)


def test_mu_zero_is_sliding_linear(sector):
    """mu = 0: only the normal springs (no lift-off at this CF): the 'sliding' linear system."""
    w_l, a_l = _linear_peak(sector, "sliding")
    hb = SectorHB(sector, 3, cf=3e4, mu=0.0)
    c = frf(hb, np.linspace(w_l * 0.97, w_l * 1.03, 21))
    lin = "linear FRF of the sector with sliding contacts"
    check("UPD-24 HB peak frequency [rad/s], mu = 0", c.peak_omega, w_l, rtol=LIMIT_OMEGA_RTOL,
          kind="self-consistency", source=lin, growth=SEARCH_GROWTH)
    check("UPD-24 HB peak amplitude [m], mu = 0", c.peak_amplitude, a_l, rtol=LIMIT_AMP_RTOL,
          kind="self-consistency", source=lin, growth=SEARCH_GROWTH)


def test_sector_equals_ring(sector):
    """Cyclic sector == HB of the 4-blade ring (no symmetry assumed), with partial lift-off:
    the mapped sector solution satisfies the ring equations, and Newton on the ring from
    a 1 %-perturbed start returns to it."""
    from harmonic_balance.bladed_disk.ring import RingHB
    from harmonic_balance.newton import newton

    hb, rg = SectorHB(sector, 5, cf=60.0), RingHB(sector, 5, cf=60.0)
    w = 2 * np.pi * 434.0
    x = start_point(hb, w)
    assert max(hb.contact_summary(x)["lift_off"]) > 0.1
    xr = rg.from_sector(x)
    # the sector solution's Newton tolerance (solve.TOL_REL) bounds the ring residual;
    # measured 4.5e-14 (a12e5f1)
    assert np.linalg.norm(rg(xr, w, False)) < 1e-10 * np.linalg.norm(rg.Fext)
    start = xr * (1 + 0.01 * np.random.default_rng(0).standard_normal(xr.size))
    xn = newton(lambda z: rg(z, w)[:2], start, 1e-8, 50).x
    # both ends are Newton solutions (ring to 1e-8 |R|, sector to 1e-10): measured 4.1e-14
    # (a12e5f1); 1e-11 is 250x that, far below the 1 % perturbation
    assert np.abs(xn - xr).max() < 1e-11 * np.abs(xr).max()


#: The coarse start and Newton from the stuck guess at the full H solve the same equations
#: to |R| < 1e-10 max(F0, CF): their solutions agree to that over the Jacobian's scale;
#: measured 2e-14 relative (CF 120 N, H = 21); 1e-9 leaves room for the conditioning.
START_RTOL = 1e-9


@pytest.mark.parametrize("cf", [60.0, 600.0])
def test_coarse_start_is_the_start_newton_finds_at_the_full_harmonics(sector, cf):
    from harmonic_balance.bladed_disk.solve import START_H, coarse_start, solve_point

    hb = SectorHB(sector, START_H + 6, cf=cf, f0=30.0)
    omega = 2 * np.pi * sector.cfg["load.band_hz"][0]
    direct = solve_point(hb, omega, hb.stuck_guess(omega), max_iter=80)
    coarse = coarse_start(hb, omega)
    assert coarse is not None
    assert np.linalg.norm(coarse - direct) <= START_RTOL * np.linalg.norm(direct)
    assert coarse_start(hb.with_harmonics(START_H), omega) is None   # nothing coarser to start from
