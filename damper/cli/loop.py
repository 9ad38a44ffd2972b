"""``damper loop``: the steady hysteresis loop of one contact under harmonic motion.

Examples::

    damper loop --curve curve.json --amplitude 2e-6 --json
    damper loop --curve curve.json --force-amplitude 30 --json --plot out/loop

The contact's virgin curve (``contact_core.curve`` JSON; ``u``, ``T`` and
optionally ``N``, ``mu``) becomes a Masing/Iwan element (the C core through
``fmu_src.element``), driven by u = a cos(2 pi i / n), i = 0..n-1, at constant
normal load N. Beyond its last point the curve follows its file's ``tail``
(``flat``: gross slip; ``slope``: the last slope continues; version 1 files: see
``contact_core.curve``). A curve with more segments than the element holds is
reduced by the min-max optimal fit; the resulting largest force error is printed
(``fit_error`` in the JSON).

Output (JSON with ``--json``): ``energy_per_cycle`` [J], ``force_amplitude`` [N]
(half the force range), ``displacement_amplitude`` [m], ``u`` [m] and ``F`` [N]
(the closed loop, n samples), ``initial_stiffness`` (the stuck stiffness, every
slider's spring plus k_res) [N/m], ``input_bound`` [m], and the element's data.

Amplitudes are bounded as the element's FMU bounds its input (``input_bound``,
``fmu_src.fmu_build``): beyond 1e-6 r_min / eps (r_min the smallest slip distance at
N) the round-off of a slider force exceeds 1e-6 of its strength, so larger
amplitudes are refused rather than answered with forces above mu N.
"""
from __future__ import annotations

import argparse
import math
import sys


def register(subparsers) -> None:
    """Add the ``loop`` subcommand."""
    p = subparsers.add_parser(
        "loop", help="steady hysteresis loop and energy per cycle of one contact",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--curve", required=True, help="virgin-curve JSON file")
    amp = p.add_mutually_exclusive_group(required=True)
    amp.add_argument("--amplitude", type=float, help="displacement amplitude a [m]")
    amp.add_argument("--force-amplitude", type=float,
                     help="tangential force amplitude T* [N] (below the gross-slip force)")
    p.add_argument("--samples", type=int, default=256, help="samples per cycle (default 256)")
    p.add_argument("--N", dest="N", type=float, default=None,
                   help="normal load [N] (default: the curve's N); slip forces scale with N")
    p.add_argument("--fit", choices=("reject", "concave"), default="reject",
                   help="a curve that is not concave: refuse it (default) or use its "
                   "least concave majorant")
    p.add_argument("--scale", type=float, default=1.0, help="friction scale on every slip force")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--plot", metavar="DIR", help="write DIR/loop.png (loop over the virgin curve)")
    p.set_defaults(func=run)


def _check_args(args) -> None:
    for name in ("amplitude", "force_amplitude", "N", "scale"):
        value = getattr(args, name)
        if value is not None and not math.isfinite(value):
            raise ValueError(f"--{name.replace('_', '-')} must be finite, got {value}")
    if args.amplitude is not None and not args.amplitude > 0.0:
        raise ValueError(f"--amplitude must be > 0, got {args.amplitude}")
    if args.force_amplitude is not None and not args.force_amplitude > 0.0:
        raise ValueError(f"--force-amplitude must be > 0, got {args.force_amplitude}")
    from damper import limits

    from .common import check_out_dir

    limits.check_size("--samples", args.samples, 4, limits.MAX_LOOP_SAMPLES,
                      "1e6 samples take ~4 s and 0.24 GB (and 40 MB of JSON)")
    if args.N is not None and not args.N > 0.0:
        raise ValueError(f"--N must be > 0 (N <= 0 is lift-off: no loop), got {args.N:g}")
    if not args.scale > 0.0:
        raise ValueError(f"--scale must be > 0 (a friction scale), got {args.scale:g}")
    if args.N is not None:  # as the FMU's --n-ref and --preload: N / N_ref scales the slip limits
        limits.check_range("--N", args.N, limits.MIN_NORMAL_LOAD, limits.MAX_NORMAL_LOAD, "N",
                           "the slip limits scale with N / N_ref, which underflows or overflows far outside")
    limits.check_range("--scale", args.scale, limits.MIN_FRICTION_SCALE, limits.MAX_FRICTION_SCALE, "",
                       "a factor on every slip force (a change of mu); far outside, the slip limits "
                       "underflow or overflow")
    check_out_dir(args.plot, "--plot")


def amplitude_bound(el, N: float) -> float:
    """Largest displacement amplitude [m] the element resolves at N (its FMU's input bound at N)."""
    import numpy as np

    from fmu_src.fmu_build import U_BOUND_RTOL

    if el.n_sliders == 0:
        return float("inf")
    return U_BOUND_RTOL * float(np.min(el.slip_radii(N))) / float(np.finfo(float).eps)


def build_element(curve, fit: str, scale: float):
    """Element of a virgin curve, and whether it is flat beyond the end (gross slip)."""
    from fmu_src.element import IwanElement

    el = IwanElement.from_virgin_curve(curve, fit=fit, scale=scale)
    return el, curve.tail == "flat"


def amplitude_for_force(el, T_amp: float, N: float) -> float:
    """Displacement amplitude a [m] with virgin force g(a) = T_amp at N (exact inversion).

    The virgin curve is piecewise linear with breakpoints at the slip radii, so
    interpolating it there inverts it exactly; beyond the last one only k_res acts.
    """
    import numpy as np

    F_gs = el.gross_slip_force(N)
    if T_amp >= F_gs:
        raise ValueError(f"force amplitude {T_amp:g} N is not below the gross-slip force "
                         f"{F_gs:g} N: no steady loop (the contact slides)")
    b = np.unique(np.concatenate([[0.0], el.slip_radii(N)]))
    g = el.virgin(b, N)
    if T_amp <= g[-1]:
        return float(np.interp(T_amp, g, b))
    return float(b[-1] + (T_amp - g[-1]) / el.k_res)


def run(args) -> int:
    """Compute the loop; print JSON or a summary; optionally plot it."""
    import numpy as np

    from contact_core.curve import read_curve
    from damper.cli.common import print_json

    _check_args(args)
    curve = read_curve(args.curve)
    try:
        el, tail = build_element(curve, args.fit, args.scale)
    except ValueError as err:
        raise ValueError(f"{args.curve}: {err}") from None
    N = args.N if args.N is not None else el.N_ref
    bound = amplitude_bound(el, N)
    if args.amplitude is not None:
        a = args.amplitude
        if a > bound:
            raise ValueError(f"--amplitude {a:g} m is beyond the element's bound {bound:.4g} m at N = {N:g} N "
                             f"(its FMU's input bound: beyond it double precision cannot resolve the smallest "
                             f"slip distance {float(np.min(el.slip_radii(N))):.3g} m); give at most {bound:.4g} m")
    else:
        a = amplitude_for_force(el, args.force_amplitude, N)
    u = a * np.cos(2.0 * np.pi * np.arange(args.samples) / args.samples)
    loop = el.periodic(u, N)
    result = {
        "energy_per_cycle": loop.W_cycle, "force_amplitude": 0.5 * float(np.ptp(loop.F)),
        "displacement_amplitude": a, "N": N, "N_ref": el.N_ref, "scale": el.scale,
        "n_sliders": el.n_sliders, "k_res": el.k_res, "initial_stiffness": float(np.sum(el.k) + el.k_res),
        "input_bound": bound if math.isfinite(bound) else None,
        "gross_slip_force": el.gross_slip_force(N), "gross_slip_tail": tail,
        "samples": args.samples, "u": u, "F": loop.F,
        "curve_points": int(curve.u.size), "fit_error": el.fit_error,
    }
    if not math.isfinite(result["gross_slip_force"]):
        result["gross_slip_force"] = None          # no gross slip: k_res > 0
    if args.plot:
        result["plot"] = str(plot_loop(args.plot, el, u, loop.F, N))
    if el.fit_error > 0.0:
        print(f"note: the curve's {curve.u.size} points were reduced to the element's limit; "
              f"largest force error of the fit {el.fit_error:.3g} N", file=sys.stderr)
    if args.json:
        print_json(result)
    else:
        print(f"displacement amplitude {a:.6g} m, force amplitude "
              f"{result['force_amplitude']:.6g} N, energy per cycle {loop.W_cycle:.6g} J")
    return 0


def plot_loop(directory, el, u, F, N):
    """Write DIR/loop.png: the loop over the virgin curve (odd extension)."""
    import io
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from damper.cli.common import atomic_write

    a = float(np.max(np.abs(u)))
    uv = np.linspace(-1.3 * a, 1.3 * a, 401)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(uv * 1e6, el.virgin(uv, N), "k--", lw=1, label="virgin curve (odd extension)")
    ax.plot(np.append(u, u[0]) * 1e6, np.append(F, F[0]), "C0-", lw=1.6, label="steady loop")
    ax.set_xlabel("tangential displacement u [um]")
    ax.set_ylabel("tangential force F [N]")
    ax.grid(alpha=0.3)
    ax.legend()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120, bbox_inches="tight")
    plt.close(fig)
    return atomic_write(Path(directory) / "loop.png", buf.getvalue())
