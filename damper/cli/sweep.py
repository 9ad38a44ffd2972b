"""``damper sweep``: run a scene for several values of its parameters, on Dask.

Examples::

    damper sweep scene.toml --param contact.damper.mu --values 0.3 0.5 0.7
    damper sweep scene.toml --param contact.damper.force --range 60 180 5 --out out/sweep
    damper sweep scene.toml --param contact.damper.mu --values 0.3 0.5 \\
        --param excitation.forces --values '[10]' '[20]'            # a grid of two parameters
    damper sweep scene.toml --param ... --values ... --scheduler tcp://host:8786

A parameter is a dotted scene key (``contact.NAME.KEY``, ``structure.zeta``, ...).
``--values`` takes the values (JSON: numbers, lists), ``--range START STOP NUM`` evenly
spaced numbers; several parameters form a grid (``--zip``: taken in step). Stages
shared by the variants run once; every variant then runs as one task on a Dask local
cluster (one worker per core, ``--workers``), an existing cluster (``--scheduler``),
or in this process (``--serial``). Writes ``sweep.csv``, ``sweep.json`` and
``sweep.png`` into ``--out``; ``--json`` prints the table as one object.

Every variant is validated before any work (a bad value: exit 2, nothing written). A
variant that fails while it runs (a solver that does not converge) does not stop the
others: its row has the message in the ``error`` column, the table is written, and the
command exits with code 3 at the end; ``--fail-fast`` stops at the first failure instead.
At most 1000 variants (each is one scene run).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .cache import add_cache_options, store_from_args


class _Ordered(argparse.Action):
    """Keep --param / --values / --range in the order given (they pair up)."""

    def __call__(self, parser, namespace, values, option_string=None):
        items = getattr(namespace, "specs", None) or []
        items.append((self.dest, values))
        namespace.specs = items


def register(subparsers) -> None:
    """Add the ``sweep`` subcommand."""
    p = subparsers.add_parser("sweep", help="run a scene over parameter values (Dask)", description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene")
    p.add_argument("--param", action=_Ordered, dest="param", metavar="KEY", help="dotted scene key")
    p.add_argument("--values", action=_Ordered, dest="values", nargs="+", metavar="V")
    p.add_argument("--range", action=_Ordered, dest="range", nargs=3, metavar=("START", "STOP", "NUM"))
    p.add_argument("--zip", action="store_true", help="take the parameters' values in step, not as a grid")
    p.add_argument("--out", type=Path, default=None, help="output folder (default out/sweep_<scene name>)")
    p.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler")
    p.add_argument("--workers", type=int, default=None, help="local cluster workers (default: cores)")
    p.add_argument("--serial", action="store_true", help="no Dask: run the tasks in this process")
    p.add_argument("--json", action="store_true", help="print the table as one JSON object")
    p.add_argument("--fail-fast", action="store_true",
                   help="stop at the first variant that fails (default: run every variant, report failures "
                   "in the table's error column and exit with code 3)")
    add_cache_options(p)
    p.set_defaults(func=run, specs=None, out_folder=True)


def specs_from(items) -> list[tuple[str, list]]:
    """[(param, values)] from the ordered --param/--values/--range items."""
    import numpy as np

    from damper import limits
    from damper.sweep import parse_value

    out, name, last = [], None, None
    for kind, v in items or []:
        if kind == "param":
            if name is not None:
                raise ValueError(f"--param {name} has no --values or --range")
            name = v
            continue
        if name is None:
            text = f"--{kind} {' '.join(v)}"
            if last is None:
                raise ValueError(f"{text}: give its --param KEY first")
            raise ValueError(f"{text} has no --param of its own (--param {last} already has its values): "
                             "give every --param one --values or --range")
        if kind == "values":
            out.append((name, [parse_value(t) for t in v]))
        else:
            try:
                a, b, n = float(v[0]), float(v[1]), int(v[2])
            except ValueError:
                raise ValueError(f"--range needs START STOP NUM (numbers, NUM an integer), got "
                                 f"{' '.join(v)}") from None
            if not (np.isfinite(a) and np.isfinite(b)):
                raise ValueError(f"--range {' '.join(v)}: START and STOP must be finite")
            limits.check_size("--range NUM", n, 1, limits.MAX_SWEEP_VARIANTS,
                              "each value is one scene run (seconds to minutes)")
            out.append((name, [float(x) for x in np.linspace(a, b, n)]))
        name, last = None, name
    if name is not None:
        raise ValueError(f"--param {name} has no --values or --range")
    return out


def check_distinct_variants(specs, zipped: bool) -> None:
    """Refuse two variants that are the same run (a value given twice: ``--values 0.5 0.5``,
    ``--range 0.5 0.5 3``; with ``--zip``, the same tuple twice), before any work."""
    if zipped:
        rows = list(zip(*(values for _, values in specs)))
        twice = [r for i, r in enumerate(rows) if r in rows[:i]]
        if twice:
            raise ValueError(f"--zip: the values {', '.join(f'{n}={v}' for (n, _), v in zip(specs, twice[0]))} "
                             "are given twice: the two variants would be the same run; give distinct ones")
        return
    for name, values in specs:
        twice = [v for i, v in enumerate(values) if v in values[:i]]
        if twice:
            raise ValueError(f"--param {name}: {twice[0]} is given twice: the two variants would be the same "
                             "run; give distinct values")


def run(args) -> int:
    from damper import limits
    from damper.scene import load_scene
    from damper.sweep import run_sweep

    from .common import check_folder_holds_no_input, check_out_dir, print_json

    if args.workers is not None:
        limits.check_workers("--workers", args.workers)
    if args.scheduler is not None and not args.scheduler.strip():   # not a silent local cluster
        raise ValueError("--scheduler '' names no scheduler: give its address (tcp://host:8786), or drop "
                         "--scheduler for a local cluster")
    specs = specs_from(args.specs)
    check_distinct_variants(specs, args.zip)
    out = args.out if args.out is not None else Path("out") / f"sweep_{Path(args.scene).stem}"
    flag = "--out" if args.out is not None else "the default output folder (no --out)"   # (as damper run)
    check_folder_holds_no_input(out, flag, [("scene", Path(args.scene))] + load_scene(args.scene).files())
    check_out_dir(out, "--out")
    store = store_from_args(args).prepare()
    echo = (lambda t: print(t, file=sys.stderr)) if args.json else print
    rec = run_sweep(args.scene, specs, store, out, grid=not args.zip, scheduler=args.scheduler,
                    workers=args.workers, serial=args.serial, echo=echo, fail_fast=args.fail_fast)
    if args.json:
        print_json(rec.to_json())
    else:
        for row in rec.rows:
            print("  ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()
                            if v is not None))
        print(f"results in {out}/ (sweep.csv, sweep.json, sweep.png); shared stages: {', '.join(rec.shared) or 'none'}")
    failed = [r for r in rec.rows if r.get("error")]
    if failed:
        print(f"damper sweep: failed: {len(failed)} of {len(rec.rows)} variant(s) failed (the error column of "
              f"{out / 'sweep.csv'} says why); the others are in the table", file=sys.stderr)
        return 3
    return 0
