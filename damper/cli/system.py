"""``damper system``: the UPD ring as blade and damper FMUs in an SSP 1.0 archive.

Examples::

    damper system --cf 120 --f0 30 -o ring.ssp --json
    damper system --config upd.toml --cf 60 --f0 30 -o ring60.ssp
    damper system --contacts geometry --cf 120 -o ring_geo.ssp
"""
from __future__ import annotations

import numpy as np

from damper import limits


def register(sub) -> None:
    p = sub.add_parser("system", help="the UPD ring (blade and damper FMUs) as an SSP archive",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--config", help="UPD model TOML (default: the bundled UPD-24)")
    p.add_argument("--cf", type=float, help="centrifugal load [N] (default: config)")
    p.add_argument("--f0", type=float, help="EO force amplitude [N] (default: config)")
    p.add_argument("-o", "--output", required=True, help="the .ssp archive to write")
    p.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                   help="FMI version of the FMUs (libcosim, for damper cosim, runs FMI 2 only)")
    p.add_argument("--frequency-hz", type=float,
                   help="default excitation frequency in the archive (damper cosim sets its own; "
                   "default: the middle of the config's band)")
    p.add_argument("--contacts", choices=("toml", "geometry"), default="toml",
                   help="contact laws: the TOML's Jenkins points, or from the [geometry] section")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=run)


def run(args) -> int:
    from damper.ring_system import build_ring
    from damper.upd_geometry import apply_to_args
    from harmonic_balance.bladed_disk.config import load_config

    from .common import check_out_file, print_json

    check_out_file(args.output, "-o")   # before building the FMUs (seconds)
    cfg = load_config(args.config)
    cf = cfg.cf if args.cf is None else args.cf
    f0 = cfg.f0 if args.f0 is None else args.f0
    limits.check_load("--cf", cf)
    limits.check_load("--f0", f0)
    limits.check_cf_floor("--cf", cf, f0, args.config, "or damper upd frf --damper free for the blades without a "
                          "damper")
    if args.frequency_hz is not None:
        limits.check_range("--frequency-hz", args.frequency_hz, limits.MIN_OMEGA / (2 * np.pi),
                           limits.MAX_OMEGA / (2 * np.pi), "Hz", "the band of a structural mode, "
                           "1e-6 to 1e9 rad/s")
    args.cf = cf
    cfg = apply_to_args(args, cfg)
    info = build_ring(cfg, cf, f0, args.output, fmi_version=args.fmi_version,
                      frequency_hz=args.frequency_hz,
                      config_name=args.config or "UPD-24")
    if "contact_report" in args:
        info["contacts_from_geometry"] = args.contact_report
    if args.json:
        print_json(info)
    else:
        print(f"wrote {info['path']}: {info['ring_blades']} blades + {info['ring_blades']} dampers "
              f"(N_b {info['blades']}, EO {info['engine_order']}), CF {cf} N, F0 {f0} N; "
              f"coupling limit {info['step_limit']:.3g} s, default step {info['default_step']:.3g} s")
    return 0
