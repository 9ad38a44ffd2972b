"""``damper fmu``: package the friction element of one contact as an FMU.

Example::

    damper fmu --curve curve.json --fmi-version 2 -o damper.fmu
    damper fmu --curve curve.json --normal normal.json -o point.fmu      # 3D contact point
    damper fmu --curve curve.json --k-n 3e8 --preload 200 -o point.fmu   # penalty normal law

The virgin curve (``contact_core.curve`` JSON) travels inside the FMU with the C
sources and a compiled Linux binary. Inputs ``u`` [m], ``N`` [N]; outputs ``F``
[N], ``kt`` [N/m], ``W`` [J], ``slip`` [-]; parameters ``scale`` [-], ``N_ref`` [N].
Beyond its last point the curve follows its file's ``tail`` (``flat``: gross slip,
``slope``: the last slope continues), as in ``damper loop``. A curve with more
segments than the element holds is reduced by the min-max optimal fit
(``fmu_src.curve_fit``) and the largest force error printed.

With ``--normal`` (a normal approach curve of ``damper normal --normal-curve``) or
``--k-n`` (a penalty spring) the FMU is a 3D contact point instead: inputs ``u_x``,
``u_y``, ``p`` [m] (penetration, positive pressed) and the velocities ``v_x``, ``v_y``,
``v_n`` [m/s] for optional dashpots; outputs ``F_x``, ``F_y``, ``N`` [N], ``W``,
``stored_energy`` [J], ``state`` (0 open, 1 stick, 2 slip), ``slip`` and the tangent
``K_xx`` ... ``K_pp`` [N/m] (also as directional derivatives); parameters ``scale``,
``N_ref``, ``c_t``, ``c_n``. The slip limits follow N(p) / N_ref. ``--preload`` is the
normal load at the start (the start value of p), by default the curve's N. A normal
curve computed up to another load than the virgin curve's N is refused unless
``--preload`` says at which load the contact starts.
"""
from __future__ import annotations

import argparse


def register(subparsers) -> None:
    """Add the ``fmu`` subcommand."""
    p = subparsers.add_parser(
        "fmu", help="package the friction element as an FMI 2.0/3.0 co-simulation FMU",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--curve", required=True, help="virgin-curve JSON file (damper tangential)")
    p.add_argument("--fmi-version", type=int, choices=(2, 3), default=2)
    p.add_argument("-o", "--output", required=True, help="FMU file to write")
    p.add_argument("--n-ref", type=float, default=None,
                   help="normal load the curve was computed at [N] (default: the curve's N)")
    p.add_argument("--fit", choices=("reject", "concave"), default="reject",
                   help="a curve that is not concave: refuse it (default) or use its "
                   "least concave majorant")
    law = p.add_mutually_exclusive_group()
    law.add_argument("--normal", default=None, metavar="FILE",
                     help="3D contact point with this normal approach curve (damper normal "
                     "--normal-curve) as its normal law")
    law.add_argument("--k-n", type=float, default=None,
                     help="3D contact point with a penalty normal law N = k_n p [N/m]")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (the FMU's path, model, points, fit error) on stdout")
    p.add_argument("--preload", type=float, default=None,
                   help="contact point: normal load at the start [N] (default: the curve's N)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Read the curve (and the normal law), build and write the FMU; print its path."""
    from contact_core.curve import read_curve

    from .common import check_out_file

    check_numbers(args)
    check_out_file(args.output, "--output")
    source = read_curve(args.curve)
    n_ref = args.n_ref if args.n_ref is not None else source.N
    if n_ref is None:
        raise ValueError(f"{args.curve}: the curve has no normal load N; pass --n-ref")
    if args.n_ref is None:
        from damper import limits

        limits.check_range(f"{args.curve}: N", n_ref, limits.MIN_NORMAL_LOAD, limits.MAX_NORMAL_LOAD, "N",
                           "the slip limits scale with N / N_ref; give --n-ref")
    if args.normal is None and args.k_n is None:
        if args.preload is not None:
            raise ValueError("--preload needs a normal law: --normal FILE or --k-n K")
        return _run_element(args, source, n_ref)
    return _run_point(args, source, n_ref)


def check_numbers(args) -> None:
    """--n-ref, --preload, --k-n within :mod:`damper.limits`' ranges (ValueError)."""
    from damper import limits

    load_why = "the slip limits scale with N / N_ref, which underflows or overflows far outside"
    for name in ("n_ref", "preload"):
        v = getattr(args, name)
        if v is not None:
            limits.check_range(f"--{name.replace('_', '-')}", v, limits.MIN_NORMAL_LOAD,
                               limits.MAX_NORMAL_LOAD, "N", load_why)
    if args.k_n is not None:
        limits.check_range("--k-n", args.k_n, limits.MIN_PENALTY_STIFFNESS, limits.MAX_PENALTY_STIFFNESS,
                           "N/m", "the start penetration N / k_n would be beyond any contact "
                           "(0.2 m at 200 N and 1e3 N/m) or below an atom")


def _run_element(args, source, n_ref) -> int:
    """The 1D friction element FMU (inputs u, N)."""
    from contact_core.fileio import read_text_bounded
    from fmu_src.curve_fit import reduce_virgin_curve
    from fmu_src.fmu_build import build_fmu

    try:
        curve, error = reduce_virgin_curve(source, fit=args.fit)
    except ValueError as err:
        raise ValueError(f"{args.curve}: {err}") from None
    reduced = (f", reduced from {source.u.size} points, largest force error {error:.3g} N"
               if curve is not source else "")
    description = (f"Masing/Iwan friction element from the virgin curve {args.curve} "
                   f"({curve.u.size} points{reduced}, N_ref = {n_ref:g} N"
                   + (f", mu = {curve.mu:g}" if curve.mu is not None else "")
                   + (", flat beyond its end: gross slip" if curve.tail == "flat" else "") + ")")
    path = build_fmu(curve.u, curve.T, n_ref, args.output, fmi_version=args.fmi_version,
                     fit=args.fit, description=description, tail=curve.tail,
                     curve_json=read_text_bounded(args.curve, what="curve file"))
    return _report(args, path, "element", source, curve, error, n_ref, None)


#: A normal curve and a virgin curve computed at loads closer than this (relative)
#: count as computed at the same load.
SAME_LOAD_RTOL = 1e-6


def _normal_law(args, n_ref: float):
    """(p, N, text of the source file or None, description) of --normal / --k-n."""
    from contact_core.fileio import read_text_bounded
    from fmu_src.fmu_point import penalty_table

    if args.k_n is not None:
        p, N = penalty_table(args.k_n)
        return p, N, None, f"penalty k_n = {args.k_n:g} N/m"
    from contact_core.normal_curve import read_normal_curve

    normal = read_normal_curve(args.normal)
    top = float(normal.N[-1])
    if args.preload is not None and args.preload > top * (1.0 + SAME_LOAD_RTOL):
        raise ValueError(f"--preload {args.preload:g} N is beyond the normal curve {args.normal}, which "
                         f"covers 0 ... {top:g} N: give a preload in that range or a normal curve "
                         "computed up to a higher load (damper normal --force)")
    if args.preload is None and abs(normal.load - n_ref) > SAME_LOAD_RTOL * n_ref:
        raise ValueError(f"{args.curve} was computed at N = {n_ref:g} N but {args.normal} up to "
                         f"{normal.load:g} N: pass --preload N to say at which normal load the "
                         "contact starts (the slip limits scale with N(p) / N_ref)")
    return normal.approach, normal.N, read_text_bounded(args.normal, what="normal-curve file"), \
        f"normal curve {args.normal}"


def _run_point(args, source, n_ref) -> int:
    """The 3D contact point FMU (inputs u_x, u_y, p)."""
    from contact_core.fileio import read_text_bounded
    from fmu_src.curve_fit import reduce_virgin_curve
    from fmu_src.fmu_point import build_point_fmu

    p, N, normal_text, law = _normal_law(args, n_ref)
    try:
        curve, error = reduce_virgin_curve(source, fit=args.fit)
    except ValueError as err:
        raise ValueError(f"{args.curve}: {err}") from None
    preload = n_ref if args.preload is None else args.preload
    description = (f"3D contact point: 2D Masing/Iwan element from the virgin curve {args.curve} "
                   f"({curve.u.size} points, N_ref = {n_ref:g} N) and the normal law of the {law}; "
                   f"start at N = {preload:g} N")
    resources = {"curve.json": read_text_bounded(args.curve, what="curve file")}
    if normal_text is not None:
        resources["normal.json"] = normal_text
    path = build_point_fmu(curve.u, curve.T, n_ref, p, N, args.output, fmi_version=args.fmi_version,
                           N_start=preload, fit=args.fit, tail=curve.tail, description=description,
                           resources=resources)
    return _report(args, path, "contact_point", source, curve, error, n_ref, preload)


def _report(args, path, model, source, curve, error, n_ref, preload) -> int:
    """Print the FMU's path (and a note on a reduced curve), or one JSON object."""
    import sys

    from .common import print_json

    reduced = curve is not source
    if args.json:
        print_json({"fmu": str(path), "model": model, "fmi_version": args.fmi_version,
                    "points": int(curve.u.size), "curve_points": int(source.u.size),
                    "fit_error_N": float(error) if reduced else 0.0, "n_ref_N": n_ref,
                    "preload_N": preload})
        return 0
    if reduced:
        print(f"note: the curve's {source.u.size} points were reduced to {curve.u.size}; "
              f"largest force error of the fit {error:.3g} N", file=sys.stderr)
    print(path)
    return 0
