"""``damper upd mistuning``: the mistuned ring's Monte Carlo study and its worst-pattern search.

The sub-command's options, its run, and the printed statistics and worst pattern; the
other ``damper upd`` actions and the registration are in :mod:`damper.cli.upd`.
"""
from __future__ import annotations

from .common import accuracy_lines, upd_model_options, upd_response_options


def register(s) -> None:
    """Add the ``mistuning`` action to the ``damper upd`` sub-parsers ``s``."""
    from .cache import add_cache_options

    p = s.add_parser("mistuning", help="mistuned full ring: Monte Carlo of the blades' peaks (Dask)",
                     description="Per sample the full ring's forced response (harmonic balance, or "
                     "a linear limit) and every blade's peak; amplification = worst blade / tuned "
                     "peak. Samples run as Dask tasks, each stored in the cache (a rerun resumes).")
    upd_model_options(p)
    p.add_argument("--std", type=float, help="standard deviation of the factors (default 0.02)")
    p.add_argument("--samples", type=int, help="number of random patterns (default 20)")
    p.add_argument("--seed", type=int, help="seed, >= 0; sample i draws from [seed, i] (default 1)")
    p.add_argument("--kind", choices=("stiffness", "frequency"), default="stiffness",
                   help="the factors scale the blades' stiffness, or their frequencies")
    p.add_argument("--distribution", choices=("normal", "uniform"), default="normal")
    p.add_argument("--factors", type=float, nargs="+", metavar="K",
                   help="one given pattern, a factor per blade (instead of --std/--samples)")
    p.add_argument("--blades", type=int, help="number of blades N_b (default: config)")
    p.add_argument("--engine-order", type=int, help="engine order EO (default: config)")
    upd_response_options(p)
    p.add_argument("--harmonics", type=int, default=7, help="highest harmonic H (with --accuracy "
                   "the first one tried)")
    p.add_argument("--accuracy", type=float, metavar="TOL",
                   help="relative accuracy of the tuned peak amplitude, in (1e-6, 0.5): H is raised on "
                   "the tuned sector until its estimated truncation error is below TOL, and every "
                   "sample runs at that H (default: the fixed --harmonics, the tuned estimate reported)")
    p.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"),
                   help="band [Hz] (default: around the tuned peak, widened with the scatter)")
    p.add_argument("--points", type=int, default=41,
                   help="least number of frequency points per ring curve (--solver full; more where the "
                   "tuned ring's narrowest half-power width asks, then refined at the peaks)")
    p.add_argument("--until-ci", type=float, metavar="W",
                   help="stop when the amplification's 0.95 quantile is known to +-W (its 95 %% "
                   "interval's half-width); --samples is then the most to run (default 2000)")
    p.add_argument("--solver", choices=("fast", "full"), default="fast",
                   help="fast: adaptive continuation with Hermite peaks (default); full: the "
                   "fixed grid with every point solved (the reference)")
    p.add_argument("--worst", action="store_true",
                   help="search the worst pattern within 1 +- --bound (the friction damper, or the linear "
                   "ring with --damper free|stuck)")
    p.add_argument("--bound", type=float, help="half-width B of the --worst box (default 3 --std)")
    p.add_argument("--max-evaluations", type=int, metavar="N",
                   help="with --worst and the friction damper: ring curves per start at most "
                   "(default 25)")
    p.add_argument("--out", metavar="FILE", help="with --worst: also write its JSON to FILE")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    p.add_argument("--workers", type=int, help="local Dask cluster workers (default: cores)")
    p.add_argument("--serial", action="store_true", help="no Dask: the samples in this process")
    p.add_argument("--plot", metavar="DIR", help="write mistuning_histogram.png, mistuning_blades.png")
    add_cache_options(p)
    p.set_defaults(func=run_mistuning)


def run_mistuning(args) -> int:
    import sys

    from damper.mistuning import AllSamplesFailed, run_study
    from damper.mistuning_plot import plot_study

    from .cache import store_from_args
    from .common import print_json, print_warnings

    study = _study(args)
    if args.worst or args.bound is not None or args.out is not None or args.max_evaluations is not None:
        if args.until_ci is not None:
            raise ValueError("--until-ci goes with a random study, not with --worst")
        return _run_worst(args, study)
    echo = (lambda t: print(t, file=sys.stderr)) if args.json else print
    try:
        # the cache folder checked before any sample (a file there was found only after the work)
        out = run_study(study, store_from_args(args).prepare(), args.scheduler, args.workers, args.serial, echo)
    except KeyboardInterrupt:
        from damper.run.runner import Interrupted

        raise Interrupted("mistuning interrupted; the samples finished so far are in the cache, "
                          "the same command resumes") from None
    except AllSamplesFailed as err:  # the object with every sample's error, then exit 3
        if args.json:
            print_json(err.summary)
        else:
            _print_samples(err.summary)
        raise
    if args.plot:
        out["plots"] = plot_study(out, args.plot)
    if args.json:
        print_json(out)
        print_warnings(out, ("truncation_warning", "lift_off_warning"), True)
        return 0
    _print_samples(out)
    print(f"tuned peak {out['tuned_peak']:.5e} m at {out['tuned_frequency_hz']:.2f} Hz"
          + ("" if out["damper"] != "nonlinear" else f" (H = {out['harmonics']}, every sample)")
          + "; amplification "
          f"max {out['max_amplification']:.4f} (Whitehead bound {out['whitehead_bound']:.3f}); "
          f"{out['failed']} failed, {out['cached']} from the cache, {out['time_s']:.1f} s"
          + (f"; {out['widened']} searched on a band widened past a peak at its end" if out["widened"] else ""))
    for line in statistics_lines(out):
        print(line)
    for line in accuracy_lines(out):
        print(line)
    print_warnings(out, ("lift_off_warning",), False)
    return 0


def _study(args):
    """The Study the options ask for, every option combination checked first (ValueError)."""
    from damper import limits
    from damper.mistuning import Study

    from .common import check_accuracy_option, check_out_dir

    if args.scheduler is not None and not args.scheduler.strip():   # not a silent local cluster
        raise ValueError("--scheduler '' names no scheduler: give its address (tcp://host:8786), or drop "
                         "--scheduler for a local cluster")
    given = [o for o, v in (("--scheduler", args.scheduler), ("--workers", args.workers),
                            ("--serial", args.serial)) if v]
    if len(given) > 1:
        raise ValueError(f"give one of --scheduler, --workers, --serial (got {', '.join(given)})")
    if args.workers is not None:
        limits.check_workers("--workers", args.workers)
    check_out_dir(args.plot, "--plot")
    check_accuracy_option(args.accuracy)
    limits.check_load("--cf", args.cf)
    limits.check_load("--f0", args.f0)
    if args.engine_order is not None and args.engine_order < 0:   # (the model's check names its config key)
        raise ValueError(f"--engine-order must be >= 0 (0 ... blades / 2), got {args.engine_order}")
    if args.accuracy is not None and args.damper != "nonlinear":
        raise ValueError(f"--accuracy goes with --damper nonlinear: the linear limit {args.damper!r} "
                         "has no harmonic truncation (drop --accuracy)")
    draw = {k: getattr(args, k) for k in ("std", "samples", "seed") if getattr(args, k) is not None}
    if args.until_ci is not None and args.factors is None:
        draw.setdefault("samples", UNTIL_CI_SAMPLES)
    if args.factors is not None and draw:
        raise ValueError("give --factors or --std/--samples/--seed, not both")
    study = Study(config=args.config, blades=args.blades, engine_order=args.engine_order,
                  **draw, kind=args.kind,
                  distribution=args.distribution, factors=args.factors, damper=args.damper,
                  cf=args.cf, f0=args.f0, harmonics=args.harmonics, accuracy=args.accuracy,
                  band_hz=args.band, points=args.points, until_ci=args.until_ci, solver=args.solver)
    return study


#: Most ring curves per start of a friction --worst search.
MAX_EVALUATIONS_CLI = 1000
#: Most samples of an --until-ci study without --samples.
UNTIL_CI_SAMPLES = 2000


def _ci(d: dict) -> str:
    lo, hi = ("-" if d[k] is None else f"{d[k]:.4f}" for k in ("low", "high"))
    return f"[{lo}, {hi}]"


def _quantile_line(q: dict) -> str:
    """One quantile with its interval; a one-sided interval says so, and a quantile the
    sample bounds but cannot estimate (:func:`damper.mistuning_stats.quantile_ci`) has no
    number printed as its estimate."""
    est = "-     " if q["value"] is None else f"{q['value']:.4f}"
    line = f"  quantile {q['q']:<4g} {est} {_ci(q)}"
    if (q["low"] is None) != (q["high"] is None):
        side, b = ("at least", q["low"]) if q["high"] is None else ("at most", q["high"])
        line += f" one-sided: {side} {b:.4f} at {100 * q['coverage']:.1f} % confidence"
        if q["value"] is None:
            line += "; too few samples for an estimate"
    return line


def statistics_lines(out: dict) -> list:
    """The printed statistics: mean and quantiles with their 95 % intervals, the fit, the
    stopping rule, the parallel efficiency."""
    st = out["statistics"]
    lines = [f"amplification over {st['n']} samples (95 % intervals, '-' where the sample gives no "
             f"bound): mean {st['mean']['value']:.4f} {_ci(st['mean'])}"]
    lines += [_quantile_line(q) for q in st["quantiles"]]
    fit = st["fit"]
    if fit and fit["best"]:
        f = fit["fits"][fit["best"]]
        p = f["params"]
        lines.append(f"  fit {f['family']}: c {p['c']:.4g}, loc {p['loc']:.5g}, scale {p['scale']:.4g}; "
                     f"KS distance {f['ks_distance']:.4f} (p {f['ks_pvalue']:.2g}); 0.95 quantile "
                     f"{f['quantiles']['0.95']:.4f}")
    if "until_ci" in out:
        u = out["until_ci"]
        lines.append(f"  --until-ci {u['half_width_target']:g}: " + (
            f"reached after {u['samples_used']} samples" if u["reached"] else
            f"not reached after {u['samples_used']} samples (half-width "
            f"{'unbounded' if u['half_width'] is None else format(u['half_width'], '.4g')}; give more --samples)"))
    e = out["efficiency"]
    lines.append(f"parallel efficiency {e['efficiency']:.2f}: {e['cpu_s']:.1f} s CPU in {e['chunks']} "
                 f"chunks of {e['chunk_size']} on {e['workers']} worker(s) in {e['wall_s']:.1f} s")
    return lines


def _print_samples(out: dict) -> None:
    for s in out["samples"]:
        print(f"sample {s['index']:4d}: " + (f"amplification {s['amplification']:.4f}, worst blade "
              f"{s['worst_blade']} at {s['frequency_hz']:.2f} Hz" if s["error"] is None
              else f"failed: {s['error']}"))


def _run_worst(args, study) -> int:
    """``--worst``: the worst pattern, printed (and written to --out)."""
    from pathlib import Path

    from damper.mistuning_worst import check_worst, run_worst

    from .common import atomic_write, check_out_file, dumps, print_json, print_warnings

    if not args.worst:
        raise ValueError("--bound, --out and --max-evaluations go with --worst")
    friction = {}
    if args.max_evaluations is not None:
        if study.damper != "nonlinear":
            raise ValueError("--max-evaluations limits the friction damper's search (ring curves "
                             "per start): drop it with --damper free|stuck")
        from damper import limits

        limits.check_size("--max-evaluations", args.max_evaluations, 1, MAX_EVALUATIONS_CLI,
                          "each evaluation is a ring curve (~5 s CPU at 24 blades, H = 7)")
        friction["max_evaluations"] = args.max_evaluations
    if args.plot or args.scheduler or args.workers:
        raise ValueError("--worst runs in this process and draws no plots: drop --plot, "
                         "--scheduler, --workers")
    study.check()
    check_worst(study, args.bound)
    check_out_file(args.out, "--out")   # a folder, an unwritable one (/proc), before the search
    out = run_worst(study, args.bound, **friction)
    if args.out is not None:   # dumps: a non-finite number refused (exit 3), not written as NaN
        atomic_write(Path(args.out), dumps(out, indent=1) + "\n")
    if args.json:
        print_json(out)
    else:
        for line in worst_lines(out):
            print(line)
    print_warnings(out, ("lift_off_warning",), args.json)
    return 0


def worst_lines(out: dict) -> list:
    """The printed worst pattern: amplification, factors, convergence, the time-integration
    check (friction damper)."""
    lines = [f"worst pattern within 1 +- {out['bound']:.4g} ({out['damper']} damper, {out['blades']} "
             f"blades): amplification {out['amplification']:.4f} (Whitehead bound "
             f"{out['whitehead_bound']:.3f}, linear disks) at {out['frequency_hz']:.2f} Hz on blade "
             f"{out['worst_blade']}",
             "factors: " + " ".join(f"{k:.5f}" for k in out["factors"])]
    if out["damper"] == "nonlinear":
        lines += [f"  start {s['label']}: " + ("no pattern solved" if s["amplification"] is None else
                  f"amplification {s['amplification']:.4f}") + f", {s['evaluations']} ring curves, "
                  f"{s['message']}" for s in out["starts"]]
    if not out["converged"]:
        lines.append(f"note: the best start's optimizer did not converge ({out['message']}); the best "
                     "pattern found is shown")
    c = out.get("timeint_check")
    if c:
        lines.append(f"time integration at {out['frequency_hz']:.2f} Hz: blade {out['worst_blade']} "
                     f"{c['timeint_amplitude']:.5e} m, {100 * c['rel_diff']:+.2f} % from the HB peak "
                     f"(H = {out['harmonics']}; " + ("within 1 %" if c["within_1_percent"] else "not within 1 %")
                     + (f"; HB at H = {c['check_harmonics']}: {100 * c['rel_diff_check']:+.2f} %"
                        if c["rel_diff_check"] is not None else "")
                     + f"; {c['periods']} periods" + ("" if c["settled"] else ", not settled") + ")")
    return lines
