"""``damper fmu``: package the friction element of one contact as an FMU.

Example::

    damper fmu --curve curve.json --fmi-version 2 -o damper.fmu

The virgin curve (``contact_core.curve`` JSON) travels inside the FMU with the C
sources and a compiled Linux binary. Inputs ``u`` [m], ``N`` [N]; outputs ``F``
[N], ``kt`` [N/m], ``W`` [J], ``slip`` [-]; parameters ``scale`` [-], ``N_ref`` [N].
Beyond its last point the curve follows its file's ``tail`` (``flat``: gross slip,
``slope``: the last slope continues), as in ``damper loop``. A curve with more
segments than the element holds is reduced by the min-max optimal fit
(``fmu_src.curve_fit``) and the largest force error printed.
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
    p.set_defaults(func=run)


def run(args) -> int:
    """Read the curve, build and write the FMU; print the output path."""
    import sys
    from pathlib import Path

    from contact_core.curve import read_curve
    from fmu_src.curve_fit import reduce_virgin_curve
    from fmu_src.fmu_build import build_fmu

    from .common import check_out_file

    if args.n_ref is not None and not (args.n_ref > 0 and args.n_ref < float("inf")):
        raise ValueError(f"--n-ref must be a positive finite normal load [N], got {args.n_ref:g}")
    check_out_file(args.output, "--output")
    source = read_curve(args.curve)
    n_ref = args.n_ref if args.n_ref is not None else source.N
    if n_ref is None:
        raise ValueError(f"{args.curve}: the curve has no normal load N; pass --n-ref")
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
                     curve_json=Path(args.curve).read_text())
    if reduced:
        print(f"note: the curve's {source.u.size} points were reduced to {curve.u.size}; "
              f"largest force error of the fit {error:.3g} N", file=sys.stderr)
    print(path)
    return 0
