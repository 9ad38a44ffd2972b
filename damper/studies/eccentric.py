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

#: The thesis's damper face width DW (section 3.1) and a face length [m].
WIDTH, LENGTH = 1.2e-3, 5e-3
#: Normal force of the plane-on-plane study (thesis 3.2, 3.3: NF = 500 N) and mu.
FORCE, MU = 500.0, 0.5
#: Eccentricity e_k / (W/2) of cases e0-e8.
SHARES = (0.0, 0.1, 0.2, 0.3, 0.45, 0.55, 0.65, 0.75, 0.85)
FULL = {"grid": 21, "height": 0.0}
QUICK = {"grid": 9, "height": 0.0}


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
            "time_s": time.perf_counter() - t0}


def run(quick: bool = False, cache_dir=None, workers: int = 2) -> dict:
    """All cases e0-e8 (in parallel), loop areas relative to e0 at e0's gross-slip displacement."""
    from contact_core.tangential_reference import masing_loop_energy

    cfg = QUICK if quick else FULL
    t0 = time.perf_counter()
    jobs = [(k, s * WIDTH / 2, cfg["grid"], cfg["height"], cache_dir) for k, s in enumerate(SHARES)]
    if workers > 1:
        with ProcessPoolExecutor(workers, mp_context=SPAWN) as pool:
            cases = list(pool.map(run_case, *zip(*jobs)))
    else:
        cases = [run_case(*job) for job in jobs]
    amplitude = cases[0]["u"][-1]  # e0's gross-slip displacement
    for c in cases:
        c["loop_area"] = masing_loop_energy(amplitude, np.asarray(c["u"]), np.asarray(c["T"]))
    for c in cases:
        c["loop_area_ratio"] = c["loop_area"] / cases[0]["loop_area"]
    return {"quick": quick, "grid": cfg["grid"], "width": WIDTH, "length": LENGTH, "force": FORCE,
            "mu": MU, "amplitude": amplitude, "cases": cases, "wall_time_s": time.perf_counter() - t0}


def table(result: dict) -> str:
    """Text table of the cases."""
    head = ("case", "e [um]", "contact", "k_t [N/m]", "loop/e0", "|dF|/F", "|dM|/M")
    lines = [f"{head[0]:5s} " + " ".join(f"{h:>{w}s}" for h, w in zip(head[1:], (8, 8, 11, 8, 9, 9)))]
    for c in result["cases"]:
        lines.append(f"{c['case']:5s} {c['eccentricity'] * 1e6:8.1f} {100 * c['contact_fraction']:7.1f}% "
                     f"{c['k_t']:11.4g} {c['loop_area_ratio']:8.3f} {c['force_residual']:9.1e} "
                     f"{c['moment_residual']:9.1e}")
    return "\n".join(lines)
