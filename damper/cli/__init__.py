"""The ``damper`` console command.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``, which adds an ``argparse`` parser whose default
``func(args) -> int`` runs it. Heavy imports happen inside ``func`` so that
``damper --help`` stays fast.

Exit codes: 0 success, 2 bad input (``ValueError``, ``OSError``: a clear
message on stderr, nothing written), 3 a solver that did not converge
(``RuntimeError``), 130 interrupted (Ctrl-C: one line saying where), 143 terminated
(SIGTERM: handled as Ctrl-C, so temporary folders are removed on the way out).
With ``--json``, exit codes 2 and 3 also print one JSON object on stdout,
``{"error": message, "exit_code": code}``, unless the command printed its own
partial result.
Warnings (numpy's overflow, a library's note) print as one line each, once per
message, however often their cause repeats.
"""
from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import warnings

# Small dense work (contact compliances, AFT) runs slower with two BLAS threads than
# with one on the 2-core machines we measure on (bem 41x41 tangential: 3.2 s vs 1.9 s);
# set before numpy is first imported. A user's own setting wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

#: Subcommand modules, in the order ``damper --help`` lists them.
SUBCOMMANDS = ("run", "sweep", "cache", "normal", "tangential", "loop", "fmu", "frf", "backbone", "upd", "system",
               "cosim", "study",
               "bench", "stress")


#: A negative number as a command-line value (``--k-n -5e7``, ``--shift -.5``, ``-inf``):
#: argparse's own pattern knows only ``-5`` and ``-0.5`` and reads ``-5e7`` as an option.
NEGATIVE_NUMBER = re.compile(r"^-(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|inf|infinity|nan)$", re.IGNORECASE)


class Parser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line (``prog: error: message``,
    exit 2, no usage block) and which reads any negative number as a value.

    Subparsers are of the same class (``add_subparsers`` takes the parent's class).
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    #: The last refusal's line (``damper.cli._parse`` prints it as JSON with ``--json``).
    last_error = None

    def error(self, message: str):
        """Print one line naming the command and where its options are listed; exit 2."""
        text = " ".join(str(message).split())
        Parser.last_error = f"{self.prog}: error: {text} (see {self.prog} --help)"
        self.exit(2, Parser.last_error + "\n")

    def add_subparsers(self, **kwargs):
        kwargs.setdefault("parser_class", _SubParser)
        return super().add_subparsers(**kwargs)


class _SubParser(Parser):
    """A subcommand's parser: refuses arguments it does not know itself, so the message
    names the subcommand (argparse would leave them to ``damper``'s parser)."""

    def parse_known_args(self, args=None, namespace=None):
        namespace, extras = super().parse_known_args(args, namespace)
        if extras:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        return namespace, extras


def build_parser() -> argparse.ArgumentParser:
    """Return the top-level parser with every available subcommand."""
    parser = Parser(
        prog="damper",
        description="Friction-damper design toolkit: contact stiffness and virgin "
        "curves (FE), the Masing/Iwan friction element, harmonic balance.",
    )
    parser.add_argument("--version", action="version", version=f"damper {version()}")
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


def version() -> str:
    """The installed package's version, with the git revision of the code when there is one."""
    from importlib import metadata

    try:
        text = metadata.version("damper-toolkit")
    except metadata.PackageNotFoundError:
        text = "unknown"
    from damper.provenance import git_revision

    rev = git_revision()
    if rev.get("commit"):
        text += f" (git {rev['commit'][:12]}{', modified' if rev.get('dirty') else ''})"
    return text


def _one_line_warnings(command: str) -> None:
    """Each distinct warning once, as one line naming the command (no source line, no repeats)."""
    seen = set()

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        if (category, text) not in seen:
            seen.add((category, text))
            print(f"damper {command}: warning: {text} ({category.__name__})", file=file or sys.stderr)

    warnings.showwarning = show


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that cleanup (finally, with) runs as for Ctrl-C."""


def _on_sigterm(signum, frame):
    raise Terminated("terminated (SIGTERM)")


def _sigterm_as_interrupt():
    """Install :func:`_on_sigterm` (main thread only); return the handler to restore, or None."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.signal(signal.SIGTERM, _on_sigterm)


def main(argv: list[str] | None = None) -> int:
    """Run the ``damper`` command; return the process exit code."""
    import signal

    previous = _sigterm_as_interrupt()
    try:
        return _main(argv)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _main(argv: list[str] | None) -> int:
    command = "damper"
    from .jsonout import STATE

    STATE["printed"] = False  # main may run several commands in one process (tests)
    _blas_threads_as_set()
    try:
        parser = build_parser()
        args = _parse(parser, argv)
        command = args.command
        _one_line_warnings(command)
        try:
            from contact_core.fileio import guard_inputs

            from .common import check_outputs

            check_outputs(args)
            with guard_inputs():
                return int(args.func(args) or 0)
        except (ValueError, OSError) as err:
            return _failed(args, f"damper {command}: error: {_text(err)}", 2)
        except RuntimeError as err:
            return _failed(args, f"damper {command}: failed: {_text(err)}", 3)
    except KeyboardInterrupt as err:
        where = getattr(err, "message", "")
        if isinstance(err, Terminated) or isinstance(err.__context__, Terminated):  # (re-raised with a where)
            text = where.replace("interrupted", "terminated (SIGTERM)", 1) if where else "terminated (SIGTERM)"
            print(f"damper {command}: {text}", file=sys.stderr)
            return 143
        print(f"damper {command}: {where or 'interrupted'}", file=sys.stderr)
        return 130


def _parse(parser, argv):
    """``parser.parse_args``; with ``--json`` among the arguments, a refusal of the command
    line also prints its JSON error object (:func:`_failed`)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        return parser.parse_args(argv)
    except SystemExit as stop:
        if stop.code == 2 and "--json" in argv:
            from .common import print_json_error

            print_json_error(Parser.last_error or "bad command line", 2)
        raise


def _failed(args, line: str, code: int) -> int:
    """Print the one-line message on stderr (and, with ``--json``, the JSON error object on
    stdout, so a program reading stdout gets an object on failure too); return ``code``."""
    print(line, file=sys.stderr)
    if getattr(args, "json", False) is True:
        from .common import print_json_error

        print_json_error(line, code)
    return code


def _blas_threads_as_set() -> None:
    """Apply OPENBLAS_NUM_THREADS also when numpy was loaded before this module (``main``
    called from Python, a test): the environment variable alone is read only at load, and a
    run in-process must give the same bits as the command."""
    if "numpy" not in sys.modules:
        return
    try:
        threads = int(os.environ["OPENBLAS_NUM_THREADS"])
        from threadpoolctl import threadpool_limits
    except (KeyError, ValueError, ImportError):  # a user's own odd setting: leave BLAS as it is
        return
    threadpool_limits(limits=threads, user_api="blas")


def _text(err: BaseException) -> str:
    """One line of an error's message (an OSError without its errno prefix)."""
    if isinstance(err, OSError) and err.strerror and err.filename:
        text = f"{err.filename}: {err.strerror}"
    else:
        text = str(err) or type(err).__name__
    # a numpy scalar's repr (np.float64(7.0)) reads as the plain number it is
    text = re.sub(r"np\.(?:float|int|uint|bool_?)\d*\(([^()]*)\)", r"\1", text)
    return " ".join(text.split())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
