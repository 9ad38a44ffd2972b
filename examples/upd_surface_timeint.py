"""UPD-24 with contact surfaces: the sector harmonic balance against the ring time integration.
============================================================================================

The damper's faces as planar contact surfaces (``damper upd frf --contacts surface``,
:class:`harmonic_balance.bladed_disk.surface_hb.SurfaceSectorHB`) solved by harmonic
balance at one frequency per harmonic count, and the short ring of the same sectors
marched in time to its periodic steady state
(:func:`harmonic_balance.bladed_disk.timeint.march_ring` with ``surfaces``), which
shares with the HB only the model. Prints one row per harmonic count: the first
harmonic of blade 0's u_a from both, their difference, and the time integration's
periods, step count and cost per step.

Full run (``python examples/upd_surface_timeint.py``: CF 120 N, 448 Hz, H 3, 5, 7, steady
state to 1e-5): about an hour on a shared 2-core machine (~1300 steps per period at
20-30 ms each, a few hundred periods). ``--quick`` runs the same code for two periods at
H 1 (no steady state: a smoke run of the path, not a comparison).
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from damper.cache import Store
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk import solve
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.surface_hb import SurfaceSectorHB
from harmonic_balance.bladed_disk.timeint import march_ring


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cf", type=float, default=120.0, help="centrifugal load [N]")
    ap.add_argument("--freq", type=float, default=448.0, help="frequency [Hz]")
    ap.add_argument("--nodes", type=int, default=5, help="surface nodes per side")
    ap.add_argument("--harmonics", default="3,5,7", help="HB harmonic counts, comma-separated")
    ap.add_argument("--tol", type=float, default=1e-5, help="steady-state tolerance of the march")
    ap.add_argument("--periods", type=int, default=1500, help="most periods marched")
    ap.add_argument("--quick", action="store_true", help="two periods, H 1: a smoke run")
    args = ap.parse_args(argv)
    if args.quick:
        args.harmonics, args.periods = "1", 2
    cfg = load_config(None)
    sector = Sector(cfg)
    surfaces = build_surfaces(cfg, args.nodes, args.cf, Store().prepare())
    omega = 2 * np.pi * args.freq
    t0 = time.perf_counter()
    ti = march_ring(sector, [omega], cf=args.cf, max_periods=args.periods, tol=args.tol,
                    surfaces=surfaces)
    t_ti = time.perf_counter() - t0
    print(f"ring time integration, CF {args.cf:g} N, {args.freq:g} Hz, {args.nodes} nodes per side: "
          f"|u_a,1| = {ti['amplitude'][0]:.6e} m, {int(ti['periods'][0])} periods "
          f"({'settled' if ti['converged'][0] else 'NOT settled'}), {ti['steps_per_period']} steps "
          f"per period, {1e3 * t_ti / ti['time_steps']:.1f} ms per step")
    print(f"{'H':>3} {'HB |u_a,1| [m]':>15} {'TI - HB':>9} {'HB time [s]':>11}")
    for H in (int(h) for h in args.harmonics.split(",")):
        t0 = time.perf_counter()
        hb = SurfaceSectorHB(sector, surfaces, H, cf=args.cf)
        a = hb.amplitude_h1(solve.start_point(hb, omega))
        # a march that has not settled is no reference: no difference printed (quick mode)
        diff = f"{ti['amplitude'][0] / a - 1:>+9.2%}" if ti["converged"][0] else f"{'-':>9}"
        print(f"{H:>3} {a:>15.6e} {diff} {time.perf_counter() - t0:>11.1f}")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
