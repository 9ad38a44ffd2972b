"""``damper study cylinders|compression|eccentric``: the thesis's studies, recomputed.

    damper study cylinders [--quick] [--plot DIR] [--json]
    damper study compression [--quick] [--plot DIR] [--json]
    damper study eccentric [--quick] [--plot DIR] [--json]

``cylinders``: delta = C F^a L^-b D^c fits of the normal and tangential approach
of the thesis's Table II cylinders (eqs. 2.11, 2.14, Tables III, V).
``compression``: the cylinder's own share of the approach (section 2.2.5,
Table I cylinders). ``eccentric``: flat damper face under an eccentric normal
load, cases e0-e8 (section 3.3.1). ``--quick`` runs a coarse version. Sweeps run
in two processes sharing the condensation cache.
"""
from __future__ import annotations

import argparse

from .common import print_json

STUDIES = ("cylinders", "compression", "eccentric")


def register(subparsers) -> None:
    """Add the ``study`` subcommand."""
    p = subparsers.add_parser("study", help="the thesis's studies (cylinder laws, compression, eccentric load)",
                              description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("name", choices=STUDIES)
    p.add_argument("--quick", action="store_true", help="coarse version (under a minute)")
    p.add_argument("--plot", metavar="DIR", help="write the study's figures in DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--workers", type=int, default=2, help="parallel processes (default 2)")
    p.add_argument("--cache-dir", default=None, help="condensation cache folder")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run one study; print its table or JSON; plot as asked."""
    from damper import limits
    from damper.cache import Store

    from .common import check_out_dir

    limits.check_workers("--workers", args.workers)
    check_out_dir(args.plot, "--plot")
    store = Store(args.cache_dir).prepare()
    if args.name == "eccentric":
        from damper.studies import eccentric as study
    else:
        from damper.studies import cylinders as study
    result = study.run(quick=args.quick, cache_dir=store, workers=args.workers)
    if args.name == "compression":
        result = {"quick": result["quick"], "grids": result["grids"], "models": result["compression"],
                  "sphere": result["compression_sphere"], "wall_time_s": result["wall_time_s"]}
    if args.plot:
        from damper.studies import plots

        plots.plot(args.name, result, args.plot)
    if args.json:
        print_json(result)
    elif args.name == "compression":
        _print_compression(result)
    else:
        print(study.table(result))
    return 0


def _print_compression(result: dict) -> None:
    """Body-1 shares of the approach: at the centre, and outside the contact (~3 b)."""
    for m in [*result["models"], result["sphere"]]:
        name = f"cylinder {m['cylinder']}" if "cylinder" in m else "sphere"
        size = f"D {m['D'] * 1e3:g} mm" + (f" L {m['L'] * 1e3:g} mm" if "L" in m else "")
        far = [v for v in m["body1_share_far"] if v is not None]
        print(f"{name} {size}: "
              f"share at centre {100 * min(m['body1_share']):.0f}-{100 * max(m['body1_share']):.0f} %, "
              f"outside the contact {100 * min(far, default=float('nan')):.0f}-"
              f"{100 * max(far, default=float('nan')):.0f} % (forces {m['force'][0]:g}-{m['force'][-1]:g} N)")
