"""The example scripts' command lines, answered as the ``damper`` command answers its own.

Each script in ``examples/`` is a command a user runs. A bad argument is refused by
``argparse`` (usage line, exit 2) through the types here, checked before any work:
:func:`count` (an integer with a lower bound), :func:`numbers` (a comma-separated list)
and :func:`out_folder` (an output folder that is not a file). :func:`run` runs a script's
``main`` and turns what the libraries refuse into one line on stderr: a ValueError or
OSError (bad input, a file that cannot be read or written) exit 2, a RuntimeError (a
solver that failed) exit 3, Ctrl-C exit 130, never a traceback.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def count(low: int = 1):
    """An argparse ``type``: an integer >= ``low`` (a size, a number of samples or repeats)."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be an integer >= {low}, got {value}")
        return value
    parse.__name__ = f"integer >= {low}"
    return parse


def numbers(kind=float, low: float | None = None):
    """An argparse ``type``: comma-separated numbers of ``kind`` (int or float), each finite
    and >= ``low`` when given, at least one."""
    import math

    def parse(text: str) -> list:
        try:
            values = [kind(v) for v in text.split(",")]
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: give comma-separated {kind.__name__} values, "
                                             "e.g. 1,2,3") from None
        for v in values:
            if not math.isfinite(v) or (low is not None and v < low):
                raise argparse.ArgumentTypeError(f"{text!r}: every value must be finite"
                                                 + ("" if low is None else f" and >= {low:g}") + f", got {v:g}")
        return values
    parse.__name__ = f"comma-separated {kind.__name__} values"
    return parse


def out_folder(text: str) -> Path:
    """An argparse ``type``: an output folder, refused if a file of that name exists (the
    script would fail at its first write, after the work)."""
    path = Path(text)
    if not text or (path.exists() and not path.is_dir()):
        raise argparse.ArgumentTypeError(f"{text!r}: a file of that name exists (or the name is empty); "
                                         "give a folder")
    return path


def run(main) -> int:
    """``main()``'s exit code (0 when it returns no int: a result); a refused input, an
    unwritable output or a failed solve as one line ``<script>: error: ...`` (exit 2) or
    ``<script>: failed: ...`` (exit 3) on stderr."""
    from damper.cli import _text

    name = Path(sys.argv[0]).name
    try:
        code = main()
        return code if isinstance(code, int) else 0
    except (ValueError, OSError) as err:
        print(f"{name}: error: {_text(err)}", file=sys.stderr)
        return 2
    except RuntimeError as err:
        print(f"{name}: failed: {_text(err)}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr)
        return 130
