"""``damper upd``: bladed disk with an underplatform damper (cyclic sector, HB).

Examples::

    damper upd modes --json
    damper upd frf --cf 120 --f0 30 --harmonics 7 --band 400 500 --json --plot out/upd
    damper upd frf --damper stuck --json
    damper upd frf --contacts surface --surface-nodes 5 --harmonics 1 --band 440 490 --points 5 --json
    damper upd optimize --cf-range 30 3000 --points 20 --json --plot out/upd
    damper upd optimize --contacts surface --harmonics 3 --json   # slow: minutes per load
    damper upd mistuning --std 0.02 --samples 200 --seed 1 --workers 2 --json --plot out/mt
    damper upd mistuning --blades 4 --engine-order 1 --factors 1.04 0.97 1 0.99 --json
    damper upd mistuning --accuracy 0.01 --samples 20 --json   # H chosen on the tuned sector
"""
from __future__ import annotations

import numpy as np

from damper.upd_frf import SURFACE_MODEL, SURFACE_NODES, surface_line
from damper.upd_surface import SURFACE_MODELS

from .common import accuracy_lines, upd_model_options, upd_response_options
from .upd_mistuning import register as register_mistuning


def register(sub) -> None:
    p = sub.add_parser("upd", help="bladed disk with an underplatform damper (UPD-24 default)",
                       description=__doc__.split("\n\n")[0])
    s = p.add_subparsers(dest="upd_command", metavar="ACTION")
    s.required = True
    m = s.add_parser("modes", help="free and stuck natural frequencies per nodal diameter")
    upd_model_options(m)
    m.set_defaults(func=run_modes)
    f = s.add_parser("frf", help="forced response of the EO excitation (nonlinear or linear limits)")
    upd_model_options(f)
    upd_response_options(f)
    f.add_argument("--harmonics", type=int, default=7, help="highest harmonic H (0..H kept; with "
                   "--accuracy the first one tried)")
    f.add_argument("--accuracy", type=float, metavar="TOL",
                   help="relative accuracy of the peak amplitude, in (1e-6, 0.5): the curve is traced at "
                   "--harmonics, then its peak alone is re-solved with more harmonics (up to 80) until "
                   "the estimated truncation error is below TOL (default: the fixed --harmonics, "
                   "its estimate reported, a warning above 1 %%)")
    f.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"), help="band [Hz]")
    f.add_argument("--points", type=int, default=200, help="frequency points")
    f.add_argument("--check-steady-state", action="store_true",
                   help="time-integrate the ring at the peak from rest and from the harmonic balance's "
                   "state: says whether the curve is the state a start from rest reaches (seconds; "
                   "point contacts)")
    f.add_argument("--plot", metavar="DIR", help="write upd_frf.png here")
    _contacts(f, surface=True)
    f.set_defaults(func=run_frf)
    o = s.add_parser("optimize", help="peak response against CF and the optimal load")
    upd_model_options(o)
    o.add_argument("--cf-range", type=float, nargs=2, default=(30.0, 3000.0), metavar=("LO", "HI"))
    o.add_argument("--points", type=int, help=f"number of CF values (log-spaced; default {LOAD_POINTS}, "
                   f"with --contacts surface {SURFACE_LOAD_POINTS})")
    o.add_argument("--harmonics", type=int, default=7, help="highest harmonic H of the load sweep "
                   "(with --accuracy the first one tried)")
    o.add_argument("--accuracy", type=float, metavar="TOL",
                   help="relative accuracy of the optimum's peak amplitude, in (1e-6, 0.5): its curve is "
                   "raised in H until the estimate is below TOL, and the sweep re-run at that H "
                   "(default: the fixed --harmonics, the optimum's estimate reported)")
    o.add_argument("--grid", type=int, help=f"frequency points per curve (default {GRID}; not with "
                   "--contacts surface, whose peaks are searched by Brent's method)")
    o.add_argument("--workers", type=int, help=f"processes for the load grid (default {WORKERS}; results "
                   "do not depend on it; not with --contacts surface, which walks the loads in one process)")
    o.add_argument("--plot", metavar="DIR", help="write upd_optimize.png here")
    _contacts(o, surface=True, slow=True)
    o.set_defaults(func=run_optimize)
    register_mistuning(s)


#: ``upd optimize``'s --grid and --workers with point contacts when not given.
GRID, WORKERS = 40, 2
#: ``upd optimize``'s --points when not given: with point contacts, and with surfaces, whose
#: every load is a peak search of minutes (the refinement between the neighbours of the
#: smallest walked peak then finds the optimum, as with points).
LOAD_POINTS, SURFACE_LOAD_POINTS = 20, 8


def _contacts(p, surface: bool = False, slow: bool = False) -> None:
    """--contacts and, with ``surface``, the surface options; ``slow``: ``upd optimize``'s
    help, which says what a sweep with surfaces costs."""
    what = ("; surface: the damper's faces as contact surfaces of many 3D points on the "
            "condensed FE bodies (damper.upd_surface; slower)")
    if slow:
        what = ("; surface: the damper's faces as contact surfaces (damper.upd_surface, the condensed "
                "model): SLOW, a peak search of minutes per load (~1 s CPU per residual evaluation at 5 "
                "nodes per side, ~120 evaluations per load at H 7); the loads walked from the largest down, each "
                "warm-started from the last; the estimate is printed before the walk")
    p.add_argument("--contacts", choices=("toml", "geometry") + (("surface",) if surface else ()),
                   default="toml",
                   help="contact laws: the TOML's Jenkins points, or computed by contact_core "
                   "from the [geometry] section (damper.upd_geometry; cached)" + (what if surface else ""))
    if surface:
        p.add_argument("--surface-nodes", type=int, metavar="N",
                       help="with --contacts surface: contact-zone nodes per side of each face "
                       f"(5 .. 41; default {SURFACE_NODES})")
        p.add_argument("--surface-model", choices=SURFACE_MODELS,
                       help="with --contacts surface: condensed (default): the faces condensed onto "
                       "their rigid inputs, the nodes marched in time in each evaluation, the first "
                       "point reached by a path in CF from the load where the stuck damper keeps its "
                       "faces closed (~1 s per evaluation at 5 nodes per side, ~2.5 s at 10); nodes: "
                       "every node's DOFs as unknowns (needs a well-loaded damper, UPD-24: CF ~300 N)")


def check_surface_nodes(args) -> None:
    """``--surface-nodes`` and ``--surface-model`` only with ``--contacts surface`` (refused
    otherwise); their defaults there."""
    model = getattr(args, "surface_model", None)
    if args.contacts == "surface":
        args.surface_nodes = SURFACE_NODES if args.surface_nodes is None else args.surface_nodes
        args.surface_model = SURFACE_MODEL if model is None else model
        return
    for opt, value in (("--surface-nodes", args.surface_nodes), ("--surface-model", model)):
        if value is not None:
            raise ValueError(f"{opt} goes with --contacts surface (got --contacts {args.contacts}): "
                             f"add --contacts surface or drop {opt}")


def _sector(args):
    from damper.upd_frf import upd_sector

    return upd_sector(args)


def run_modes(args) -> int:
    from harmonic_balance.bladed_disk.sector import modes_table

    from .common import print_json

    tab = modes_table(_sector(args))
    if args.json:
        print_json(tab)
        return 0
    print("ND  free modes [Hz]                     stuck modes [Hz] (first 3)")
    for nd, fr, st in zip(tab["nodal_diameter"], tab["free_hz"], tab["stuck_hz"]):
        print(f"{nd:2d}  {' '.join(f'{v:9.2f}' for v in fr[:3])}   {' '.join(f'{v:9.2f}' for v in st[:3])}")
    return 0


def _check_frf(args) -> None:
    """Every option of ``upd frf``, before the model (or its contacts) is built."""
    from damper import limits

    from .common import check_accuracy_option, check_out_dir

    if args.band is not None:
        limits.check_omega_range("--band", *args.band, unit="Hz", scale=2 * np.pi)
        if not args.band[0] < args.band[1]:
            raise ValueError(f"--band {args.band[0]:g} {args.band[1]:g}: give LO < HI [Hz]")
    limits.check_size("--points", args.points, 3, limits.MAX_UPD_POINTS,
                      "each frequency point is a harmonic-balance solve (~7 ms at H = 7; 10000 points ~1 min)")
    limits.check_size("--harmonics", args.harmonics, 1, limits.MAX_UPD_HARMONICS,
                      limits.harmonics_why(limits.MAX_UPD_HARMONICS))
    check_accuracy_option(args.accuracy)
    limits.check_load("--cf", args.cf)
    limits.check_load("--f0", args.f0)
    check_out_dir(args.plot, "--plot")
    check_surface_nodes(args)
    from damper.upd_surface import check_options

    check_options(args)
    if args.damper == "nonlinear":
        limits.check_cf_floor("--cf", args.cf, args.f0, args.config)


def run_frf(args) -> int:
    import sys

    from damper.upd_frf import frf_record

    from .common import print_json, print_warnings

    _check_frf(args)
    out = frf_record(args)
    if args.plot:
        _plot_frf(out, args.plot)
    if args.json:
        print_json(out)
    else:
        at = ("" if "harmonics_peak" not in out else
              f" at H = {out['harmonics_peak']} (curve at H = {out['harmonics']})")
        what = "largest amplitude at the band's end" if out["band_end_warning"] else "peak"
        print(f"{what} {out['peak_frequency_hz']:.4f} Hz, first-harmonic amplitude "
              f"{out['peak_amplitude']:.6e} m{at} ({out['time_s']:.2f} s"
              + ("" if out.get("cpu_s") is None else f", {out['cpu_s']:.2f} s CPU") + ")")
        if "warning" in out:
            print(f"warning: {out['warning']}")
        if out.get("zone_edge_warning"):
            print(out["zone_edge_warning"])
        if "surface_model" in out:
            print(surface_line(out["surface_model"]))
    from harmonic_balance.steady_state import summary_lines

    print_warnings(out, ("band_end_warning", "lift_off_warning"), args.json)
    for line in accuracy_lines(out) + summary_lines(out.get("steady_state")):
        if not args.json or line.startswith("warning"):
            print(line, file=sys.stderr if args.json else sys.stdout)
    return 0


def _check_optimize(args) -> None:
    """Every option of ``upd optimize``, before the model (or its contacts) is built."""
    from damper import limits

    from .common import check_accuracy_option, check_out_dir

    lo, hi = args.cf_range
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi <= limits.MAX_MAGNITUDE):
        raise ValueError(f"--cf-range {lo:g} {hi:g}: give 0 < LO < HI <= {limits.MAX_MAGNITUDE:g} [N]")
    if args.points is None:
        args.points = SURFACE_LOAD_POINTS if args.contacts == "surface" else LOAD_POINTS
    limits.check_size("--points", args.points, 3, limits.MAX_LOAD_POINTS,
                      "each CF value is a whole forced response (seconds)")
    limits.check_size("--harmonics", args.harmonics, 1, limits.MAX_UPD_HARMONICS,
                      limits.harmonics_why(limits.MAX_UPD_HARMONICS))
    check_surface_nodes(args)
    from damper.upd_surface import check_optimize_options

    check_optimize_options(args)
    if args.contacts != "surface":
        args.grid = GRID if args.grid is None else args.grid
        args.workers = WORKERS if args.workers is None else args.workers
        limits.check_size("--grid", args.grid, 3, limits.MAX_UPD_GRID,
                          "each frequency point is a harmonic-balance solve of the sector")
        limits.check_workers("--workers", args.workers)
    check_accuracy_option(args.accuracy)
    check_out_dir(args.plot, "--plot")
    limits.check_cf_floor("--cf-range", lo, None, args.config, "or start the range there")


def run_optimize(args) -> int:
    import sys
    import time

    from damper import limits
    from harmonic_balance.accuracy import warning
    from harmonic_balance.bladed_disk.accuracy import optimal_load_to_accuracy, optimum_truncation
    from harmonic_balance.bladed_disk.optimize import optimal_load

    from .common import print_json

    _check_optimize(args)
    sector = _sector(args)
    if args.contacts == "surface":
        from damper.upd_surface import optimize_record

        out = optimize_record(sector, args, note=lambda line: print(line, file=sys.stderr, flush=True))
    elif args.accuracy is None:
        out = optimal_load(sector, args.cf_range, args.points, args.harmonics, grid=args.grid,
                           workers=args.workers)
        out["truncation_error"] = optimum_truncation(sector, out, args.grid, limits.MAX_UPD_HARMONICS)
    else:
        t0 = time.perf_counter()
        out = optimal_load_to_accuracy(sector, args.cf_range, args.accuracy, args.points,
                                       args.harmonics, args.grid, args.workers, limits.MAX_UPD_HARMONICS)
        out["time_s"] = time.perf_counter() - t0  # both sweeps and the curves that chose H
    out["truncation_warning"] = warning(out["truncation_error"])
    out |= {"contacts_from_geometry": args.contact_report} if "contact_report" in args else {}
    if args.plot:
        _plot_optimize(out, args.plot)
    if args.json:
        print_json(out)
    else:
        print(f"optimum CF {out['optimum_cf']:.4g} N, peak {out['optimum_peak_amplitude']:.5e} m "
              f"({out['method']}, H = {out['harmonics']}, {out['time_s']:.1f} s)")
        line = flat_band_line(out.get("optimum_band_cf"), args.cf_range)
        if line:  # the minimum is flat: the CF range a design can use
            print(line)
        if "surface_model" in out:
            from damper.upd_surface import optimize_line

            print(optimize_line(out["surface_model"]))
    if "warning" in out:   # a surface walk that stopped above the range's low end
        print(f"warning: {out['warning']}", file=sys.stderr if args.json else sys.stdout)
    for line in accuracy_lines(out):
        if not args.json or line.startswith("warning"):
            print(line, file=sys.stderr if args.json else sys.stdout)
    return 0


def flat_band_line(band, cf_range) -> str | None:
    """The printed CF interval of a peak within 1 % of the optimum; an end the load sweep
    does not bracket (None) is named as beyond the swept range."""
    if not band:
        return None
    if band[0] is None and band[1] is None:
        return (f"peak within 1 % of the optimum over the whole CF range {cf_range[0]:.4g} ... "
                f"{cf_range[1]:.4g} N (widen --cf-range to find where it rises)")
    lo = f"below {cf_range[0]:.4g}" if band[0] is None else f"{band[0]:.4g}"
    hi = f"above {cf_range[1]:.4g}" if band[1] is None else f"{band[1]:.4g}"
    return f"peak within 1 % of the optimum for CF {lo} ... {hi} N"


def _plot_frf(out, out_dir) -> None:
    from pathlib import Path

    from damper.upd_frf import plot_frf

    plot_frf(out, Path(out_dir) / "upd_frf.png")


def _plot_optimize(out, out_dir) -> None:
    from pathlib import Path

    from damper.run.backbone_stages import plot_optimal_load

    plot_optimal_load(out, Path(out_dir) / "upd_optimize.png")
