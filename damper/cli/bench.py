"""``damper bench``: every stage's accuracy against cost in one run, one report.

Writes DIR/bench.json (``stages``: stage -> rows {case, size, error, time_s,
memory_mb, cached}, plus the run's stamp) and DIR/bench.html (a plot of error
against time per stage, the tool's defaults starred). ``--quick`` is a small
version (about a minute) that the tests run; ``--solvers`` adds the sparse
back ends on the 21x21 and 41x41 sphere (minutes). The hb stage ends with whole
curves of the model classes (single-DOF soft and stiff, 3- and 5-mass friction
chains, UPD-24), and of the peers pyHarm (``--pyharm PYTHON``) and NLvib
(``--nlvib DIR``, GNU Octave) on the same cases when given::

    damper bench --stage hb --pyharm /opt/pyharm/bin/python --nlvib /opt/NLvib --out out/bench
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path


def register(sub) -> None:
    p = sub.add_parser("bench", help="benchmark: error against time of every stage, one report",
                       description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="small sizes only (about a minute)")
    p.add_argument("--out", default="out/bench", help="folder for bench.json and bench.html")
    p.add_argument("--stage", action="append", help="only these stages (repeatable): contact, tangential, "
                   "element, fmu, hb, surface, solvers")
    p.add_argument("--solvers", action="store_true", help="also time every sparse back end (slow)")
    p.add_argument("--json", action="store_true", help="print one JSON object with `stages`")
    g = p.add_argument_group("hb stage: model classes and peers (damper.bench.hb_classes)")
    g.add_argument("--full", action="store_true", help="all 18 curves of the 3-mass chain (default: 4)")
    g.add_argument("--case", action="append", default=[], metavar="TEXT",
                   help="only the model cases whose name contains TEXT (repeatable), e.g. 'chain5', 'sdof soft'")
    g.add_argument("--pyharm", metavar="PYTHON", help="a Python interpreter with pyHarm (pip install pyharm-os)")
    g.add_argument("--nlvib", metavar="DIR", help="an NLvib folder (github.com/maltekrack/NLvib), run by Octave")
    g.add_argument("--octave", metavar="EXE", help="GNU Octave for NLvib (default: octave on PATH)")
    p.set_defaults(func=run, out_folder=True)


def run(args) -> int:
    from damper.bench import report, solvers, stages
    from damper.bench.common import stamp
    from damper.bench.hb_classes import ModelOptions, case_names

    log = (lambda s: print(s, file=sys.stderr, flush=True)) if args.json else (lambda s: print(s, flush=True))
    models = ModelOptions(args.full, tuple(args.case), args.pyharm, args.nlvib, args.octave)
    if args.case and not case_names(args.quick, models):
        raise ValueError(f"--case {args.case} matches no model case; names: "
                         f"{', '.join(case_names(False, ModelOptions(full=True)))}")
    funcs = dict(stages.STAGES)
    funcs["hb"] = lambda quick, work, log: stages.hb(quick, work, log, models)
    funcs["solvers"] = lambda quick, work, log: solvers.run(grids=(5,) if quick else (21, 41), log=log)
    names = args.stage or [n for n in funcs if n != "solvers" or args.solvers]
    bad = [n for n in names if n not in funcs]
    if bad:
        raise ValueError(f"unknown stage(s) {', '.join(map(repr, bad))}: use {', '.join(funcs)}")
    from .common import check_out_dir

    check_out_dir(args.out, "--out")
    result = {"stamp": stamp(), "quick": args.quick, "stages": {}}
    with tempfile.TemporaryDirectory(prefix="damper_bench_") as work:
        for name in names:
            log(f"== {name}")
            sub = Path(work) / name
            sub.mkdir()
            result["stages"][name] = [r.as_dict() for r in funcs[name](args.quick, sub, log)]
    j, h = report.write(Path(args.out), result)
    if args.json:
        print(json.dumps(result))
    else:
        for name, rows in result["stages"].items():
            print(report.table_text(name, rows))
        print(f"report: {h} ({j})")
    empty = [n for n, rows in result["stages"].items() if not rows]
    if empty:
        print(f"damper bench: failed: no result for stage(s) {', '.join(empty)}", file=sys.stderr)
        return 3
    return 0
