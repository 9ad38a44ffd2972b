"""The condensed surface's march: what its samples per period and its periods cost and change.
==============================================================================================

The condensed surface element
(:class:`harmonic_balance.surface_condensed.CondensedSurface`) marches its nodes over
the AFT samples of ``PERIODS`` periods inside every residual evaluation: the samples are
both the DFT's and the march's time steps, so an evaluation's cost is proportional to
their number. This script solves one UPD-24 frequency with the condensed sector
(:class:`harmonic_balance.bladed_disk.surface_hb.CondensedSurfaceSectorHB`) at several
sample counts and periods, each by Newton from one solution (``--start``, a ``.npy`` of
``examples/upd_surface_peak.py --save-x``; else the stuck start, which converges at a
well-loaded damper such as CF 300 N), and prints per case the first harmonic of u_a,
its difference from the first case's, the Newton evaluations and the CPU time of one
evaluation with its Jacobian at the solution (the second there: the first fills the
element's factor cache, as a curve's earlier points do)::

    python examples/surface_march_resolution.py --cf 120 --nodes 5 --harmonics 7 --at 466.03 \\
        --start out/np_cf120_n5_H7.npy --samples 256,128,512,64 --periods 2,3,1

(The first sample count is the reference, at ``--periods``' first value; each further
sample count runs at that period count, each further period count at the first sample
count.) ``--json FILE`` writes the rows with the revision.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from damper.bench.common import revision
from damper.cache import Store
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk import solve
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB
from harmonic_balance.surface_condensed import CondensedSurface


def case(sector, surfaces, H: int, cf: float, f: float, n_t: int, periods: int, start) -> tuple:
    """One (samples, periods) case: its row and its solution."""
    hb = CondensedSurfaceSectorHB(sector, surfaces, H, cf=cf, n_t=n_t)
    for el in hb.model.elements:
        if isinstance(el, CondensedSurface):
            el.periods = periods
    w = 2 * np.pi * f
    p0 = time.process_time()
    x = solve.start_point(hb, w) if start is None else solve.solve_point(hb, w, start, max_iter=80)
    p1 = time.process_time()
    evaluations = hb.evaluations
    hb(x, w)   # the element's factor cache filled as a curve's later points find it
    p2 = time.process_time()
    hb(x, w)
    row = {"samples": hb.basis.n_t, "periods": periods, "amplitude_h1": float(hb.amplitude_h1(x)),
           "evaluations": evaluations, "solve_cpu_s": p1 - p0,
           "eval_jac_cpu_s": time.process_time() - p2}
    return row, x


def main(argv=None) -> int:
    from damper.script import numbers

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cf", type=float, default=120.0, help="centrifugal load [N]")
    ap.add_argument("--nodes", type=int, default=5, help="surface nodes per side")
    ap.add_argument("--harmonics", type=int, default=7, help="harmonic count H")
    ap.add_argument("--at", type=float, default=466.03, help="frequency [Hz]")
    ap.add_argument("--start", help="a solution (.npy, the sector's unknowns) to start Newton from")
    ap.add_argument("--samples", type=numbers(int), default="256,128,512", help="samples per period, comma-separated")
    ap.add_argument("--periods", type=numbers(int), default="2,1", help="periods marched, comma-separated")
    ap.add_argument("--json", metavar="FILE", help="write the rows here")
    args = ap.parse_args(argv)
    samples, periods = args.samples, args.periods
    if min(periods) < 1 or min(samples) <= 2 * args.harmonics:
        ap.error("periods must be >= 1 and samples > 2 H")
    sector = Sector(load_config(None))
    try:   # a node count out of its bound, a start file that is missing or not an array
        surfaces = build_surfaces(sector.cfg, args.nodes, args.cf, Store().prepare())
        start = None if args.start is None else np.load(args.start)
    except (ValueError, OSError) as err:
        ap.error(str(err))
    cases = [(n, periods[0]) for n in samples] + [(samples[0], p) for p in periods[1:]]
    rows = []
    print(f"{'samples':>7s} {'periods':>7s} {'|u_a,1| [m]':>14s} {'difference':>11s} "
          f"{'evaluations':>11s} {'eval+J [s]':>10s}")
    for n_t, p in cases:
        row, x = case(sector, surfaces, args.harmonics, args.cf, args.at, n_t, p, start)
        start = x if start is None else start   # every case from the same solution
        row["difference"] = row["amplitude_h1"] / rows[0]["amplitude_h1"] - 1 if rows else 0.0
        rows.append(row)
        print(f"{row['samples']:7d} {p:7d} {row['amplitude_h1']:14.8e} {row['difference']:+11.2e} "
              f"{row['evaluations']:11d} {row['eval_jac_cpu_s']:10.2f}", flush=True)
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({"revision": revision() or "unknown", "command": " ".join(sys.argv),
                                               "cf": args.cf, "nodes": args.nodes, "harmonics": args.harmonics,
                                               "frequency_hz": args.at, "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
