"""``damper fmu``: package the friction element of one contact as an FMU.

Example::

    damper fmu --curve curve.json --fmi-version 2 -o damper.fmu

The virgin curve (``contact_core.curve`` JSON) travels inside the FMU with the C
sources and a compiled Linux binary. Inputs ``u`` [m], ``N`` [N]; outputs ``F``
[N], ``kt`` [N/m], ``W`` [J], ``slip`` [-]; parameters ``scale`` [-], ``N_ref`` [N].
A curve that declares ``mu`` and ``N`` and ends at T = mu N is continued flat
beyond its end (gross slip), the same rule as ``damper loop``; otherwise its last
slope continues.
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
    from pathlib import Path

    from contact_core.curve import read_curve
    from fmu_src.element import ends_at_gross_slip
    from fmu_src.fmu_build import build_fmu

    curve = read_curve(args.curve)
    n_ref = args.n_ref if args.n_ref is not None else curve.N
    if n_ref is None:
        raise ValueError(f"{args.curve}: the curve has no normal load N; pass --n-ref")
    gross_slip = ends_at_gross_slip(curve.T, curve.mu, curve.N)   # the rule of damper loop
    description = (f"Masing/Iwan friction element from the virgin curve {args.curve} "
                   f"({curve.u.size} points, N_ref = {n_ref:g} N"
                   + (f", mu = {curve.mu:g}" if curve.mu is not None else "")
                   + (", flat beyond its end: gross slip" if gross_slip else "") + ")")
    path = build_fmu(curve.u, curve.T, n_ref, args.output, fmi_version=args.fmi_version,
                     fit=args.fit, description=description, gross_slip=gross_slip,
                     curve_json=Path(args.curve).read_text())
    print(path)
    return 0
