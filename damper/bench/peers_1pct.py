"""``python -m damper.bench.peers_1pct``: the rows of :mod:`.peer_accuracy` (each tool at
its own H for 1 %) alone, without the rest of the hb stage."""
from __future__ import annotations

import sys
from pathlib import Path

from . import peer_accuracy


def main(argv=None) -> int:
    """``python -m damper.bench.peers_1pct --pyharm PYTHON [--case NAME]... [--json]``:
    the rows of :func:`.peer_accuracy.run` alone (without the rest of the hb stage)."""
    import argparse
    import json
    import tempfile

    from .hb_classes import PEER_SETTINGS, PEER_TIMEOUT_S, ModelOptions, case_names, run_ours
    from .peers import available

    ap = argparse.ArgumentParser(prog="python -m damper.bench.peers_1pct", description=main.__doc__)
    ap.add_argument("--pyharm", required=True, help="a Python interpreter with pyHarm (pip install pyharm-os)")
    ap.add_argument("--case", action="append", default=[], help="only cases whose name contains this (repeatable)")
    ap.add_argument("--json", action="store_true", help="print one JSON object with `rows`")
    args = ap.parse_args(argv)
    names = case_names(False, ModelOptions(cases=tuple(args.case)))
    say = (lambda s: print(s, file=sys.stderr)) if args.json else print
    with tempfile.TemporaryDirectory(prefix="peer_accuracy_") as tmp:
        why = available("pyharm", args.pyharm, None, Path(tmp))
        if why:
            print(f"error: pyHarm {why}", file=sys.stderr)
            return 2
        rows = [r.as_dict() for r in peer_accuracy.run(names, "pyharm", args.pyharm, Path(tmp), PEER_SETTINGS,
                                                       run_ours, timeout=PEER_TIMEOUT_S, log=say)]
    if args.json:
        print(json.dumps({"target_rel": peer_accuracy.TARGET_REL, "scan": list(peer_accuracy.SCAN),
                          "peer_settings": PEER_SETTINGS, "rows": rows}))
    else:
        print("\n".join(peer_accuracy.markdown(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
