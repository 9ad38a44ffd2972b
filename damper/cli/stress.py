"""``damper stress``: extreme but legal inputs over every stage, each case checked, and bad inputs.

Each case runs in a child process with a time limit (a hang is detected, not
suffered), ends converged and checked (equilibrium, force bounds, energy) or
with a clear error; the table of outcomes is printed and saved. The ``inputs``
stage tries bad inputs over every subcommand and file type: each must end with
exit code 2 or 3, one line, no traceback and no file written (plus the cache's
and the runner's duties: a user's file in the cache folder kept, a corrupt
entry recomputed, Ctrl-C one line and exit code 130).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def register(sub) -> None:
    p = sub.add_parser("stress", help="stress run: extreme inputs over every stage, outcomes classified",
                       description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="the quick subset (about a minute or two)")
    p.add_argument("--stage", action="append", choices=("inputs", "normal", "tangential", "loop", "fmu", "frf"),
                   help="only these stages (repeatable); inputs: bad inputs over every subcommand and file type")
    p.add_argument("--case", action="append", help="only the cases whose name contains this text (repeatable)")
    p.add_argument("--out", default="out/stress", help="folder for stress.json and stress.md")
    p.add_argument("--json", action="store_true", help="print one JSON object with `cases`")
    p.set_defaults(func=run, out_folder=True)


def run(args) -> int:
    from contact_core.fileio import atomic_write
    from damper.stress import inputs, runner

    from .common import check_out_dir

    check_out_dir(args.out, "--out")
    log = (lambda s: print(s, file=sys.stderr, flush=True)) if args.json else (lambda s: print(s, flush=True))
    rows = runner.run(quick=args.quick, stages=args.stage, log=log, match=args.case)
    if not rows:
        raise ValueError("no stress case matches --stage/--case")
    summ = runner.summary(rows)
    out = Path(args.out)
    result = {"cases": rows, "summary": summ, "quick": args.quick}
    atomic_write(out / "stress.json", json.dumps(result, indent=1) + "\n")
    atomic_write(out / "stress.md", inputs.group_table(rows) + "\n" + runner.table(rows))
    if args.json:
        print(json.dumps(result))
    else:
        print(runner.table(rows))
        print(f"outcomes: {summ['counts']}; unexpected {summ['unexpected']}, unexplained {len(summ['unexplained'])}"
              f"; table in {out / 'stress.md'}")
    return 1 if summ["unexplained"] else 0
