"""``damper tangential``: virgin curve T(u), k_t and stick/slip maps of a contact.

Examples::

    damper tangential --body sphere --radius 0.01 --force 200 --mu 0.5 --grid 21 --json
    damper tangential --body cylinder --diameter 5e-3 --length 1.2e-3 --force 120 --mu 0.5 --out curve.json
    damper tangential --body cylinder --diameter 5e-3 --length 1.2e-3 --approach 5e-6 --mu 0.5

``--force`` holds the normal force (CNF), ``--approach`` the normal approach
(CND). The curve runs from zero to gross slip (T = mu N) with points chosen
where it bends. ``--tangential-force T`` adds the state at T in force control
(refused above mu N); ``--loop-amplitude A`` adds a hysteresis loop 0 -> A ->
-A -> A computed by the contact model, compared with Masing's loop.
"""
from __future__ import annotations

import argparse

from .normal import add_body_options


def register(subparsers) -> None:
    """Add the ``tangential`` subcommand."""
    p = subparsers.add_parser(
        "tangential", help="tangential contact: virgin curve, k_t, stick/slip maps",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_body_options(p)
    p.add_argument("--eccentricity", type=float, default=None,
                   help="flat face: x position of the normal resultant [m] (CNF only)")
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--force", type=float, help="normal force N [N] (constant normal force, CNF)")
    load.add_argument("--approach", type=float, help="normal approach [m] (constant normal displacement, CND)")
    p.add_argument("--mu", type=float, required=True, help="friction coefficient (> 0)")
    p.add_argument("--model", choices=("real", "halfspace", "bem"), default="real",
                   help="real FE bodies, FE blocks with a curved gap, or the half-space BEM")
    p.add_argument("--tangential-force", type=float, default=None,
                   help="also solve at this tangential force [N] (force control)")
    p.add_argument("--loop-amplitude", type=float, default=None,
                   help="also compute a hysteresis loop at this displacement amplitude [m]")
    p.add_argument("--tol", type=float, default=None, help="curve step tolerance (fraction of mu N)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--out", help="write the virgin-curve file (JSON) here")
    p.add_argument("--plot", metavar="DIR", help="save curve, stick/slip and traction plots in DIR")
    p.add_argument("--no-cache", action="store_true", help="do not use the condensation cache")
    p.add_argument("--cache-dir", default=None, help="condensation cache folder")
    p.set_defaults(func=run)


def spec_from_args(args):
    """The ``ContactSpec`` of the body options, built by ``damper normal``'s own reader.

    The BEM model uses the FE half-space spec (same zone and grid).
    """
    import argparse as _argparse

    from damper.cli.normal import spec_from_args as normal_spec

    fields = vars(args) | {"model": "halfspace" if args.model == "bem" else args.model, "curve": 0}
    return normal_spec(_argparse.Namespace(**fields))


def run(args) -> int:
    """Compute the virgin curve; print JSON, write the curve file and plots as asked."""
    import shlex
    import sys

    from contact_core import tangential_run
    from contact_core.curve import write_curve
    from contact_core.tangential_curve import CURVE_TOL
    from damper.cache import Store
    from damper.cli.common import check_out_dir, check_out_file, print_json

    _check_finite(args)
    spec = spec_from_args(args)
    check_load_options(args, spec)
    check_out_file(args.out, "--out")
    check_out_dir(args.plot, "--plot")
    command = "damper " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    result = tangential_run.run(spec, args.mu, force=args.force, approach=args.approach,
                                eccentricity=args.eccentricity, model=args.model,
                                cache=False if args.no_cache else Store(args.cache_dir).prepare(),
                                tol=CURVE_TOL if args.tol is None else args.tol, command=command)
    for warning in result.warnings:
        print(f"damper tangential: warning: {warning}", file=sys.stderr)
    extra = _extras(result, args)
    if args.out:
        write_curve(result.curve, args.out)
    if args.plot:
        from contact_core.tangential_plots import plot_all

        plot_all(result.virgin, result.problem, args.plot, _reference_curve(result))
        if "loop" in extra:
            from contact_core.tangential_plots import plot_loop

            plot_loop(extra.pop("_loop_path"), args.loop_amplitude, result.curve.u,
                      result.curve.T, args.plot)
    extra.pop("_loop_path", None)
    if args.json:
        print_json(summary(result) | extra)
    else:
        s = summary(result)
        print(f"{s['load_case']}: N = {s['normal_force']:.6g} N, mu = {s['mu']:g}, "
              f"k_t = {s['k_t']:.6g} N/m, k_n = {s['k_n']:.6g} N/m, gross slip at "
              f"u = {s['u'][-1]:.6g} m ({len(s['u'])} points)")
    return 0


def _check_finite(args) -> None:
    import math

    for name in ("force", "approach", "mu", "tangential_force", "loop_amplitude", "tol",
                 "radius", "diameter", "length", "width", "height", "E", "nu", "E2", "nu2",
                 "eccentricity", "p_design"):
        v = getattr(args, name, None)
        if v is not None and not math.isfinite(v):
            raise ValueError(f"--{name.replace('_', '-')} must be finite, got {v}")
    from damper import limits

    if not args.mu > 0:
        raise ValueError(f"--mu must be > 0 (a friction coefficient), got {args.mu:g}")
    if args.mu > limits.MAX_MU:
        raise ValueError(f"--mu {args.mu:g} is above the limit {limits.MAX_MU:g}: dry contacts have mu "
                         "below a few; a larger value is a typo")
    if args.tol is not None and not limits.MIN_CURVE_TOL <= args.tol < 0.5:
        raise ValueError(f"--tol must lie in [{limits.MIN_CURVE_TOL:g}, 0.5), got {args.tol:g}: the curve's "
                         "points grow as tol^-1/2 (1e-6: ~30 times the default 1e-3's)")
    if args.loop_amplitude is not None and not args.loop_amplitude > 0:
        raise ValueError(f"--loop-amplitude must be > 0, got {args.loop_amplitude:g}")


def check_load_options(args, spec) -> None:
    """Load options that do not go together, refused before the FE work."""
    if args.eccentricity is not None:
        if args.force is None:
            raise ValueError("--eccentricity places the normal force: it needs --force (CNF), not --approach")
        spec.kind.check_eccentricity(spec, args.eccentricity)
    if args.tangential_force is not None and args.force is not None:
        limit = args.mu * args.force
        if abs(args.tangential_force) > limit:
            raise ValueError(f"--tangential-force {args.tangential_force:g} N exceeds the gross-slip limit mu N = "
                             f"{limit:g} N: no static solution in force control; give |T| <= {limit:g} N")


def summary(result) -> dict:
    """The JSON object of a run (SI units)."""
    path, prob, spec = result.virgin, result.problem, result.spec
    out = {"load_case": result.load_case, "model": result.model, "body": spec.body,
           "u": path.u, "T": path.T, "k_t": prob.k_t, "k_n": result.k_n,
           "normal_force": prob.N, "approach": float(result.normal.q[0]), "mu": prob.mu,
           "gross_slip_force": prob.mu * prob.N, "gross_slip_displacement": float(path.u[-1]),
           "stick_fraction": path.stick_fraction, "iterations": int(path.iterations.sum()),
           "iterations_per_point": path.iterations, "normal_iterations": result.normal.iterations,
           "contact_nodes": prob.n_c, "grid": result.curve.grid, "timings": result.timings,
           "warnings": result.warnings}
    out.update(spec.kind.tangential_reference(spec, prob.N, prob.mu))
    return out


def _reference_curve(result):
    """The body kind's closed-form virgin curve (Cattaneo-Mindlin for a sphere), or None."""
    spec, prob = result.spec, result.problem
    return spec.kind.tangential_reference_curve(spec, prob.N, prob.mu)


def _check_loop_amplitude(amplitude: float, u_gross: float) -> None:
    """A loop amplitude [m] between :data:`damper.limits.MIN_LOOP_SLIPS` and ``MAX_LOOP_SLIPS``
    times the gross-slip displacement ``u_gross`` [m] (refused before the loop is marched)."""
    from damper.limits import MAX_LOOP_SLIPS, MIN_LOOP_SLIPS

    if amplitude < MIN_LOOP_SLIPS * u_gross:
        raise ValueError(f"--loop-amplitude {amplitude:g} m is below {MIN_LOOP_SLIPS:g} times the gross-slip "
                         f"displacement {u_gross:.4g} m, under the tangential solve's tolerance; give at least "
                         f"{MIN_LOOP_SLIPS * u_gross:.4g} m (a loop that small is a straight line of slope k_t)")
    if amplitude > MAX_LOOP_SLIPS * u_gross:
        raise ValueError(f"--loop-amplitude {amplitude:g} m is above {MAX_LOOP_SLIPS:g} times the gross-slip "
                         f"displacement {u_gross:.4g} m: the loop is then sliding almost throughout (energy "
                         f"~ 4 mu N A) and its points grow as A; give at most {MAX_LOOP_SLIPS * u_gross:.4g} m")


def _extras(result, args) -> dict:
    """Force-control point and hysteresis loop, when asked."""
    from contact_core import tangential_curve as tc
    from contact_core.tangential_reference import masing_loop_energy

    out = {}
    prob = result.problem
    if args.tangential_force is not None:
        sol = tc.virgin_point(prob, T=args.tangential_force)
        out["force_control"] = {"T": sol.T, "u": sol.delta, "stick_fraction": sol.stick_fraction,
                                "iterations": sol.iterations}
    if args.loop_amplitude is not None:
        _check_loop_amplitude(args.loop_amplitude, float(result.curve.u[-1]))
        path, energy = tc.hysteresis_loop(prob, args.loop_amplitude)
        W_masing = masing_loop_energy(args.loop_amplitude, result.curve.u, result.curve.T)
        out["loop"] = {"amplitude": args.loop_amplitude, "u": path.u, "T": path.T,
                       "W_direct": energy["W_friction"], "W_area": energy["W_area"],
                       "W_masing": W_masing, "T_amplitude": energy["T_amplitude"]}
        out["_loop_path"] = path  # for --plot; not printed
    return out
