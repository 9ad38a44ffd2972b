"""The ``damper`` console command.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``, which adds an ``argparse`` parser whose default
``func(args) -> int`` runs it. Heavy imports happen inside ``func`` so that
``damper --help`` stays fast.

Exit codes: 0 success, 2 bad input (``ValueError``, ``OSError``: a clear
message on stderr, nothing written), 3 a solver that did not converge
(``RuntimeError``).
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys

# Small dense work (contact compliances, AFT) runs slower with two BLAS threads than
# with one on the 2-core machines we measure on (bem 41x41 tangential: 3.2 s vs 1.9 s);
# set before numpy is first imported. A user's own setting wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

#: Subcommand modules, in the order ``damper --help`` lists them.
SUBCOMMANDS = ("run", "sweep", "cache", "normal", "tangential", "loop", "fmu", "frf", "backbone", "upd", "system",
               "cosim", "study",
               "bench", "stress")


def build_parser() -> argparse.ArgumentParser:
    """Return the top-level parser with every available subcommand."""
    parser = argparse.ArgumentParser(
        prog="damper",
        description="Friction-damper design toolkit: contact stiffness and virgin "
        "curves (FE), the Masing/Iwan friction element, harmonic balance.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in SUBCOMMANDS:
        try:
            module = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as err:
            if err.name != f"{__name__}.{name}":
                raise
            continue  # subcommand not built yet
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``damper`` command; return the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (ValueError, OSError) as err:
        print(f"damper {args.command}: error: {err}", file=sys.stderr)
        return 2
    except RuntimeError as err:
        print(f"damper {args.command}: failed: {err}", file=sys.stderr)
        return 3


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
