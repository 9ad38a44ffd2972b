"""``damper run``: run a scene, computing only the stages its wanted results need.

Examples::

    damper run examples/scenes/default.toml --out out
    damper run examples/scenes/kn_only.toml --dry-run
    damper run scene.toml --force tangential:damper --json

The scene (TOML, ``damper.scene.schema``) is validated before anything runs; a bad
scene exits with code 2 naming the key and the file line, and writes nothing. The
plan lists every stage with its action (compute, cached, skip) and why; the stages
then run (a progress bar on a terminal, plain lines otherwise), every result goes to
the shared content-addressed cache (``damper cache info``) and the output folder
(``--out``, default ``out/<scene name>``) with its provenance. The output folder is
written once every stage has finished: a run that fails or is interrupted (Ctrl-C: one
line, exit code 130) writes nothing there, and its finished stages are in the cache.
``--no-cache`` keeps every result in memory for this run (nothing read from or written
to the cache folder); a cache folder this user cannot write is read, not written.

``--json`` prints one object: ``stages`` (list of {name, action, reason}), and after a
run ``outputs`` (wanted result -> file(s)) and ``times`` (stage -> seconds).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .cache import add_cache_options, store_from_args


def register(subparsers) -> None:
    """Add the ``run`` subcommand."""
    p = subparsers.add_parser("run", help="run a scene: plan, cached stages, output folder and report",
                              description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="scene file (TOML)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default out/<scene name>)")
    p.add_argument("--json", action="store_true", help="print the plan (and run record) as one JSON object")
    p.add_argument("--dry-run", action="store_true", help="print the plan only")
    p.add_argument("--force", action="append", default=[], metavar="STAGE",
                   help="recompute this stage (name or kind) and what depends on it; repeatable")
    p.add_argument("--no-cache", action="store_true",
                   help="neither read nor write the cache folder (results stay in memory for this run)")
    add_cache_options(p)
    p.set_defaults(func=run, out_folder=True)


def run(args) -> int:
    from damper.run.runner import run_scene
    from damper.scene import load_scene

    from .common import check_folder_holds_no_input, check_out_dir, print_json

    if args.no_cache and args.cache_dir is not None:
        raise ValueError("--no-cache and --cache-dir exclude each other")
    scene = load_scene(args.scene)
    out = args.out if args.out is not None else Path("out") / Path(args.scene).stem
    if not args.dry_run:
        # the default folder too: a scene kept in out/<its name>/ would have its run's files
        # (run.json, the stages' folders) written over or beside it, then fail after the work
        flag = "--out" if args.out is not None else "the default output folder (no --out)"
        check_folder_holds_no_input(out, flag, [("scene", Path(args.scene))] + scene.files())
        check_out_dir(out, "--out")
    store = store_from_args(args).prepare()
    echo = (lambda text: print(text, file=sys.stderr)) if args.json else print
    progress = None
    if args.json:
        from damper.run.progress import Progress

        progress = Progress(0, live=False, out=sys.stderr)
    rec = run_scene(scene, store, None if args.dry_run else out, force=args.force, dry_run=args.dry_run,
                    progress=progress, echo=echo)
    if args.json:
        print_json({"stages": rec.plan.to_json()} if args.dry_run else rec.to_json())
    elif not args.dry_run:
        print(f"results in {out}/" + (f" (report: {rec.outputs['report']})" if "report" in rec.outputs else ""))
    return 0
