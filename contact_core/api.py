"""One-call normal contact analysis: condense (or load from cache), solve, report.

Used by the ``damper normal`` command and the examples. SI units throughout.
"""
from __future__ import annotations

import time

import numpy as np

from . import normal, report
from .condense import condense
from .condensed import CondensedContact
from .spec import ContactSpec


def hertz_reference(spec: ContactSpec, force: float) -> dict | None:
    """Analytic reference values of the pair at ``force`` (None without a closed form)."""
    return spec.kind.reference(spec, force)


def solve(cc: CondensedContact, force=None, approach=None, eccentricity=None):
    """Force control (``force`` [N], flat face ``eccentricity`` [m]) or displacement
    control (``approach`` [m]); exactly one of force and approach."""
    if (force is None) == (approach is None):
        raise ValueError("give exactly one of force and approach")
    if force is not None:
        return normal.solve_force(cc, force, eccentricity)
    if not (np.isfinite(approach) and approach > 0):
        raise ValueError(f"approach must be positive, got {approach!r}")
    sol = normal.solve_displacement(cc, approach)
    if not sol.active.any():
        raise ValueError(f"approach {approach:g} m does not close the initial gap")
    return sol


def curve(cc: CondensedContact, forces: np.ndarray, eccentricity=None) -> dict:
    """F-approach curve: approach [m], k_n [N/m], contact area [m^2] at each force [N]."""
    out = {"force": [], "approach": [], "k_n": [], "contact_area": []}
    for F in forces:
        sol = normal.solve_force(cc, float(F), eccentricity)
        T = normal.tangent(cc, sol.active)
        out["force"].append(float(F))
        out["approach"].append(float(sol.q[0]))
        out["k_n"].append(float(T[0, 0]))
        out["contact_area"].append(float(np.sum(cc.grid.mult * cc.grid.area * sol.active)))
    return out


def run_normal(spec: ContactSpec, force=None, approach=None, eccentricity=None,
               cache=None, curve_points: int = 0) -> dict:
    """Condense, solve and summarise one normal load case.

    Returns
    -------
    dict
        The ``report.summarize`` scalars, plus ``hertz`` (reference values and
        relative errors), ``maps`` (per-node arrays), ``curve`` (if
        ``curve_points`` > 0: forces from 5 % to 100 % of the solved force),
        ``timings`` [s] and ``meta``.
    """
    kind = spec.kind
    kind.check_eccentricity(spec, eccentricity)
    t0 = time.perf_counter()
    cc = condense(spec, cache=cache)
    t1 = time.perf_counter()
    sol = solve(cc, force, approach, eccentricity)
    t2 = time.perf_counter()
    out = report.summarize(cc, sol, kind)
    if out["zone_edge_in_contact"]:
        raise ValueError("the contact reaches the edge of the potential contact zone: raise the "
                         "design pressure (--p-design) so the zone holds this load, or the grid "
                         "if it is very coarse")
    ref = hertz_reference(spec, out["force"])
    if ref is not None:
        out["hertz"] = dict(ref, **kind.reference_errors(out, ref))
    out["maps"] = report.maps(cc, sol)
    if curve_points > 0:
        out["curve"] = curve(cc, np.linspace(0.05, 1.0, curve_points) * out["force"], eccentricity)
    out["timings"] = dict(cc.meta["timings"], condense_total=t1 - t0, solve=t2 - t1)
    out["meta"] = {k: cc.meta[k] for k in ("spec", "symmetry", "zone", "spacing", "nodes",
                                            "elements", "dofs", "solver", "cache") if k in cc.meta}
    return out
