"""``damper cosim``: run a ring archive of ``damper system`` in libcosim to its steady state.

Examples::

    damper cosim ring.ssp --frequency-hz 448.25 --periods 300 --json
    damper cosim ring.ssp --frequency-hz 440 --periods 50 --step 5e-7 --json
"""
from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("cosim", help="co-simulate a ring archive (damper system) in libcosim",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("ssp", help="the .ssp archive of damper system")
    p.add_argument("--frequency-hz", type=float, required=True, help="excitation frequency [Hz]")
    p.add_argument("--periods", type=int, default=300,
                   help="most periods to run (stops earlier once settled to --tol)")
    p.add_argument("--step", type=float,
                   help="communication step [s] (default: the archive's, a fraction of the "
                   "coupling limit; rounded down so a period holds whole ns steps)")
    p.add_argument("--tol", type=float, default=None,
                   help="settling tolerance on the first harmonic's change per period "
                   "(extrapolated); 0 runs all --periods (default 1e-4)")
    p.add_argument("--force", action="store_true",
                   help="accept a step above the coupling limit (the coupling may go unstable)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=run)


def run(args) -> int:
    from damper.cosim import SETTLE_TOL
    from damper.cosim import run as cosim

    from .common import print_json

    r = cosim(args.ssp, args.frequency_hz, args.periods, step=args.step, force=args.force,
              tol=SETTLE_TOL if args.tol is None else args.tol)
    if args.json:
        print_json(r)
        return 0
    e = r["energy"]
    change = "-" if r["settle_change"] is None else f"{r['settle_change']:.1e}"
    residual = "-" if e["relative_residual"] is None else f"{e['relative_residual']:+.1e}"
    print(f"{r['frequency_hz']} Hz: first-harmonic amplitude {r['amplitude']:.6e} m "
          f"({r['response_dof']}), {r['periods']} periods ({'settled' if r['settled'] else 'NOT settled'}: "
          f"change {change}), step {r['step']:.4g} s ({r['steps_per_period']} a period, "
          f"limit {r['step_limit']:.3g} s)")
    print(f"last period: excitation {e['excitation']:.6e} J = structural {e['structural']:.6e} + "
          f"dampers {e['damper_friction'] + e['damper_dashpots']:.6e} + stored {e['stored_change']:.1e} "
          f"(residual {residual}); wall {r['wall_time_s']:.1f} s")
    return 0
