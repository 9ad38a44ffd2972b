"""Eccentric normal load on the flat damper face (thesis Chapter 3, section 3.3.1, cases e0-e8).

A flat face W x L on a plane under a normal force N whose resultant sits at
x = e: the distant face of the damper body gets a rigid approach and a
rotation about y (a linearly varying, i.e. non-uniform, imposed displacement),
found by Newton iteration on force and moment (``contact_core.normal.solve_force``,
the thesis's "iterative algorithm checks the normal force and the eccentricity").
e0 is the centred load; e1-e3 keep the whole face in contact, e4-e8 lift part
of it. For each: the pressure map, the virgin curve to gross slip, and the
Masing loop area at a common amplitude relative to e0.

The thesis gives the eccentricities only in figures (Figs. 45-46), so the cases
here are shares of the half-width W/2 chosen to span full and partial contact.
"""
from __future__ import annotations

import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

#: Worker processes are spawned, not forked: a fork of a process whose BLAS or
#: other libraries already run threads can deadlock on a lock held at the fork
#: (seen: the study test hung inside the full test session).
SPAWN = multiprocessing.get_context("spawn")

#: The thesis's damper width DW (section 3.1) taken as the face width across
#: which the load is offset, and a face length [m] (the text gives no other
#: face dimension; Figs. 36-37 are not in the text).
WIDTH, LENGTH = 1.2e-3, 5e-3
#: Height of the damper body above the face [m]: the thesis models half of a
#: damper of radius DR = 5 mm cut through its axis (section 3.1), so the
#: distant face (the cut) lies about DR above the contact face. The library's
#: default (0: max(W, L/2) = 2.5 mm here) is kept for the other commands.
HEIGHT = 5e-3
#: Body heights [m] of the k_t-against-height check (centred load, finest grid).
HEIGHTS = (1.25e-3, 2.5e-3, 5e-3, 10e-3)
#: Normal force of the plane-on-plane study (thesis 3.2, 3.3: NF = 500 N) and mu.
FORCE, MU = 500.0, 0.5
#: Eccentricity e_k / (W/2) of cases e0-e8.
SHARES = (0.0, 0.1, 0.2, 0.3, 0.45, 0.55, 0.65, 0.75, 0.85)
#: Three grids for the Richardson estimates (full: the zone spacing halves,
#: W/6, W/12, W/24); the k_t-against-height check runs in the full study only.
FULL = {"grids": (7, 13, 25), "heights": HEIGHTS}
QUICK = {"grids": (5, 7, 9), "heights": ()}


def run_case(k: int, e: float, grid: int, height: float, cache_dir) -> dict:
    """Normal state, equilibrium residuals and virgin curve of case e_k."""
    from contact_core import normal, tangential_run
    from contact_core.spec import ContactSpec

    spec = ContactSpec(body="flat", width=WIDTH, length=LENGTH, grid=grid, height=height)
    t0 = time.perf_counter()
    run = tangential_run.run(spec, MU, force=FORCE, eccentricity=e, model="halfspace", cache=cache_dir)
    cc, sol = run.contact, run.normal
    F, M = normal.resultants(cc, sol.f)
    weight = cc.grid.mult * cc.grid.area
    return {"case": f"e{k}", "eccentricity": e, "force_residual": abs(F - FORCE) / FORCE,
            "moment_residual": abs(M - FORCE * e) / (FORCE * WIDTH / 2),
            "contact_fraction": float(weight[sol.active].sum() / weight.sum()),
            "rotation": float(sol.q[1]), "k_t": run.problem.k_t,
            "u": run.curve.u.tolist(), "T": run.curve.T.tolist(),
            "x": cc.grid.x.tolist(), "y": cc.grid.y.tolist(), "pressure": (sol.f / cc.grid.area).tolist(),
            "height": height, "cache_hit": bool(cc.meta.get("cache", {}).get("hit")),
            "time_s": time.perf_counter() - t0}


def _pool_map(func, jobs, workers):
    if workers > 1:
        with ProcessPoolExecutor(workers, mp_context=SPAWN) as pool:
            return list(pool.map(func, *zip(*jobs)))
    return [func(*job) for job in jobs]


def _loop_areas(cases) -> None:
    """Masing loop areas at e0's gross-slip displacement, and relative to e0 (in place)."""
    from contact_core.tangential_reference import masing_loop_energy

    amplitude = cases[0]["u"][-1]
    for c in cases:
        c["loop_area"] = masing_loop_energy(amplitude, np.asarray(c["u"]), np.asarray(c["T"]))
        c["loop_area_ratio"] = c["loop_area"] / cases[0]["loop_area"]
        c["amplitude"] = amplitude


def run(quick: bool = False, cache_dir=None, workers: int = 2) -> dict:
    """Cases e0-e8 on three grids (in parallel), Richardson estimates, k_t against body height."""
    from .convergence import richardson

    cfg = QUICK if quick else FULL
    grids = cfg["grids"]
    t0 = time.perf_counter()
    jobs = [(k, s * WIDTH / 2, g, HEIGHT, cache_dir) for g in grids for k, s in enumerate(SHARES)]
    jobs += [(0, 0.0, grids[-1], h, cache_dir) for h in cfg["heights"] if h != HEIGHT]
    runs = _pool_map(run_case, jobs, workers)
    n = len(SHARES)
    per_grid = [runs[k * n:(k + 1) * n] for k in range(len(grids))]
    for cases in per_grid:
        _loop_areas(cases)
    h = [1.0 / (g - 1) for g in grids]
    cases = per_grid[-1]
    for k, c in enumerate(cases):
        c["convergence"] = {key: {"grids": [pg[k][key] for pg in per_grid]}
                            | richardson([pg[k][key] for pg in per_grid], h)
                            for key in ("k_t", "loop_area_ratio", "contact_fraction") if k or key == "k_t"}
    by_height = {HEIGHT: cases[0]["k_t"]} | {r["height"]: r["k_t"] for r in runs[len(grids) * n:]}
    return {"quick": quick, "grids": list(grids), "width": WIDTH, "length": LENGTH, "height": HEIGHT,
            "force": FORCE, "mu": MU, "amplitude": cases[0]["amplitude"], "cases": cases,
            "k_t_by_height": [{"height": k, "k_t": v} for k, v in sorted(by_height.items())],
            "wall_time_s": time.perf_counter() - t0, "cache_hits": sum(r["cache_hit"] for r in runs)}


def table(result: dict) -> str:
    """Text table of the cases (finest grid, Richardson estimates) and k_t against body height."""
    head = ("case", "e [um]", "contact", "k_t [N/m]", "k_t Rich.", "loop/e0", "loop Rich.", "|dF|/F", "|dM|/M")
    widths = (8, 8, 11, 11, 8, 10, 9, 9)
    lines = [f"grids {result['grids']}; flat face W {result['width'] * 1e3:g} mm x L "
             f"{result['length'] * 1e3:g} mm, body height {result['height'] * 1e3:g} mm, N {result['force']:g} N",
             f"{head[0]:5s} " + " ".join(f"{h:>{w}s}" for h, w in zip(head[1:], widths))]
    for c in result["cases"]:
        conv = c["convergence"]
        loop_r = conv.get("loop_area_ratio", {"value": 1.0})["value"]
        lines.append(f"{c['case']:5s} {c['eccentricity'] * 1e6:8.1f} {100 * c['contact_fraction']:7.1f}% "
                     f"{c['k_t']:11.4g} {conv['k_t']['value']:11.4g} {c['loop_area_ratio']:8.3f} "
                     f"{loop_r:10.3f} {c['force_residual']:9.1e} {c['moment_residual']:9.1e}")
    lines.append("k_t of the centred load against the body height: " + ", ".join(
        f"{r['height'] * 1e3:g} mm {r['k_t']:.4g} N/m" for r in result["k_t_by_height"]))
    return "\n".join(lines)
