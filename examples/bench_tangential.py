"""Benchmark of the tangential stage: error against Cattaneo-Mindlin and time per grid.
====================================================================================

Sphere R = 10 mm on a plane, steel, N = 200 N, mu = 0.5. One line per model
and grid: contact nodes, largest error of the virgin curve against Mindlin
(fraction of mu N), k_t against 8 G* a, time per stage (condense, normal,
tangential) cold and cached (FE models: second run from the condensation
cache; the BEM has no cache, its build is the cold figure), and the process's
peak memory so far (ru_maxrss, so it only grows down the table), and whether the
condensed model came from the cache (hit, miss; - for the BEM). ::

    python examples/bench_tangential.py                       # BEM 21/41/61, FE 11/21
    python examples/bench_tangential.py --bem 21 41 --fe 21 --fe-models halfspace real
    python examples/bench_tangential.py --smoke               # tiny, for the test

Pin BLAS to one thread for these dense problems (OPENBLAS_NUM_THREADS=1): two
threads were up to 4x slower on this 2-core machine.
"""
from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time

import numpy as np

from contact_core import hertz, tangential_run
from contact_core import tangential_reference as tr
from contact_core.spec import ContactSpec

R, F, MU = 0.01, 200.0, 0.5


def one(model: str, grid: int, cache) -> dict:
    """Run the sphere case once; errors and stage times."""
    spec = ContactSpec(body="sphere", radius=R, grid=grid, load_hint=F)
    t0 = time.perf_counter()
    run = tangential_run.run(spec, MU, force=F, model=model, cache=cache)
    total = time.perf_counter() - t0
    a = hertz.sphere(F, R, spec.Estar)["a"]
    Gs = tr.shear_modulus_star(spec.E1, spec.nu1, spec.E2, spec.nu2)
    T_ref = tr.mindlin_force(run.virgin.u, run.problem.N, MU, a, Gs)
    return {"nodes": run.problem.n_c, "points": len(run.virgin.points),
            "curve_err": float(np.abs(run.virgin.T - T_ref).max() / (MU * run.problem.N)),
            "kt_err": run.problem.k_t / (8 * Gs * a) - 1.0, "total": total,
            "cache": run.contact.meta.get("cache", {}).get("hit"), **{
                k: run.timings[k] for k in ("condense", "normal", "tangential")}}


def line(model: str, grid: int, label: str, r: dict) -> str:
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB -> MB (Linux)
    return (f"{model:9s} {grid:4d} {label:6s} {r['nodes']:6d} {r['points']:6d} "
            f"{r['curve_err']:9.2e} {r['kt_err']:+8.2%} {r['condense']:9.3f} {r['normal']:7.3f} "
            f"{r['tangential']:7.3f} {r['total']:7.3f} {peak:8.0f} "
            f"{ {None: '-', True: 'hit', False: 'miss'}[r['cache']]:>5s}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bem", type=int, nargs="*", default=[21, 41, 61], help="BEM grids")
    parser.add_argument("--fe", type=int, nargs="*", default=[11, 21], help="FE grids")
    parser.add_argument("--fe-models", nargs="*", default=["halfspace", "real"])
    parser.add_argument("--smoke", action="store_true", help="BEM 9 and FE 5 only")
    args = parser.parse_args(argv)
    if args.smoke:
        args.bem, args.fe, args.fe_models = [9], [5], ["halfspace"]
    print(f"{'model':9s} {'grid':>4s} {'run':6s} {'nodes':>6s} {'points':>6s} {'err/muN':>9s} "
          f"{'k_t err':>8s} {'condense':>9s} {'normal':>7s} {'tang.':>7s} {'total':>7s} {'peak MB':>8s} {'cache':>5s}")
    for g in args.bem:
        print(line("bem", g, "cold", one("bem", g, False)), flush=True)
    with tempfile.TemporaryDirectory(prefix="bench_tangential_") as cache:
        for model in args.fe_models:
            for g in args.fe:
                print(line(model, g, "cold", one(model, g, cache)), flush=True)
                print(line(model, g, "cached", one(model, g, cache)), flush=True)
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
