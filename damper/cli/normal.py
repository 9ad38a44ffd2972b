"""``damper normal``: normal contact of a sphere, cylinder or flat face on a plane.

FE bodies (scikit-fem meshes), Guyan condensation onto the contact nodes (cached
on disk), active-set normal solve (thesis Appendix A.1). Prints one JSON object
with ``--json``; SI units. Keys: force [N], approach [m], contact_area [m^2],
p_max, p_mean [Pa], k_n = dF/d(approach) [N/m], iterations, newton_steps,
n_contact_nodes, body1_share (body 1's part of the approach at the centre),
body1_share_far (its compression outside the contact at ~3 radii/half-widths,
thesis 2.2.5), max_penetration [m], under_resolved; sphere: contact_radius [m];
cylinder: contact_halfwidth (mid-length), contact_halfwidth_end [m], p_mid_max,
p_end_max [Pa]; flat: rotation [rad], moment [N m], eccentricity [m]; hertz
(reference values, relative errors), timings [s], meta (mesh, DOFs, solver,
cache). ``--out`` adds the per-node maps and the F-approach curve.
``--normal-curve FILE`` writes the normal approach curve N(p) from first touch
(``contact_core.normal_curve``: the normal law of the contact-point FMU, ``damper fmu
--normal FILE``); it takes ``--curve`` points (20 when not given).
"""
from __future__ import annotations

import argparse
import math

from .common import atomic_write, dumps, print_json


def register(subparsers) -> None:
    """Add the ``normal`` subcommand."""
    p = subparsers.add_parser(
        "normal", help="normal contact (FE, condensation, active set): k_n, pressure, area",
        description=__doc__, formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    add_body_options(p)
    p.add_argument("--model", choices=("real", "halfspace"), default="real",
                   help="real half-sphere/half-cylinder, or block on block with curvature in the gap")
    load = p.add_mutually_exclusive_group(required=True)
    load.add_argument("--force", type=float, help="normal force [N] (force control)")
    load.add_argument("--approach", type=float, help="imposed approach [m] (displacement control)")
    p.add_argument("--eccentricity", type=float, default=None,
                   help="flat face: x position of the resultant [m] (rotation about y solved); "
                   "write a negative value as --eccentricity=-1e-4")
    p.add_argument("--curve", type=int, default=0, help="points of an F-approach curve up to the load")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--out", default=None, help="write the full result (with maps, curve) as JSON")
    p.add_argument("--normal-curve", default=None, metavar="FILE",
                   help="write the normal approach curve N(p) (the contact-point FMU's normal law)")
    p.add_argument("--plot", default=None, metavar="DIR", help="write pressure map, contact area, F-approach plots")
    p.add_argument("--no-cache", action="store_true", help="do not use the condensation cache")
    p.add_argument("--cache-dir", default=None,
                   help="condensation cache folder (default $DAMPER_CACHE_DIR or .damper_cache)")
    p.add_argument("--stiffness", nargs=2, metavar=("BODY1", "BODY2"), default=None,
                   help="bring your own bodies: stiffness matrices (.mtx or .npz), one per body")
    p.add_argument("--nodes", nargs=2, metavar=("BODY1", "BODY2"), default=None,
                   help="node files (.npz: coords (N,3), contact, distant[, sym_x0, sym_y0]) for --stiffness")
    p.set_defaults(func=run)


def add_body_options(p) -> None:
    """Body, material and contact-zone options (shared by ``damper normal`` and ``damper tangential``)."""
    from contact_core import bodies

    p.add_argument("--body", choices=bodies.names(), required=True)
    p.add_argument("--radius", type=float, help="sphere or cylinder radius [m]")
    p.add_argument("--diameter", type=float, help="sphere or cylinder diameter [m] (instead of --radius)")
    p.add_argument("--length", type=float, help="cylinder length / flat-face length along y [m]")
    p.add_argument("--width", type=float, help="flat-face width along x [m]")
    p.add_argument("--height", type=float, default=None,
                   help="flat face: height of the damper body above the face [m] (default max(W, L/2))")
    p.add_argument("--E", type=float, default=200e9,
                   help="Young's modulus of body 1 [Pa] (and of the plane unless --E2)")
    p.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio of body 1 (and of the plane unless --nu2)")
    p.add_argument("--E2", type=float, default=None, help="Young's modulus of the plane [Pa]")
    p.add_argument("--nu2", type=float, default=None, help="Poisson's ratio of the plane")
    p.add_argument("--grid", type=int, default=21, help="contact-zone nodes per side (>= 3)")
    p.add_argument("--p-design", type=float, default=None,
                   help="peak pressure [Pa] sizing the potential contact zone (default: the thesis's "
                   "2000 MPa, or, when the Hertz contact of --force would fit inside one grid cell "
                   "of that zone, the Hertz peak pressure of --force)")


#: Geometry fields of a ContactSpec and the options that give them.
_GEOMETRY_FLAGS = {"radius": "--radius or --diameter", "length": "--length", "width": "--width"}


def _radius(args) -> float | None:
    if args.radius is not None and args.diameter is not None:
        raise ValueError("give --radius or --diameter, not both")
    if args.diameter is not None:
        return 0.5 * args.diameter
    return args.radius


def spec_from_args(args):
    """A ``ContactSpec`` from the options; ValueError for missing or bad values."""
    from contact_core import bodies
    from contact_core.spec import ContactSpec

    radius = _radius(args)
    given = {"radius": radius, "length": args.length, "width": args.width}
    for name, flag in _GEOMETRY_FLAGS.items():  # the body kind says what it needs, and no more
        needed = name in bodies.get(args.body).required
        if needed and given[name] is None:
            raise ValueError(f"--body {args.body} needs {flag}")
        if not needed and given[name] is not None:
            raise ValueError(f"{flag} does not apply to --body {args.body} (it takes "
                             f"{', '.join(_GEOMETRY_FLAGS[n] for n in bodies.get(args.body).required)})")
    if getattr(args, "height", None) is not None and args.body != "flat":
        raise ValueError(f"--height applies to the flat face only, not to --body {args.body}")
    if getattr(args, "height", None) is not None and not args.height > 0:  # 0 is not the default height
        raise ValueError(f"--height must be positive, got {args.height:g} (leave it out for max(W, L/2))")
    if args.p_design is not None and not (0 < args.p_design < float("inf")):
        raise ValueError(f"--p-design must be a positive finite pressure [Pa], got {args.p_design:g}")
    if args.force is not None and not args.force > 0:
        raise ValueError(f"--force must be positive, got {args.force}")
    if args.approach is not None and not args.approach > 0:
        raise ValueError(f"--approach must be positive, got {args.approach}")
    if args.curve < 0:
        raise ValueError("--curve must be >= 0")
    spec = ContactSpec(body=args.body, radius=radius or 0.0, length=args.length or 0.0,
                       width=args.width or 0.0, E1=args.E, nu1=args.nu,
                       E2=args.E if args.E2 is None else args.E2,
                       nu2=args.nu if args.nu2 is None else args.nu2, model=args.model,
                       grid=args.grid, p_design=args.p_design or DEFAULT_P_DESIGN,
                       load_hint=args.force or 0.0, height=getattr(args, "height", None) or 0.0)
    if args.p_design is None and args.force:
        spec = zone_for_load(spec, args.force)
    if args.approach is not None and spec.body == "sphere":
        force = sphere_approach_force(spec, args.approach)
        if args.p_design is None:
            spec = zone_for_load(spec, force)
    elif args.approach is not None and spec.body == "cylinder":
        _check_approach_floor(spec, args.approach)
    elif spec.body == "flat":
        _check_flat_load(spec, args.force, args.approach)
    return spec


def _check_approach_floor(spec, approach: float) -> None:
    """A curved body's approach at least that of a Hertz contact radius of MIN_CONTACT_SHARE R
    (the gap at the contact's edge above round-off of the coordinates; an approach of
    5e-324 m gave a zero force and a division by zero)."""
    from contact_core.bodies import MIN_CONTACT_SHARE

    low = MIN_CONTACT_SHARE**2 * spec.radius
    if approach < low:
        raise ValueError(f"--approach {approach:g} m is below {low:.3g} m, what the mesh resolves in double "
                         f"precision for a radius of {spec.radius:.3g} m; give a larger approach")


def _check_flat_load(spec, force, approach) -> None:
    """A flat face's mean pressure (force) or mean strain (approach) inside the library's
    bounds (:meth:`contact_core.bodies.FlatFace.check_load`, ``check_approach``)."""
    if approach is not None:
        _refuse_as("--approach", spec.kind.check_approach, spec, approach)
    if force is not None:
        _refuse_as("--force", spec.kind.check_load, spec, force)


def _refuse_as(option: str, check, *args) -> None:
    """Run ``check``; its ValueError is prefixed with the option it concerns."""
    try:
        check(*args)
    except ValueError as err:
        raise ValueError(f"{option}: {err}") from None


def sphere_approach_force(spec, approach: float) -> float:
    """Hertz force [N] of a sphere's ``approach`` [m] (d = a^2 / R, a^3 = 3 F R / (4 E*)), after
    refusing an approach whose contact radius a lies outside what the contact model
    represents (:data:`contact_core.bodies.MIN_CONTACT_SHARE` ... ``MAX_CONTACT_SHARE`` R)."""
    from contact_core.bodies import MAX_CONTACT_SHARE, MIN_CONTACT_SHARE

    R = spec.radius
    a = math.sqrt(R * approach)
    lo, hi = MIN_CONTACT_SHARE * R, MAX_CONTACT_SHARE * R
    if not lo <= a <= hi:
        raise ValueError(f"--approach {approach:g} m gives a Hertz contact radius of {a:.3g} m, {a / R:.2g} of "
                         f"the sphere radius {R:.3g} m, outside [{MIN_CONTACT_SHARE:g}, {MAX_CONTACT_SHARE:g}] R "
                         f"(what the contact model represents); give an approach in "
                         f"[{lo**2 / R:.3g}, {hi**2 / R:.3g}] m")
    return 4.0 * spec.Estar * a**3 / (3.0 * R)


#: Points of the normal approach curve when --normal-curve is given without --curve.
NORMAL_CURVE_POINTS = 20

#: The thesis's design peak pressure sizing the potential contact zone [Pa].
DEFAULT_P_DESIGN = 2000e6
#: A zone sized from a load holds the Hertz contact of this many times the load:
#: coarse grids spread the discrete contact a cell beyond Hertz's edge (sized
#: for the load itself, 3-5 nodes per side put contact on the zone's edge).
LOAD_ZONE_FACTOR = 3.0


def zone_for_load(spec, force: float):
    """``spec`` with its zone sized from the Hertz contact of ``force`` if that contact
    would fit inside one grid cell of the design pressure's zone.

    Loads that the default zone resolves, even roughly (flagged
    ``under_resolved`` below MIN_NODES_ACROSS spacings), keep it, so their
    results and cached models are unchanged; a load whose contact would fall
    between grid nodes (a 1e-6 N load on a 10 mm sphere came out 45x Hertz's
    radius) gets a zone of its own, sized by its Hertz peak pressure (the zone
    is then ``zone_margin`` times the contact of LOAD_ZONE_FACTOR times the load).
    """
    from dataclasses import replace

    kind = spec.kind
    ref = kind.reference(spec, force) if kind.zone_from_load else None
    if ref is None:
        return spec
    zx, _ = spec.zone()
    spacing = zx / (spec.n_side // 2)
    if kind.reference_size(ref) >= spacing:
        return spec
    return replace(spec, p_design=kind.reference(spec, LOAD_ZONE_FACTOR * force)["p0"])


def _brief(result: dict) -> dict:
    """The JSON printed on stdout: scalars, Hertz comparison, timings (no maps)."""
    return {k: v for k, v in result.items() if k not in ("maps", "curve")}


def run(args) -> int:
    """Solve one load case; print, write and plot as asked."""
    from contact_core import api
    from damper.cache import Store

    check_options(args)
    spec = None if (args.stiffness or args.nodes) else spec_from_args(args)
    if spec is not None and args.eccentricity is not None:
        spec.kind.check_eccentricity(spec, args.eccentricity)
    # the application's store keeps the cache under its size limit ($DAMPER_CACHE_MAX_MB)
    cache = False if args.no_cache else Store(args.cache_dir).prepare()
    if spec is None:
        from contact_core import byo
        result = byo.run_from_files(args.stiffness, args.nodes, args.body, args.force,
                                    args.approach, cache)
        if result["zone_edge_in_contact"]:  # as for generated bodies (contact_core.api.run_normal)
            raise ValueError("the contact reaches the edge of the imported bodies' contact nodes: they do not "
                             "hold the contact at this load; give a smaller load, or bodies whose contact nodes "
                             "cover a larger zone (or check the stiffness units)")
    else:
        points = args.curve or (NORMAL_CURVE_POINTS if args.normal_curve else (8 if args.plot else 0))
        result = api.run_normal(spec, force=args.force, approach=args.approach,
                                eccentricity=args.eccentricity, cache=cache, curve_points=points)
    normal = None
    if args.normal_curve:  # built before anything is written: a bad curve writes nothing
        from contact_core.normal_curve import NormalCurve
        normal = NormalCurve.from_result(result)
    if args.plot:
        from contact_core.plots import plot_all
        plot_all(result, args.body, args.plot)
    if args.out:
        atomic_write(args.out, dumps(result, indent=1) + "\n")
    if normal is not None:
        from contact_core.normal_curve import write_normal_curve
        write_normal_curve(normal, args.normal_curve)
    if args.json:
        print_json(_brief(result))
    else:
        _print_text(result)
    return 0


#: Options that shape a generated body: they do not apply to imported ones (--stiffness).
_BODY_ONLY = ("radius", "diameter", "length", "width", "height", "E2", "nu2", "p_design", "eccentricity")


def check_options(args) -> None:
    """Options that do not go together, sizes and output paths, refused before any work."""
    import math

    from damper import limits

    from .common import check_out_dir, check_out_file

    for name in ("force", "approach", "eccentricity", "radius", "diameter", "length", "width", "height",
                 "E", "nu", "E2", "nu2", "p_design"):
        v = getattr(args, name, None)
        if v is not None and not math.isfinite(v):
            raise ValueError(f"--{name.replace('_', '-')} must be finite, got {v:g}")
    if bool(args.stiffness) != bool(args.nodes):
        raise ValueError("--stiffness and --nodes go together (one stiffness file and one node file per body)")
    if args.stiffness:
        given = [f"--{n.replace('_', '-')}" for n in _BODY_ONLY if getattr(args, n, None) is not None]
        if given:
            raise ValueError(f"{', '.join(given)}: the bodies come from --stiffness and --nodes; "
                             "these options shape generated bodies only")
    if args.eccentricity is not None and args.force is None:
        raise ValueError("--eccentricity places the normal force: it needs --force, not --approach")
    if args.curve == 1:  # one point is 5 % of the load: a curve (and --normal-curve) that stops short
        raise ValueError("--curve 1: the F-approach curve runs from 5 % to 100 % of the load, so it needs at "
                         "least 2 points (0: no curve)")
    if args.curve:
        limits.check_size("--curve", args.curve, 0, limits.MAX_APPROACH_POINTS,
                          "each point of the F-approach curve is a normal solve")
    check_out_file(args.out, "--out")
    check_out_file(getattr(args, "normal_curve", None), "--normal-curve")
    check_out_dir(args.plot, "--plot")


def _print_text(r: dict) -> None:
    keys = ("force", "approach", "contact_area", "contact_radius", "contact_halfwidth",
            "contact_halfwidth_end", "p_max", "p_mean", "k_n", "body1_share", "eccentricity",
            "iterations", "n_contact_nodes")
    for k in keys:
        if k in r:
            print(f"{k:24s} {r[k]:.6g}")
    if "hertz" in r:
        errs = {k: v for k, v in r["hertz"].items() if k.startswith("error")}
        print("vs Hertz: " + ", ".join(f"{k[6:]} {100 * v:+.2f} %" for k, v in errs.items()))
    if r.get("under_resolved"):
        from contact_core.bodies import under_resolved_warning

        print(under_resolved_warning("--p-design", "--grid"))
