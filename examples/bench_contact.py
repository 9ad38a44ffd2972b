"""Benchmark of the normal contact stage: error against Hertz vs time and memory.
==============================================================================

Each case runs in its own process twice: cold (empty cache: mesh, assembly,
condensation, solve) and cached (the condensed matrices loaded from disk, then
the solve). Peak memory is the process's maximum resident set. Prints a table
and writes ``bench_contact.json`` into ``--out``::

    python examples/bench_contact.py [--out out/bench] [--quick] [--solver scipy] [--qp]

``--qp`` instead times the bounded-QP solvers on each case's condensed normal
compliance at its load (one displacement-controlled solve): the toolkit's
projected Newton (``contact_core.qp``) against scipy's ``nnls`` and
``lsq_linear`` (bvls) on the Cholesky form, with their disagreement.

Goal: sphere, 41x41 grid, contact radius and p0 within 0.5 % of
Hertz, 20 s cold and 1 s cached end to end on a 2-core machine.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: (body, model, grid, force [N]); sphere R = 10 mm, cylinder D = 5 mm, L = 1.2 mm.
CASES = (
    ("sphere", "real", 11, 200.0), ("sphere", "real", 21, 200.0), ("sphere", "real", 31, 200.0),
    ("sphere", "real", 41, 200.0), ("sphere", "halfspace", 21, 200.0), ("sphere", "halfspace", 41, 200.0),
    ("cylinder", "real", 21, 350.0),
)
QUICK = (("sphere", "halfspace", 5, 200.0),)


def child(body: str, model: str, grid: int, force: float, cache_dir: str) -> dict:
    """One timed run in this process (called in a subprocess)."""
    t0 = time.perf_counter()
    from contact_core import api
    from contact_core.spec import ContactSpec

    t_import = time.perf_counter() - t0
    geo = {"radius": 0.01} if body == "sphere" else {"radius": 2.5e-3, "length": 1.2e-3}
    spec = ContactSpec(body=body, model=model, grid=grid, **geo)
    t1 = time.perf_counter()
    r = api.run_normal(spec, force=force, cache=cache_dir)
    wall = time.perf_counter() - t1
    h = r["hertz"]
    return {"case": f"{body}/{model}", "grid": grid, "dofs": r["meta"]["dofs"],
            "contact_nodes": r["n_contact_nodes"], "err_size": h["error_size"], "err_p0": h["error_p0"],
            "err_approach": h.get("error_approach"), "timings": r["timings"],
            "cache_hit": r["meta"]["cache"]["hit"], "solver": r["meta"]["solver"],
            "end_to_end": wall, "import": t_import,
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def _spawn(case, cache_dir, solver=None) -> dict:
    cmd = [sys.executable, __file__, "--child", *map(str, case), cache_dir]
    env = dict(os.environ, OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS", "2"))
    if solver:
        env["DAMPER_SOLVER"] = solver
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def run(cases=CASES, solver=None) -> list[dict]:
    """Cold and cached run of every case; returns one row per case."""
    rows = []
    for case in cases:
        with tempfile.TemporaryDirectory(prefix="damper_bench_") as cache_dir:
            cold = _spawn(case, cache_dir, solver)
            warm = _spawn(case, cache_dir, solver)
        rows.append({"cold": cold, "cached": warm})
        _print_row(cold, warm)
    return rows


def _print_row(c: dict, w: dict) -> None:
    t = c["timings"]
    if not hasattr(_print_row, "done"):
        print(f"{'case':18s} {'grid':>4s} {'DOF':>15s} {'err a/b':>8s} {'err p0':>7s} {'err d':>7s} "
              f"{'mesh':>5s} {'asm':>5s} {'cond':>6s} {'solve':>6s} {'cold':>6s} {'cached':>6s} {'peak MB':>7s} solver")
        _print_row.done = True
    dofs = "+".join(str(d) for d in c["dofs"])
    ed = f"{100 * c['err_approach']:+6.2f}%" if c["err_approach"] is not None else "      -"
    print(f"{c['case']:18s} {c['grid']:4d} {dofs:>15s} {100 * c['err_size']:+7.2f}% {100 * c['err_p0']:+6.2f}% "
          f"{ed} {t['mesh']:5.2f} {t['assembly']:5.2f} {t['condensation']:6.2f} {t['solve']:6.3f} "
          f"{c['end_to_end']:6.2f} {w['end_to_end']:6.3f} {max(c['peak_mb'], w['peak_mb']):7.0f} {c['solver']}")


def qp_table(cases=CASES) -> list[dict]:
    """Time the QP solvers on each case (see the module docstring)."""
    import numpy as np
    import scipy.linalg as sla
    from scipy import optimize

    from contact_core import normal
    from contact_core.condense import condense
    from contact_core.spec import ContactSpec

    def nnls(C, b):
        L = np.linalg.cholesky(C)
        return optimize.nnls(L.T, -sla.solve_triangular(L, b, lower=True), maxiter=10 * b.size)[0]

    def bvls(C, b):
        L = np.linalg.cholesky(C)
        return optimize.lsq_linear(L.T, -sla.solve_triangular(L, b, lower=True), bounds=(0, np.inf),
                                   method="bvls", tol=1e-14).x

    solvers = {"projected Newton": lambda C, b: normal.lcp(C, b)[0], "scipy nnls": nnls, "scipy bvls": bvls}
    rows = []
    print(f"{'case':28s} {'n':>5s} " + " ".join(f"{k:>17s}" for k in solvers) + "  max rel. difference")
    for body, model, grid, force in cases:
        geo = {"radius": 0.01} if body == "sphere" else {"radius": 2.5e-3, "length": 1.2e-3}
        cc = condense(ContactSpec(body=body, model=model, grid=grid, **geo), cache=None)
        q = normal.solve_force(cc, force).q
        b = cc.grid.h - cc.rigid @ q
        row = {"case": f"{body} {model} {grid}x{grid}", "n": b.size}
        f = {}
        for name, solve in solvers.items():
            t0 = time.perf_counter()
            f[name] = solve(cc.Czz, b)
            row[name] = time.perf_counter() - t0
        diff = max(np.abs(v - f["projected Newton"]).max() for v in f.values()) / f["projected Newton"].max()
        row["max_difference"] = float(diff)
        rows.append(row)
        print(f"{row['case']:28s} {b.size:5d} " + " ".join(f"{1e3 * row[k]:14.1f} ms" for k in solvers)
              + f"  {diff:.1e}")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--quick", action="store_true", help="one tiny case (smoke test)")
    ap.add_argument("--solver", choices=("cholmod", "pardiso", "scipy"), default=None,
                    help="force one sparse back end (default: the first available of cholmod, pardiso, scipy)")
    ap.add_argument("--qp", action="store_true", help="time the bounded-QP solvers instead")
    ap.add_argument("--child", nargs=5, metavar=("BODY", "MODEL", "GRID", "FORCE", "CACHE"),
                    help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        b, m, g, f, c = args.child
        print(json.dumps(child(b, m, int(g), float(f), c)))
        return 0
    if args.qp:
        qp_table(QUICK if args.quick else CASES)
        return 0
    rows = run(QUICK if args.quick else CASES, args.solver)
    from contact_core.fileio import atomic_write

    atomic_write(Path(args.out) / "bench_contact.json", json.dumps(rows, indent=1) + "\n")
    print("cold/cached: end to end in-process time [s] (condense + solve + report); "
          "timings of stages from the cold run")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
