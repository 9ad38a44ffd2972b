"""``damper frf``: forced-response curve by multi-harmonic balance and continuation.

Examples::

    damper frf --model sdof --mass 1 --stiffness 1 --damping 0.01 --contact-stiffness 1 \\
        --slip-force 0.05 --force 0.05 --harmonics 1 --omega 0.9 1.3 --json
    damper frf --model matrices.npz --elements elements.toml --harmonics odd:7 \\
        --omega 100 300 --json --plot out/frf

Harmonics and accuracy: ``--harmonics`` fixes the harmonic set; ``--accuracy TOL``
traces the curve once (at ``--harmonics``, default 3) and raises H at its peak only
(the curve points near the peak re-solved with richer harmonic sets, level after level)
until the estimated truncation error of the peak amplitude is below TOL; with neither,
``--accuracy 0.01`` from H = 3. Every result carries that estimate (with a fixed set:
the peak re-solved with ~1.5 H and ~2.25 H harmonics, docs/method/accuracy.md) and a
warning line when it exceeds 1 %.

``--model`` is ``sdof`` (a mass on a spring and dashpot with one Jenkins element to
the ground, forced by ``--force`` cos(omega t)) or a ``.npz`` file with an
``--elements`` ``.toml`` file; both formats are documented in
:mod:`harmonic_balance.model`. ``--harmonics`` takes H (harmonics 0..H), ``odd:H``
or ``all:H``.

JSON output (SI units): ``omega`` [rad/s] per point, ``amplitude`` (peak |x| of the
response DOF over the period) [m], ``amplitude_h1`` (its first-harmonic magnitude),
``peak_omega`` and ``peak_amplitude`` (the highest refined peak of max|x|),
``peak_amplitude_h1`` (the first harmonic at that peak), ``peak_h1_max`` and
``peak_h1_max_omega`` (the first harmonic's own refined maximum), ``truncation_error``
(method, H_used, H_check, order, peak_amplitude_rel and peak_frequency_rel: the
estimated relative error in H of the peak, check: the peak at H_check, extrapolated:
the peak extrapolated in H when the order was observed, else null),
``truncation_warning``, ``accuracy`` (with --accuracy: target, met, H_curve (the
curve's H), H_peak (the H of the reported peak), peak_amplitude and peak_omega (computed
at H_peak, the same as the top-level peak), levels ([H, peak amplitude, peak omega] of
the curve and each richer level), extrapolated (the peak extrapolated in H with the
observed order, or null), message (why not met)), ``stuck_links`` (links that never
slip at the peak: their mean position is the harmonic balance's convention, stuck since u = 0), ``steady_state`` and
``steady_state_warning`` (with --check-steady-state: the peak |x| of time integrations
from rest and from the harmonic balance's state at the peak frequency, ``states_differ``
when they settle apart; docs/method/accuracy.md), ``peaks`` (every
refined resonance peak: omega, amplitude), ``alias_ratio`` (AFT grid check), ``aft``
("exact": the links' Fourier coefficients without sampling, the default, n_t then only
scans for extrema; "sampled" with ``--aft sampled``; "mixed" with contacts), ``points``,
``newton_iterations`` (corrector iterations), ``time_s``, ``status`` and ``stable``
(per point, Hill's method, solved where stability can change: sign changes of the
Jacobian's determinant, peaks, ends, every 25 points, bisection where two checks
disagree; ``stability_checks`` counts them; ``--stability all`` solves it at every
point; null for models above 200 full unknowns with ``auto``, modal-only ones, or
``--stability off``; unstable stretches are dashed in frf.png). The first point does not depend
on where the sweep starts: Newton from the stuck linear guess, else a homotopy in
the excitation level or in the contact stiffness (harmonic_balance.start). A run
that fails part-way prints the points computed so far (``status`` says where and
why) and exits with code 3, with or without --json. Nonlinear modes (backbones):
``damper backbone``.
"""
from __future__ import annotations

import argparse
import math


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "frf", help="forced-response curve of a friction-damped model (harmonic balance)",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_model_arguments(p)
    p.add_argument("--harmonics", help="H, odd:H or all:H: a fixed harmonic set (with --accuracy: "
                   "the first one tried; default: --accuracy 0.01 from H = 3)")
    p.add_argument("--accuracy", type=float, metavar="TOL",
                   help="relative accuracy of the peak amplitude, in (1e-6, 0.5): the curve is traced "
                   "at --harmonics, then its peak alone is re-solved with more harmonics until the "
                   "estimated truncation error is below TOL")
    p.add_argument("--samples", type=int, default=0,
                   help="AFT samples per period (0: auto); exact links only scan them for the extrema")
    p.add_argument("--aft", choices=("exact", "sampled"), default="exact",
                   help="friction links: exact periodic loop (default) or sampled AFT on --samples "
                   "(contacts with a varying normal load are sampled either way)")
    p.add_argument("--omega", type=float, nargs=2, required=True, metavar=("START", "END"),
                   help="frequency range [rad/s]")
    p.add_argument("--tolerance", type=float,
                   help="curve accuracy: the points' polyline deviates from the curve by about this "
                   "much, relative to the response and the range (default 0.01, "
                   "harmonic_balance.continuation.CURVE_TOL); peaks are refined whatever it is")
    p.add_argument("--max-step", type=float,
                   help="largest continuation step (scaled arclength; default 0.5, "
                   "harmonic_balance.frf.DS_MAX)")
    p.add_argument("--max-points", type=int, default=2000)
    p.add_argument("--stability", choices=("auto", "all", "off"), default="auto",
                   help="Hill stability per point: auto (checked where it can change, models up "
                   "to 200 full unknowns), all (Hill at every point, any size), off")
    p.add_argument("--check-steady-state", action="store_true",
                   help="time-integrate at the peak from rest and from the harmonic balance's state: "
                        "says whether the curve is the state a start from rest reaches (seconds on a "
                        "few DOFs; matrix models)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--out", help="also write the JSON to this file")
    p.add_argument("--plot", metavar="DIR", help="write frf.png, loops.png, harmonics.png here")
    p.set_defaults(func=run)


def add_model_arguments(p) -> None:
    """Model options shared by ``damper frf`` and ``damper backbone``."""
    p.add_argument("--model", required=True, help="'sdof' or a matrices .npz file")
    p.add_argument("--elements", help="friction elements .toml (with a .npz model)")
    g = p.add_argument_group("sdof model (SI units)")
    for flag, what in (("--mass", "mass [kg]"), ("--stiffness", "spring to ground [N/m]"),
                       ("--damping", "dashpot [N s/m]"), ("--contact-stiffness", "Jenkins spring [N/m]"),
                       ("--slip-force", "Jenkins slip force [N]"), ("--force", "excitation amplitude [N]")):
        g.add_argument(flag, type=float, default=None, help=f"{what} (default {SDOF[flag]:g})")
    p.add_argument("--force-scale", type=float, default=None,
                   help="multiply the .npz excitation by this factor (default 1)")
    p.add_argument("--response-dof", type=int, help="DOF reported (default: the file's, or 0)")


#: The sdof model's options and their defaults.
SDOF = {"--mass": 1.0, "--stiffness": 1.0, "--damping": 0.01, "--contact-stiffness": 1.0,
        "--slip-force": 0.05, "--force": 0.05}


def _dest(flag: str) -> str:
    return flag[2:].replace("-", "_")


def check_model_arguments(args) -> None:
    """Refuse, before any work, options that do not apply to the model (and fill the sdof defaults)."""
    import os

    from damper import limits

    if args.model == "sdof":
        for flag in ("--elements", "--force-scale"):
            if getattr(args, _dest(flag)) is not None:
                raise ValueError(f"{flag} applies to a .npz model, not to sdof")
        if args.response_dof not in (None, 0):
            raise ValueError(f"--response-dof {args.response_dof}: the sdof model has one DOF (0)")
        for flag, value in SDOF.items():
            v = getattr(args, _dest(flag))
            if v is None:
                setattr(args, _dest(flag), value)
            elif not math.isfinite(v):
                raise ValueError(f"{flag} must be finite, got {v:g}")
            elif abs(v) > limits.MAX_MAGNITUDE:
                raise ValueError(f"{flag} {v:g} is beyond the limit {limits.MAX_MAGNITUDE:g}: the harmonic "
                                 "balance squares forces and displacements, which overflows above ~1e154")
        return
    if not os.path.exists(args.model):  # a misspelt 'sdof' is not "a .npz model without --elements"
        raise ValueError(f"--model {args.model}: no such file; give 'sdof' or a .npz model file")
    given = [flag for flag in SDOF if getattr(args, _dest(flag)) is not None]
    if given:
        raise ValueError(f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} to --model sdof only; "
                         f"the .npz file {args.model} holds the structure and its excitation (--force-scale)")
    if not args.elements:
        raise ValueError("a .npz model needs --elements FILE.toml")
    if args.force_scale is None:
        args.force_scale = 1.0
    if not (math.isfinite(args.force_scale) and abs(args.force_scale) <= limits.MAX_MAGNITUDE):
        raise ValueError(f"--force-scale must be finite and at most {limits.MAX_MAGNITUDE:g} in magnitude, "
                         f"got {args.force_scale:g}")


def build_model(args):
    """The Model described by the arguments (ValueError on bad input)."""
    import numpy as np

    from harmonic_balance.model import Model, load_elements, load_matrices, sdof_model

    check_model_arguments(args)
    if args.model == "sdof":
        return sdof_model(args.mass, args.stiffness, args.damping, args.contact_stiffness,
                          args.slip_force, args.force)
    lin, forcing, resp = load_matrices(args.model)
    forcing = {h: args.force_scale * np.asarray(f, dtype=complex) for h, f in forcing.items()}
    resp = resp if args.response_dof is None else args.response_dof
    return Model(lin, load_elements(args.elements), forcing, resp)


def run(args) -> int:
    import os

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # small dense work: one thread is faster
    from damper import limits
    from harmonic_balance.frf import FRFError, check_peak_traced, compute_frf

    from .common import atomic_write, dumps, print_json

    check_run_arguments(args)
    steps = {k: v for k, v in (("ds_max", args.max_step), ("tolerance", args.tolerance))
             if v is not None}
    model = build_model(args)
    _report_curve_fits(model)
    try:
        result = compute_frf(model, args.harmonics, args.omega, n_t=args.samples,
                             max_points=args.max_points, aft=args.aft, **steps,
                             stability=args.stability, accuracy=args.accuracy,
                             max_harmonic=limits.MAX_HARMONICS,
                             steady_state_check=args.check_steady_state)
        check_peak_traced(result)
    except FRFError as err:
        # the partial result on stdout; stderr keeps one line, the failure's (its warnings are in the JSON)
        _emit(args, err.result.summary(), print_json, atomic_write, dumps, warn=False)
        # What usually helps (measured: 1e12 k, H = 7 ended at |R| = 3e-10, the round-off of
        # the stiff link, where H = 3 completes): fewer harmonics, a shorter range, or
        # smaller steps past a sharp feature.
        if getattr(err, "hint", None):
            hint = err.hint
        elif err.result.points >= args.max_points:   # stopped by the point limit
            hint = "raise --max-points, or a larger --tolerance takes fewer points"
        else:
            hint = "try fewer --harmonics, a narrower --omega range or a smaller --tolerance"
        raise RuntimeError(f"{err} ({err.result.points} points kept); {hint}") from None
    summary = result.summary()
    if args.plot:
        from harmonic_balance.plots import plot_frf

        plot_frf(result, args.plot)
    _emit(args, summary, print_json, atomic_write, dumps)
    return 0


def check_samples(samples: int) -> None:
    """``--samples``: 0 (automatic) or a positive count up to the AFT bound."""
    from damper import limits

    if samples < 0:
        raise ValueError(f"--samples must be 0 (automatic) or a positive number of samples, got {samples}")
    if samples:
        limits.check_size("--samples", samples, 1, limits.MAX_AFT_SAMPLES,
                          "the AFT's DFT matrices hold n_t (2H + 1) numbers each (0.2 GB at 65536 x 401)")


def check_run_arguments(args) -> None:
    """Sizes and ranges of ``damper frf``, before any work (each bound names its reason)."""
    from damper import limits
    from damper.cli.common import check_out_dir, check_out_file

    check_model_arguments(args)
    check_accuracy_arguments(args)
    limits.check_harmonics("--harmonics", args.harmonics)
    check_samples(args.samples)
    limits.check_omega_range("--omega", *args.omega)
    if args.max_step is not None and not (math.isfinite(args.max_step) and args.max_step > 0):
        raise ValueError(f"--max-step must be a positive finite number, got {args.max_step:g}")
    if args.max_step is not None and args.max_step * args.max_points < 1.0:
        # the frequency range alone is 1 in scaled arclength: at most max_step a point
        raise ValueError(f"--max-step {args.max_step:g} needs more than --max-points {args.max_points} points "
                         f"to cross the range (1 in scaled arclength): give --max-step >= "
                         f"{1.0 / args.max_points:.3g} or more --max-points")
    if args.tolerance is not None and not 1e-6 <= args.tolerance < 1:
        raise ValueError(f"--tolerance must be in [1e-6, 1) (a relative curve accuracy; finer "
                         f"steps would resolve the corrector's own accuracy), got {args.tolerance:g}")
    limits.check_size("--max-points", args.max_points, 2, limits.MAX_CURVE_POINTS,
                      "each point is a Newton solve (5-50 ms for one DOF, seconds for large models)")
    check_out_file(args.out, "--out")
    check_out_dir(args.plot, "--plot")


#: Accuracy of a run that gives neither --harmonics nor --accuracy (relative, on the peak
#: amplitude), and the harmonics it starts from: measured on the bench models
#: (docs/method/accuracy.md) at 1.1-1.6 times the cost of one curve at H = 3.
DEFAULT_ACCURACY, DEFAULT_START = 1e-2, "3"


def check_accuracy_arguments(args) -> None:
    """``--accuracy`` inside (1e-6, 0.5); without it and without ``--harmonics`` the default
    accuracy and start (the arguments are filled in)."""
    from .common import check_accuracy_option

    check_accuracy_option(args.accuracy)
    if args.accuracy is None and args.harmonics is None:
        args.accuracy = DEFAULT_ACCURACY
    if args.harmonics is None:
        args.harmonics = DEFAULT_START


def _report_curve_fits(model) -> None:
    """Say on stderr which element curves were reduced to the C element's slider limit."""
    import sys

    for link in model.links:
        err = getattr(getattr(link, "element", None), "fit_error", 0.0)
        if err > 0.0:
            print(f"note: element {link.name!r}: its curve was reduced to the element's slider "
                  f"limit; largest force error of the fit {err:.3g} N", file=sys.stderr)


def _emit(args, summary, print_json, atomic_write, dumps, warn: bool = True):
    from harmonic_balance.frf_accuracy import summary_lines as accuracy_lines
    from harmonic_balance.steady_state import summary_lines as state_lines

    if args.out:
        atomic_write(args.out, dumps(summary, indent=1) + "\n")
    if args.json:
        print_json(summary)
        for line in accuracy_lines(summary)[1:] + state_lines(summary.get("steady_state"))[1:]:
            if warn and line.startswith("warning"):
                import sys

                print(line, file=sys.stderr)
        return
    print(f"{summary['points']} points, {summary['newton_iterations']} Newton iterations, "
          f"{_num(summary['time_s'], '.3f')} s, harmonics {summary['harmonics']}, "
          f"n_t {summary['n_t']}" + (f", {summary['aft']} AFT" if summary.get("aft") else ""))
    acc = summary.get("accuracy") or {}
    raised = acc.get("H_peak") is not None and acc["H_peak"] != acc.get("H_curve")
    at_peak = f" (H = {acc['H_peak']})" if raised else ""
    at_curve = f" (the curve, H = {acc['H_curve']})" if raised else ""
    print(f"peak{at_peak}: omega = {_num(summary['peak_omega'])} rad/s, "
          f"amplitude = {_num(summary['peak_amplitude'])} m (first harmonic "
          f"{_num(summary['peak_amplitude_h1'])} m there)")
    if summary.get("peak_h1_max") is not None:
        print(f"first harmonic's own peak{at_curve}: "
              f"omega = {_num(summary['peak_h1_max_omega'])} rad/s, amplitude = {_num(summary['peak_h1_max'])} m")
    for line in accuracy_lines(summary) + state_lines(summary.get("steady_state")):
        print(line)
    if summary.get("stuck_links"):
        print(f"links that never slip at the peak (mean position by convention): "
              f"{', '.join(summary['stuck_links'])}")
    if summary.get("stable") is not None:
        n_unst = sum(1 for s in summary["stable"] if s is False)
        print(f"stability (Hill): {n_unst} of {summary['points']} points unstable")
    print(f"status: {summary['status']}")


def _num(v, fmt=".9g") -> str:
    """A number for the text summary; 'none' when undefined (no converged point)."""
    return "none" if v is None else format(v, fmt)

