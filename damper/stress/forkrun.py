"""Run many short ``damper`` commands fast: one forked child each, with a time limit.

A fresh interpreter per command spends a second or more importing numpy, scipy and the
toolkit; the input stage runs hundreds of commands that mostly end within
milliseconds. This process imports everything once (:func:`preload`) and forks one
child per command: the child enters its own folder, points the cache there, redirects
its output to files, caps its address space (a runaway allocation fails instead of
exhausting a shared machine), runs ``damper.cli.main`` as the console script does
(``SystemExit`` is its exit code, any other exception prints a traceback and exits
with 1), and leaves with ``os._exit``. The parent kills the child's process group when
the time limit passes (a hang is classified, not waited on), or sends it SIGINT when
asked to interrupt it once a text shows in its standard error.
"""
from __future__ import annotations

import importlib
import os
import resource
import signal
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

#: Modules imported once in the parent so that children start with them loaded.
PRELOAD = ("numpy", "scipy.linalg", "scipy.sparse", "scipy.optimize", "damper.cli", "damper.cli.common",
           "damper.scene", "damper.run.runner", "damper.run.kinds", "damper.sweep", "contact_core.condense",
           "contact_core.api", "contact_core.tangential_run", "contact_core.curve", "fmu_src.element",
           "fmu_src.curve_fit", "harmonic_balance.frf", "harmonic_balance.epmc", "harmonic_balance.model",
           "harmonic_balance.bladed_disk.config")
#: Address-space cap of a child [bytes]: the input cases need well under 1 GB.
MEMORY_CAP = 4 * 2**30
#: Seconds between polls of a running child.
POLL_S = 0.005


@dataclass
class Finished:
    """Outcome of one child: exit code (None after the time limit), output texts, wall time."""

    code: int | None
    stdout: str
    stderr: str
    time_s: float
    interrupted: bool = False


def preload() -> None:
    """Import the heavy modules once (each child inherits them)."""
    for name in PRELOAD:
        importlib.import_module(name)
    for name in __import__("damper.cli", fromlist=["SUBCOMMANDS"]).SUBCOMMANDS:
        importlib.import_module(f"damper.cli.{name}")


def _child(argv: list[str], cwd: Path, env: dict, out: Path, err: Path) -> None:
    """In the forked child: set up, run the command, exit (never returns)."""
    code = 1
    try:
        os.setpgid(0, 0)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        os.chdir(cwd)
        os.environ.update(env)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        for fd, path in ((1, out), (2, err)):
            f = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(f, fd)
            os.close(f)
        # the streams themselves too (a test runner may have replaced them with its own objects)
        sys.stdout = open(1, "w", closefd=False)  # noqa: SIM115
        sys.stderr = open(2, "w", closefd=False)  # noqa: SIM115
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
        sys.argv = ["damper", *argv]
        from damper.cli import main

        try:
            code = int(main(argv) or 0)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            if isinstance(exc.code, str):
                print(exc.code, file=sys.stderr)
        except BaseException:  # noqa: BLE001 - what the interpreter would print for an uncaught exception
            traceback.print_exc()
            code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


def run(argv: list[str], cwd: Path, timeout: float, env: dict | None = None,
        interrupt_on: str | None = None, interrupt_delay: float = 0.3) -> Finished:
    """Run ``damper ARGV`` in a forked child in ``cwd`` (its ``.out``/``.err`` files go to ``cwd.parent``).

    ``interrupt_on``: send SIGINT ``interrupt_delay`` s after this text first shows in the
    child's standard error.
    """
    cwd = Path(cwd)
    out, err = cwd.parent / f"{cwd.name}.out", cwd.parent / f"{cwd.name}.err"
    sys.stdout.flush()
    sys.stderr.flush()
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        _child(argv, cwd, dict(env or {}), out, err)
    code, interrupted, seen_at = None, False, None
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code = os.waitstatus_to_exitcode(status)
            break
        now = time.perf_counter()
        if now - t0 > timeout:
            _kill(pid)
            break
        if interrupt_on and not interrupted:
            if seen_at is None and interrupt_on in _read(err):
                seen_at = now
            if seen_at is not None and now - seen_at >= interrupt_delay:
                with _suppress():
                    os.kill(pid, signal.SIGINT)
                interrupted = True
        time.sleep(POLL_S)
    wall = time.perf_counter() - t0
    return Finished(code, _read(out), _read(err), wall, interrupted)


def _kill(pid: int) -> None:
    """Kill the child's process group (and the child), then reap it."""
    for target in (lambda: os.killpg(pid, signal.SIGKILL), lambda: os.kill(pid, signal.SIGKILL)):
        with _suppress():
            target()
    with _suppress():
        os.waitpid(pid, 0)


class _suppress:
    def __enter__(self):
        return self

    def __exit__(self, kind, value, tb):
        return kind is not None and issubclass(kind, (ProcessLookupError, ChildProcessError, PermissionError))


def _read(path: Path) -> str:
    try:
        return path.read_text(errors="replace")
    except OSError:
        return ""
