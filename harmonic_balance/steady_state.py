"""Which steady state: the harmonic balance's peak against time integrations at its frequency.

A friction-damped structure can have more than one periodic response at one frequency:
a Jenkins slider that never slips over the period is a periodic solution for *any*
constant offset of its spring force within the slip limit, so the mean position of a
stuck slider (and with it the zeroth harmonic of every DOF) depends on the history that
led to the steady state; stick-slip oscillators also have coexisting periodic solutions
of different slip patterns. The harmonic balance fixes the stuck slider's mean by a
convention (stuck since its virgin state at u = 0, :mod:`aft`) and follows one branch;
a structure started from rest may settle elsewhere.

:func:`check_peak` answers the question at the refined peak of a forced-response curve
with two time integrations of the same model (:func:`timeint.march`, the C core's
element law, no Fourier series) at the peak frequency:

* from rest, elements virgin: the state a start from rest reaches;
* from the harmonic balance's state: displacements and velocities of the HB period at
  t = 0, each slider having been run through that period beforehand (``history``), so it
  carries the HB loop's past.

Both share the time discretisation and the missing harmonics, so their difference
measures the steady states alone, not the truncation in H: when they settle at peak
amplitudes more than :data:`SAME_STATE_TOL` apart, the HB branch is not the state a start
from rest reaches (``states_differ``). The HB state's own drift (``hb_state_drift``: the
second time integration against the HB peak) is the truncation in H plus, for an
unstable HB branch, the departure to another state.

:func:`stuck_links` names the links that never slip at a solution: their mean is the
convention's (cheap: one element evaluation).
"""
from __future__ import annotations

import time

import numpy as np

#: Relative difference of the two time integrations' peak |x| above which they are reported
#: as different steady states: the accuracy a default run promises (1 %, the truncation
#: warning's level). Runs that reach the same state agree to ~1e-5 (their settling
#: tolerance CHECK_TOL and the shared step); a stuck slider's offset left by a transient
#: moves the peak by its mean displacement: 0.11 % on the bench's 5-mass chain between
#: a start from rest and one from its H = 7 state (response mean -0.0064 against -5e-5 m),
#: 9.9 % on a preloaded single-DOF oscillator whose start from rest slips the slider once.
SAME_STATE_TOL = 1e-2
#: Time steps per period of the check (raised for stability by :mod:`timeint`): the
#: step error of central differences near a stick-slip peak is ~1e-4 at 512 (the
#: bench's 5-mass chain: 256 and 512 steps differ by 1e-4); it is common to both runs.
CHECK_STEPS = 512
#: Settling tolerance (timeint's extrapolated distance to steady state) and the period
#: limit of the check's time integrations.
CHECK_TOL = 1e-7
CHECK_PERIODS = 3000


def stuck_links(problem, x) -> list[str]:
    """Names of the friction links that never slip over the period at solution ``x``.

    Their loop is the straight stuck line: no energy dissipated, the force mean fixed
    by the harmonic balance's convention (virgin at u = 0), not by the dynamics.
    """
    from .aft import STUCK_RTOL

    names = []
    for link, (u, F, W) in zip(problem.residual.elements, problem.residual.link_samples(x)):
        k0 = getattr(link, "k0", None)
        if k0 is None or F is None or W > 0.0:
            continue
        if np.ptp(F - k0 * u) <= STUCK_RTOL * (k0 * np.ptp(u) + np.abs(F).max() + 1e-300):
            names.append(getattr(link, "name", "") or f"link{len(names)}")
    return names


def hb_period(basis, X: np.ndarray, omega: float, samples: int):
    """Displacements over one HB period and the velocity at t = 0.

    Parameters
    ----------
    basis : FourierBasis
    X : (n_b, n) array, harmonics of every DOF [m]
    omega : float [rad/s]
    samples : int, samples per period

    Returns
    -------
    x : (samples, n) array at t = j T / samples [m]; v0 : (n,) array [m/s]
    """
    from .fourier import FourierBasis

    E = FourierBasis(basis.harmonics, samples).E   # the same coefficient order as basis
    return E @ X, omega * (E[0] @ (basis.dtheta @ X))


def _mean(hist) -> float:
    return float(np.mean(hist))


def check_peak(result, steps_per_period: int = CHECK_STEPS) -> dict:
    """Time integrations at the refined peak from rest and from the HB state (module docstring).

    Parameters
    ----------
    result : FRFResult with ``problem`` and ``peak_solution`` (a matrix model: M, C, K)
    steps_per_period : int

    Returns
    -------
    dict: method, omega [rad/s], hb_amplitude, from_rest, from_hb_state (peak |x_r| [m]),
    hb_mean, mean_from_rest, mean_from_hb_state (mean of x_r [m]), rest_vs_hb (from_rest /
    hb_amplitude - 1), states_rel (|from_rest / from_hb_state - 1|), hb_state_drift
    (from_hb_state / hb_amplitude - 1), states_differ (bool), stuck_links, periods
    (from rest, from the HB state), converged, time_s; or ``{"method": ..., "note": why}``
    when the check cannot run.
    """
    from .timeint import march

    method = "time integration at the peak frequency from rest and from the HB state"
    prob, x = result.problem, result.peak_solution
    if prob is None or x is None or not np.isfinite(result.peak_omega):
        return {"method": method, "note": "no refined peak"}
    model = prob.model
    if model.linear.K is None or model.linear.M is None:
        return {"method": method, "note": "the time integration needs M, C, K matrices"}
    t0, w, r = time.perf_counter(), float(result.peak_omega), model.response_dof
    X = prob.residual.displacements(x, w)
    xs, v0 = hb_period(prob.basis, X, w, 4 * steps_per_period)
    rest = march(model, w, steps_per_period, CHECK_PERIODS, CHECK_TOL)
    # twice through the HB period: a virgin slider reaches the periodic loop within the first
    hb = march(model, w, steps_per_period, CHECK_PERIODS, CHECK_TOL, x0=xs[0], v0=v0,
               history=np.vstack([xs, xs]))
    rec = compare(w, float(result.peak_amplitude), rest.amplitude, hb.amplitude, method)
    return rec | {"hb_mean": float(X[0, r]) if prob.basis.harmonics[0] == 0 else 0.0,
                  "mean_from_rest": _mean(rest.x_last), "mean_from_hb_state": _mean(hb.x_last),
                  "stuck_links": stuck_links(prob, x), "periods": [rest.periods, hb.periods],
                  "converged": bool(rest.converged and hb.converged),
                  "steps_per_period": hb.steps_per_period, "time_s": time.perf_counter() - t0}


def compare(omega: float, hb_amplitude: float, from_rest: float, from_hb_state: float,
            method: str, quantity: str | None = None) -> dict:
    """The comparison of a check (the one shared by every model): peak amplitudes [m] of the
    harmonic balance and of the time integrations from rest and from its state at ``omega``
    [rad/s] -> the record's omega, hb_amplitude, from_rest, from_hb_state, rest_vs_hb
    (from_rest / hb_amplitude - 1), states_rel (|from_rest / from_hb_state - 1|),
    hb_state_drift (from_hb_state / hb_amplitude - 1), states_differ (states_rel >
    :data:`SAME_STATE_TOL`) and, when given, ``quantity``: what the amplitudes are, named
    in the text (default: the model's max|x| of the response DOF)."""
    hb_amplitude, from_rest, from_hb_state = float(hb_amplitude), float(from_rest), float(from_hb_state)
    states = abs(from_rest / from_hb_state - 1.0)
    return {"method": method, "omega": float(omega), "hb_amplitude": float(hb_amplitude),
            "from_rest": float(from_rest), "from_hb_state": float(from_hb_state),
            "rest_vs_hb": from_rest / hb_amplitude - 1.0, "states_rel": states,
            "hb_state_drift": from_hb_state / hb_amplitude - 1.0,
            "states_differ": bool(states > SAME_STATE_TOL)} | ({"quantity": quantity} if quantity else {})


def annotate(result, check: bool = False):
    """A refined curve's ``extra["stuck_links"]`` (at its peak) and, when ``check``, its
    ``extra["steady_state"]`` (:func:`check_peak`) and ``extra["steady_state_warning"]``;
    in place, returns ``result``. The check's time is added to ``result.time_s``."""
    prob, x = getattr(result, "problem", None), getattr(result, "peak_solution", None)
    if prob is not None and x is not None:
        result.extra["stuck_links"] = stuck_links(prob, x)
    if check:
        rec = result.extra["steady_state"] = check_peak(result)
        result.extra["steady_state_warning"] = warning(rec)
        result.time_s += rec.get("time_s", 0.0)
    return result


def warning(record: dict | None) -> str | None:
    """The summary's warning line when the HB peak is not the state a start from rest reaches."""
    if not record or not record.get("states_differ"):
        return None
    stuck = record.get("stuck_links") or []
    why = (f"; links that never slip there (their mean is a convention of the harmonic balance): "
           f"{', '.join(stuck)}" if stuck else "")
    return (f"warning: at the peak (omega = {record['omega']:.6g} rad/s) a start from rest settles at "
            f"peak |x| {record['from_rest']:.6g} m, {100 * record['rest_vs_hb']:+.2g} % from the harmonic "
            f"balance's {record['hb_amplitude']:.6g} m, which the time integration started from the "
            f"harmonic balance's state keeps ({record['from_hb_state']:.6g} m): two steady states{why}")


def summary_lines(record: dict | None) -> list[str]:
    """Text lines of a check (empty without one)."""
    if not record:
        return []
    if "note" in record:
        return [f"steady state: not checked ({record['note']})"]
    what = f", {record['quantity']}" if record.get("quantity") else ""
    line = (f"steady state (time integration at the peak{what}): from rest {record['from_rest']:.6g} m, "
            f"from the harmonic balance's state {record['from_hb_state']:.6g} m, harmonic balance "
            f"{record['hb_amplitude']:.6g} m (from rest {100 * record['rest_vs_hb']:+.2g} % from the harmonic "
            f"balance, {record['states_rel']:.1e} from the run started on its state)"
            + ("" if record.get("converged", True) else "; not settled within the period limit"))
    w = warning(record)
    return [line] + ([w] if w else [])
