"""Which steady state on the bladed disk: the sector HB's peak against ring time integrations.

The question and its answer are :mod:`harmonic_balance.steady_state`'s (stuck sliders
whose mean is the harmonic balance's convention, coexisting stick-slip states); this
module runs the same check for the cyclic sector, whose model is not a matrix model of
:mod:`harmonic_balance.timeint`: at the refined peak of a sector curve, the tuned ring of
N_r blades with the sector's travelling-wave excitation
(:func:`.timeint.march_ring`, the same contact elements and C core, no Fourier series)
is marched twice at the peak frequency:

* from rest at the frictionless prestress state, sliders virgin (the state a start from
  rest reaches);
* from the harmonic balance's state: the sector's harmonics rotated onto every blade of
  the ring (:meth:`.ring.RingHB.from_sector`), displacements and velocities at t = 0, each
  contact's slider first stepped twice through the HB period so it carries that loop's
  past.

Amplitudes are the sector's ``amplitude_max``: max |u_a(t) - mean| of blade 0's
response DOF over the (last) period. The comparison, the 1 % threshold and the wording
of the warning are :func:`~harmonic_balance.steady_state.compare`,
:data:`~harmonic_balance.steady_state.SAME_STATE_TOL` and
:func:`~harmonic_balance.steady_state.summary_lines`. ``stuck_links`` names the contact
points that never slip at the peak (no friction energy, in contact for part of the period
at least): their slider's mean is the convention's.
"""
from __future__ import annotations

import time

import numpy as np

#: Settling tolerance of both ring integrations (timeint's extrapolated relative change
#: of the first harmonic per period): two orders below the 1 % the check decides on. On
#: UPD-24 at H = 7, CF 120 N the two runs then agree to 3e-6 (45 and 31 periods, 2.7 s
#: CPU); 1e-4 gives 4e-5 (2.0 s), 1e-6 gives 2e-8 for 9.7 s.
RING_TOL = 1e-5
#: Period limit of each integration: it bounds the cost of a case that never settles
#: (``converged`` false) to ~70 s of CPU a run on UPD-24 (0.034 s a period of ~600 steps);
#: the slowest case measured, every contact stuck (CF 3000 N, F0 0.3 N: a linear ring
#: damped ~1e-3 of critical), settles from rest in 818 periods.
RING_PERIODS = 2000
#: Samples of the HB period the sliders are stepped through (twice) before the start from
#: the HB state: the HB's own AFT resolution at H <= 30 is coarser, so the loop is traced.
HISTORY_SAMPLES = 512


def stuck_contacts(hb, x: np.ndarray, omega: float) -> list[str]:
    """Names of the contact points that never slip over the period at sector solution ``x``
    (in contact for part of it at least; friction energy per cycle exactly zero [J])."""
    s = hb.contact_summary(x, omega)
    return [n for n, W, lift in zip(s["names"], s["friction_energy"], s["lift_off"])
            if lift < 1.0 and W <= 0.0]


def ring_start(hb, x: np.ndarray, omega: float, samples: int = HISTORY_SAMPLES):
    """The ring's start at the sector solution ``x``: x0 (n_r,) [m], v0 (n_r,) [m/s], a0
    (n_r,) [m/s^2] at t = 0 and the history (2 samples, n_r) [m]: the HB period twice,
    oldest first, ending just before t = 0."""
    from ..steady_state import hb_period
    from .ring import RingHB

    ring = RingHB(hb.sector, hb.H, cf=hb.cf, f0=hb.f0, mu=hb.mu)
    X = ring.from_sector(x).reshape(ring.nb, ring.ndof)
    xs, v0 = hb_period(ring.basis, X, omega, samples)
    a0 = omega * hb_period(ring.basis, ring.basis.dtheta @ X, omega, samples)[1]
    # the period ends at t = T = t0: the last sample before the start is xs[-1]
    return xs[0], v0, a0, np.vstack([xs, xs])


def check_peak(hb, curve, max_periods: int = RING_PERIODS, tol: float = RING_TOL) -> dict:
    """Ring time integrations at the sector curve's refined peak (module docstring).

    Parameters
    ----------
    hb : SectorHB (point contacts; its ``mu`` is the ring's)
    curve : solve.Curve with ``peak_omega`` [rad/s] and ``peak_x`` (sector harmonics)
    max_periods, tol : bounds of each integration (:data:`RING_PERIODS`, :data:`RING_TOL`)

    Returns
    -------
    dict: :func:`harmonic_balance.steady_state.compare`'s record on max |u_a - mean| [m],
    plus hb_amplitude_h1, h1_from_rest, h1_from_hb_state (first harmonics [m]), hb_mean,
    mean_from_rest, mean_from_hb_state (means of u_a [m]), stuck_links, periods (from rest,
    from the HB state), settle_error, converged, steps_per_period, blades, cpu_s, time_s;
    or ``{"method": ..., "note": why}`` when the check cannot run.
    """
    from ..steady_state import compare
    from .timeint import march_ring

    method = "ring time integration at the peak frequency from rest and from the HB state"
    x, w = curve.peak_x, float(curve.peak_omega)
    if x is None or not np.isfinite(w):
        return {"method": method, "note": "no refined peak"}
    from .hb import SectorHB

    if type(hb) is not SectorHB:
        return {"method": method, "note": "the ring time integration takes point contacts on the tuned sector"}
    if hb.mu != hb.sector.cfg.mu:
        return {"method": method, "note": "the ring time integration takes the configuration's friction coefficient"}
    t0, p0 = time.perf_counter(), time.process_time()
    kw = {"cf": hb.cf, "f0": hb.f0, "max_periods": max_periods, "tol": tol}
    rest = march_ring(hb.sector, [w], **kw)
    own = march_ring(hb.sector, [w], start=ring_start(hb, x, w), **kw)
    c0 = float(np.mean(hb.basis.E @ hb.response(x)))
    rec = compare(w, hb.amplitude_max(x), rest["amplitude_max"][0], own["amplitude_max"][0], method,
                  "max|u_a - mean| of blade 0")
    return rec | {"hb_amplitude_h1": float(hb.amplitude_h1(x)), "h1_from_rest": float(rest["amplitude"][0]),
                  "h1_from_hb_state": float(own["amplitude"][0]), "hb_mean": c0,
                  "mean_from_rest": float(rest["mean"][0]), "mean_from_hb_state": float(own["mean"][0]),
                  "stuck_links": stuck_contacts(hb, x, w), "periods": [rest["periods"], own["periods"]],
                  "settle_error": [float(rest["settle_error"][0]), float(own["settle_error"][0])],
                  "converged": bool(rest["converged"][0] and own["converged"][0]),
                  "steps_per_period": int(own["steps_per_period"]), "blades": hb.sector.cfg.ring_blades,
                  "cpu_s": time.process_time() - p0, "time_s": time.perf_counter() - t0}


def annotate(hb, curve, check: bool = False) -> dict:
    """A point-contact curve's ``stuck_links`` at its peak and, with ``check``, its
    ``steady_state`` (:func:`check_peak`) and ``steady_state_warning``
    (:func:`harmonic_balance.steady_state.warning`): the keys of its JSON."""
    from ..steady_state import warning
    from .hb import SectorHB

    out = {}
    if type(hb) is SectorHB and curve.peak_x is not None:
        out["stuck_links"] = stuck_contacts(hb, curve.peak_x, curve.peak_omega)
    if check:
        rec = check_peak(hb, curve)
        out |= {"steady_state": rec, "steady_state_warning": warning(rec)}
    return out
