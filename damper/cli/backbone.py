"""``damper backbone``: nonlinear mode of a friction-damped model by EPMC.

Examples::

    damper backbone --model sdof --contact-stiffness 1 --slip-force 0.05 --harmonics 1 \\
        --amplitude 1e-3 10 --json
    damper backbone --model matrices.npz --elements elements.toml --harmonics odd:7 \\
        --amplitude 1e-4 1 --mode 0 --json

Model options as ``damper frf`` (the excitation of the model is ignored: a nonlinear
mode is a free motion). ``--amplitude`` is the range of the mass-normalised modal
amplitude a [m sqrt(kg)] (for the sdof model of unit mass: the first-harmonic
amplitude [m]); start it small (the start is the stuck linear mode).

JSON output (SI): ``modal_amplitude``, ``omega`` [rad/s], ``xi`` [1/s] (the
artificial negative damping), ``damping_ratio`` (xi / (2 omega)), ``amplitude``
(peak |x| of the response DOF) per point, ``points``, ``newton_iterations``,
``status``, and ``truncation_error``: a few points re-solved with about 1.5 H harmonics
(``method``, ``H_used``, ``H_check``, ``omega_rel`` and ``damping_ratio_rel``, the
largest estimated relative errors, ``points``), with ``truncation_warning`` above 1 %;
``--accuracy TOL`` raises H per backbone until both are below TOL (``harmonics``: the H
used; ``truncation_error.accuracy``: target, met, H_sequence, message).
A backbone that stops early prints its points and exits with code 3.
"""
from __future__ import annotations

import argparse
import math


def register(subparsers) -> None:
    from .frf import add_model_arguments

    p = subparsers.add_parser(
        "backbone", help="nonlinear mode (backbone: frequency, damping vs amplitude) by EPMC",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_model_arguments(p)
    p.add_argument("--harmonics", default="1", help="H, odd:H or all:H (default 1; with --accuracy "
                   "the first one tried)")
    p.add_argument("--accuracy", type=float, metavar="TOL",
                   help="relative accuracy of the frequency and the damping ratio, in (1e-6, 0.5): H "
                   "is raised per backbone until both estimates are below TOL")
    p.add_argument("--samples", type=int, default=0, help="AFT samples per period (0: auto)")
    p.add_argument("--amplitude", type=float, nargs=2, required=True, metavar=("START", "END"),
                   help="modal amplitude range [m sqrt(kg)]")
    p.add_argument("--mode", type=int, default=0, help="mode of the stuck linear system (0-based)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", help="also write the JSON to this file")
    p.set_defaults(func=run)


def run(args) -> int:
    from damper import limits
    from harmonic_balance.epmc import EPMCError, compute_backbone
    from harmonic_balance.epmc_accuracy import backbone_to_accuracy, truncation_error, warning

    from .common import atomic_write, check_accuracy_option, check_out_file, dumps, print_json
    from .frf import build_model, check_model_arguments, check_samples

    check_model_arguments(args)
    limits.check_harmonics("--harmonics", args.harmonics)
    check_samples(args.samples)
    check_accuracy_option(args.accuracy)
    a0, a1 = args.amplitude
    if not (math.isfinite(a0) and math.isfinite(a1) and a0 > 0 and a1 > 0 and a0 != a1):
        raise ValueError(f"--amplitude {a0:g} {a1:g}: give two different positive finite amplitudes")
    if a0 > a1:
        raise ValueError(f"--amplitude {a0:g} {a1:g}: give START < END (the curve starts at the stuck "
                         "linear mode, at a small amplitude)")
    if max(a0, a1) > limits.MAX_MAGNITUDE:
        raise ValueError(f"--amplitude {a0:g} {a1:g}: above the limit {limits.MAX_MAGNITUDE:g} m sqrt(kg) (the "
                         "harmonic balance squares displacements and forces, which overflows)")
    if args.mode < 0:
        raise ValueError(f"--mode must be >= 0 (0 is the first mode), got {args.mode}")
    check_out_file(args.out, "--out")
    model = build_model(args)
    try:
        if args.accuracy is None:
            bb = compute_backbone(model, args.harmonics, args.amplitude, n_t=args.samples,
                                  mode=args.mode)
            rec = truncation_error(model, args.harmonics, bb, args.samples, args.mode,
                                   limits.MAX_HARMONICS)
        else:
            bb, rec = backbone_to_accuracy(model, args.harmonics, args.amplitude, args.accuracy,
                                           args.samples, args.mode, limits.MAX_HARMONICS)
    except EPMCError as err:
        _emit(args, err.result.summary(), print_json, atomic_write, dumps)
        raise RuntimeError(f"{err} ({err.result.a.size} points kept)") from None
    s = bb.summary() | {"harmonics": rec["H_used"]}
    s["truncation_error"], s["truncation_warning"] = rec, warning(rec)
    _emit(args, s, print_json, atomic_write, dumps)
    return 0


def _emit(args, s, print_json, atomic_write, dumps):
    if args.out:
        atomic_write(args.out, dumps(s, indent=1) + "\n")
    import sys

    from harmonic_balance.epmc_accuracy import summary_lines

    lines = summary_lines(s.get("truncation_error"))
    if args.json:
        print_json(s)
        for line in lines:  # the warning stays visible beside the JSON
            if line.startswith("warning"):
                print(line, file=sys.stderr)
        return
    print(f"{s['points']} points, {s['newton_iterations']} Newton iterations, status: {s['status']}")
    for a, w, d in list(zip(s["modal_amplitude"], s["omega"], s["damping_ratio"]))[:: max(1, s["points"] // 10)]:
        print(f"a = {a:.4g}  omega = {w:.6g} rad/s  damping ratio = {d:.4g}")
    for line in lines:
        print(line)
