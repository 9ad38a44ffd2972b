"""Run a ``damper ... --json`` command and keep its output, stamped, as documentation data.

The performance and stability pages are rendered from these files, so every figure
on them names the command, the code revision, the date and the machine it came from::

    python docs/tools/record.py docs/data/bench.json -- damper bench --json
    python docs/tools/record.py docs/data/stress.json -- damper stress --json

The command's JSON (its last stdout line that parses as an object) is stored under
``result`` next to ``stamp`` (machine, cores, load average, library versions, git
revision, UTC date: :func:`damper.bench.common.stamp`), ``command`` (as typed after
``--``, with no folder of the machine: :func:`portable`) and ``exit_code``. The file is
written only when the command printed a JSON object, through a temporary file and a
rename (nothing half-written).
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

#: The repository: paths inside it are recorded relative to it.
ROOT = Path(__file__).resolve().parents[2]


def portable(command: list[str], root: Path = ROOT) -> list[str]:
    """The command as it reads on any machine: an absolute path inside the repository
    relative to it; one outside it (a peer tool's interpreter or checkout) as the name of
    the option it follows in capitals, as the Makefile's variables (``--pyharm PYHARM``),
    or ``PATH``. Other arguments as typed.
    """
    out = []
    for i, arg in enumerate(command):
        opt, eq, value = arg.partition("=") if arg.startswith("--") else ("", "", arg)
        if not value.startswith("/"):
            out.append(arg)
            continue
        try:  # normpath, not resolve: .venv/bin/python is a link out of the repository
            value = Path(os.path.normpath(value)).relative_to(root).as_posix() or "."
        except ValueError:
            before = opt if eq else (command[i - 1] if i else "")
            value = before.lstrip("-").replace("-", "_").upper() if before.startswith("--") else "PATH"
        out.append(f"{opt}={value}" if eq else value)
    return out


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--" not in argv:
        print("usage: record.py OUT.json -- COMMAND [ARGS...]", file=sys.stderr)
        return 2
    cut = argv.index("--")
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="the data file to write (JSON)")
    args = ap.parse_args(argv[:cut])
    command = argv[cut + 1:]
    if not command:
        print("record.py: error: no command after --", file=sys.stderr)
        return 2
    from damper.bench.common import revision, stamp

    started_at = revision()   # the code that runs: a commit made during a long run must not be named
    t0 = time.perf_counter()
    proc = subprocess.run(command, stdout=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    result = None
    for line in reversed(proc.stdout.strip().splitlines()):
        try:
            result = json.loads(line)
            break
        except ValueError:
            continue
    if not isinstance(result, dict):
        print(f"record.py: error: `{shlex.join(command)}` printed no JSON object (exit {proc.returncode}); "
              f"nothing written", file=sys.stderr)
        return 3
    data = {"command": shlex.join(portable(command)), "exit_code": proc.returncode, "wall_s": round(wall, 1),
            "stamp": {**stamp(), "revision": started_at}, "result": result}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(args.out.suffix + ".tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(args.out)
    print(f"wrote {args.out} ({shlex.join(portable(command))}, exit {proc.returncode}, {wall:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
