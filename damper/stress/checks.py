"""Invariant checks of one stage's JSON result: equilibrium, force bounds, energy balance.

Each check returns ``(worst_residual, message)``: the largest relative violation
found (0 when every invariant holds to round-off) and what was violated (empty
when nothing). A residual above ``TOL`` makes the case "wrong".
"""
from __future__ import annotations

import math

import numpy as np

#: Contact size off Hertz by more than this without the ``under_resolved`` flag is a
#: silently wrong number: grids of 11 nodes resolve a Hertz contact to ~5-10 %.
HERTZ_SIZE_TOL = 0.25
#: A contact radius beyond this fraction of the body radius is outside what Hertz and a
#: half-space model represent (a/R small): accepted without a refusal it is a wrong number.
CONTACT_SIZE_LIMIT = 0.5
#: Largest relative violation of an invariant that counts as round-off. The
#: solvers stop at ~1e-9 relative (normal active set, tangential march); 1e-6
#: leaves three decades of margin and still catches any real error.
TOL = 1e-6


def _finite(out: dict) -> bool:
    """Every number in the (nested) result is finite."""
    stack = [out]
    while stack:
        v = stack.pop()
        if isinstance(v, dict):
            stack.extend(v.values())
        elif isinstance(v, list):
            stack.extend(v)
        elif isinstance(v, float) and not math.isfinite(v):
            return False
    return True


def _worst(pairs) -> tuple[float, str]:
    worst, what = 0.0, ""
    for r, name in pairs:
        if r > worst:
            worst, what = r, name
    return worst, (what if worst > TOL else "")


def _size_check(a, req: dict) -> tuple[float, str]:
    """Contact radius a against CONTACT_SIZE_LIMIT x the body radius (when the case gives one)."""
    R = req.get("radius")
    if not R or a is None:
        return 0.0, ""
    what = f"contact radius {a:.3g} m above {CONTACT_SIZE_LIMIT} R accepted"
    return max(a / (CONTACT_SIZE_LIMIT * R) - 1.0, 0.0), what


def normal(out: dict, req: dict) -> tuple[float, str]:
    """Force equilibrium against the request, no penetration, no tensile contact force."""
    F = req.get("force")
    p = [(abs(out["force"] / F - 1.0), "force equilibrium") if F else (0.0, ""),
         (max(out.get("max_penetration", 0.0), 0.0) / max(out["approach"], 1e-300), "penetration"),
         (max(-out.get("min_force", 0.0), 0.0) / max(abs(out["force"]), 1e-300), "tensile contact force")]
    if out["approach"] < 0 or out["k_n"] <= 0:
        p.append((1.0, "negative approach or k_n"))
    p.append(_size_check(out.get("contact_radius"), req))
    err = abs((out.get("hertz") or {}).get("error_size") or 0.0)
    if err > HERTZ_SIZE_TOL and not out.get("under_resolved"):
        p.append((err, "contact size off Hertz without the under_resolved flag"))
    return _worst(p)


def tangential(out: dict, req: dict) -> tuple[float, str]:
    """Virgin curve monotone, bounded by mu N, ending at gross slip mu N; normal equilibrium."""
    T, u = np.asarray(out["T"]), np.asarray(out["u"])
    muN = out["mu"] * out["normal_force"]
    p = [(max(-np.min(np.diff(T), initial=0.0), 0.0) / muN, "T not monotone"),
         (max(np.max(T) / muN - 1.0, 0.0), "|T| above mu N"),
         (max(-np.min(np.diff(u), initial=0.0), 0.0) / max(u[-1], 1e-300), "u not increasing"),
         (abs(out["gross_slip_force"] / muN - 1.0), "gross slip force != mu N")]
    if req.get("force"):
        p.append((abs(out["normal_force"] / req["force"] - 1.0), "normal force equilibrium"))
    p.append(_size_check((out.get("mindlin") or {}).get("contact_radius"), req))
    return _worst(p)


def loop(out: dict, req: dict) -> tuple[float, str]:
    """|F| <= the slip force; energy per cycle between 0 and the rigid-plastic bound 4 F_s a."""
    F = np.asarray(out["F"])
    Fs = out["gross_slip_force"]
    a = out["displacement_amplitude"]
    E = out["energy_per_cycle"]
    scale = max(4.0 * Fs * a, 1e-300)
    p = [(max(np.max(np.abs(F)) / Fs - 1.0, 0.0) if Fs > 0 else float(np.max(np.abs(F)) > 0), "|F| above slip force"),
         (max(-E, 0.0) / scale, "negative dissipation"),
         (max(E / scale - 1.0, 0.0), "dissipation above 4 F_s a")]
    return _worst(p)


def frf(out: dict, req: dict) -> tuple[float, str]:
    """Energy bound of every point: input work pi F X1 >= viscous loss pi c w X1^2, so X1 <= F / (c w)."""
    w = np.asarray(out["omega"])
    X1 = np.asarray(out["amplitude_h1"])
    bound = req["force"] / (req["damping"] * w)
    p = [(max(float(np.max(X1 / bound)) - 1.0, 0.0), "amplitude above the energy bound F/(c w)"),
         (float(np.any(X1 < 0)), "negative amplitude")]
    if not str(out.get("status", "complete")).startswith("complete"):  # "complete; warning: ..." is complete
        p.append((1.0, f"status {out.get('status')}"))
    return _worst(p)


def fmu(out: dict, req: dict) -> tuple[float, str]:
    """|F| <= mu N, W never decreases, input work - W (the stored energy) between 0 and its bound.

    The input work is summed by the trapezoidal rule, whose error on a step where
    F is monotone is at most |dF du| / 2: ``slack`` (their sum) widens both bounds.
    """
    muN = out["slip_force"]
    scale = max(out["work_scale"], 1e-300)
    slack = out["slack"]
    p = [(max(out["max_abs_F"] / muN - 1.0, 0.0), "|F| above mu N"),
         (max(-out["min_dW"], 0.0) / scale, "W decreased"),
         (max(-out["stored"] - slack, 0.0) / scale, "negative stored energy"),
         (max(out["stored"] - out["stored_bound"] - slack, 0.0) / scale, "stored energy above its bound")]
    return _worst(p)


CHECKS = {"normal": normal, "tangential": tangential, "loop": loop, "frf": frf, "fmu": fmu}


def check(stage: str, out: dict, req: dict) -> tuple[str, float, str]:
    """Outcome ("converged", "nan" or "wrong"), worst residual and message of a finished case."""
    if not _finite(out):
        return "nan", float("nan"), "non-finite number in the result"
    worst, what = CHECKS[stage](out, req)
    if what:
        return "wrong", worst, f"{what} (relative violation {worst:.2e})"
    return "converged", worst, ""
