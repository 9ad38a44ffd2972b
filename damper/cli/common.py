"""Helpers shared by the subcommands: JSON output, all-or-nothing file writes, output paths
checked before any work.

Outputs and inputs: :func:`check_outputs` runs for every subcommand before its work
(``damper.cli.main``). The options that name outputs are the ones of :data:`OUTPUTS`
(a subcommand whose ``--out`` is a result folder sets ``out_folder=True`` in its
parser's defaults); every other option value that names an existing file is an input.
An output file that is one of the inputs, whatever the spelling (symlinks, ``./``, hard
links: compared by device and inode), is refused, as is an output that exists and is
not a regular file (``/dev/null``, a FIFO, a socket: writing through a temporary file
and a rename would replace it). A result folder (``run --out``, ``sweep --out``) that
holds one of the inputs is refused too: the command writes that folder's files as its
own; so is one that holds a file the scene names (``Scene.files``: its matrices, its UPD
model). Two outputs naming one path are refused. A figure folder (``--plot``) may hold
inputs: its files have fixed ``.png`` names, and while the command runs no input it read is ever replaced
(:func:`contact_core.fileio.guard_inputs`).
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np

from contact_core.fileio import (
    atomic_write,  # noqa: F401  (re-exported for subcommands)
    check_writable_target,
)

#: Option destinations that name outputs: dest -> (flag, "file" or "folder").
OUTPUTS = {"output": ("-o", "file"), "out": ("--out", "file"), "normal_curve": ("--normal-curve", "file"),
           "plot": ("--plot", "figures")}
#: Positional arguments that name input files (named as they are in messages, without --).
POSITIONAL = ("scene", "ssp")


def to_jsonable(obj):
    """Convert numpy scalars and arrays (recursively) to plain Python for JSON."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    return obj


def dumps(obj, indent: int | None = None) -> str:
    """JSON text of ``obj``; NaN and infinity are refused (never a silent bad number): a
    RuntimeError (exit 3) naming the first such key, not json's "out of range float"."""
    data = to_jsonable(obj)
    try:
        return json.dumps(data, indent=indent, allow_nan=False)
    except ValueError:
        where = _non_finite(data)
        if where is None:
            raise
        raise RuntimeError(f"the result's {where} is not a finite number (an overflow or a failed "
                           "solve): nothing written; inputs of more moderate size may help") from None


def _non_finite(data, path: str = "") -> str | None:
    """Path (``loop.T[3]``) of the first NaN or infinity in plain JSON data, or None."""
    if isinstance(data, float):
        return None if np.isfinite(data) else (path or "value")
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    for key, value in items:
        found = _non_finite(value, f"{path}.{key}" if isinstance(key, str) and path else
                            key if isinstance(key, str) else f"{path}[{key}]")
        if found is not None:
            return found
    return None


def print_json(obj) -> None:
    """Print one JSON object on stdout."""
    from .jsonout import STATE

    sys.stdout.write(dumps(obj) + "\n")
    STATE["printed"] = True


def print_warnings(out: dict, keys, as_json: bool) -> None:
    """The warning lines ``out[key]`` of a result (None or absent: no warning), each printed
    once: on stderr with ``--json`` (stdout holds the one JSON object, which has them too),
    else on stdout after the text output."""
    for key in keys:
        if out.get(key):
            print(out[key], file=sys.stderr if as_json else sys.stdout)


def print_json_error(message: str, exit_code: int) -> None:
    """With ``--json``, a failure's one JSON object on stdout (``error``, ``exit_code``), unless
    the command printed its own (a partial result with its error)."""
    from .jsonout import STATE

    if not STATE["printed"]:
        print_json({"error": message, "exit_code": exit_code})


def check_accuracy_option(tol) -> None:
    """``--accuracy`` unset or inside :data:`harmonic_balance.accuracy.ACCURACY_RANGE`
    (open interval)."""
    from harmonic_balance.accuracy import ACCURACY_RANGE

    lo, hi = ACCURACY_RANGE
    if tol is not None and not lo < tol < hi:
        raise ValueError(f"--accuracy must be a relative tolerance in ({lo:g}, {hi:g}) on the peak "
                         f"amplitude, got {tol:g}")


def upd_model_options(p) -> None:
    """``--config`` and ``--json`` of every ``damper upd`` action."""
    p.add_argument("--config", help="UPD model TOML (default: the bundled UPD-24)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def upd_response_options(p) -> None:
    """``--cf``, ``--f0`` and ``--damper`` of the ``damper upd`` actions that solve the
    forced response (``frf``, ``mistuning``)."""
    p.add_argument("--cf", type=float, help="centrifugal load [N] (default: config)")
    p.add_argument("--f0", type=float, help="EO force amplitude on the airfoil [N] (default: config)")
    p.add_argument("--damper", choices=("nonlinear", "free", "stuck"), default="nonlinear",
                   help="free: damper removed; stuck: contacts stuck (linear limits)")


def accuracy_lines(out) -> list[str]:
    """The truncation-error lines of a ``upd frf``, ``upd optimize`` or ``upd mistuning``
    result (frequencies in Hz)."""
    from harmonic_balance.frf_accuracy import summary_lines

    rec = out.get("truncation_error")
    if not rec:
        return []
    summary = {"truncation_error": rec, "accuracy": rec.get("accuracy"),
               "truncation_warning": out.get("truncation_warning")}
    return summary_lines(summary, hz=True)


def _writable_parent(path: Path, flag: str) -> None:
    """The nearest existing folder above ``path`` must be a folder this user can write."""
    probe = path.parent
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        raise ValueError(f"{flag} {path}: {probe} is a file, not a folder")
    if not _can_create_in(probe):
        raise ValueError(f"{flag} {path}: cannot write in {probe} (permission denied or a read-only file system)")


def _can_create_in(folder: Path) -> bool:
    """Whether a folder can be created in ``folder`` (made and removed at once): the
    permission bits alone say yes to root on /proc or a read-only mount, where the write
    would fail only after the work."""
    import tempfile

    if not os.access(folder, os.W_OK | os.X_OK):
        return False
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".damper-write-check-", dir=folder))
    except OSError:
        return False
    return True


def check_out_file(path, flag: str) -> None:
    """Refuse, before any work, an output file that cannot be written (a folder, no permission)."""
    if path is None:
        return
    if str(path).endswith(tuple(filter(None, (os.sep, os.altsep)))):   # Path() drops it: "x/" wrote a file x
        raise ValueError(f"{flag} {path}: a name ending in {str(path)[-1]} is a folder; give a file name")
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{flag} {path}: that is a folder; give a file name")
    _writable_parent(path, flag)


def check_out_dir(path, flag: str) -> None:
    """Refuse, before any work, an output folder that cannot be written (a file, no permission)."""
    if path is None:
        return
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{flag} {path}: a file of that name exists; give a folder")
    if path.is_dir():
        if not _can_create_in(path):
            raise ValueError(f"{flag} {path}: cannot write in this folder (permission denied or a read-only "
                             "file system)")
        return
    _writable_parent(path, flag)


def _inputs(args) -> list[tuple[str, Path]]:
    """(option, path) of every option value that names an existing file and is not an output."""
    found = []
    for dest, value in vars(args).items():
        if dest in OUTPUTS or dest in ("func", "command"):
            continue
        for v in value if isinstance(value, (list, tuple)) else [value]:
            if isinstance(v, (str, os.PathLike)) and str(v) and os.path.isfile(v):
                found.append((dest if dest in POSITIONAL else "--" + dest.replace("_", "-"), Path(v)))
    return found


def _same(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _inside(folder: Path, path: Path) -> bool:
    try:
        folder, path = folder.resolve(), path.resolve()
    except OSError:
        return False
    return folder in path.parents


def _distinct_outputs(args) -> None:
    """Two output options naming one path (``--out r.json --normal-curve r.json``, ``--out c.json
    --plot c.json``): the second write would replace or block the first, after work and
    with one output already written; refused before any work."""
    seen = {}
    for dest, (flag, _) in OUTPUTS.items():
        value = getattr(args, dest, None)
        if value is None or isinstance(value, bool) or not str(value):
            continue
        key = Path(value).resolve()
        if key in seen:
            raise ValueError(f"{flag} {value} and {seen[key]} name the same path: give each output its own name")
        seen[key] = f"{flag} {value}"


def check_folder_holds_no_input(out, flag: str, inputs) -> None:
    """Refuse a result folder ``out`` that holds one of ``inputs`` ((name, path) pairs; e.g. the
    files a scene names): the command writes that folder's files as its own."""
    for name, path in inputs:
        if _inside(Path(out), Path(path)):
            raise ValueError(f"{flag} {out} holds the input {name} {path}: the result folder is the "
                             "command's own; give another folder")


def check_outputs(args) -> None:
    """Refuse, before any work, an output that is one of the inputs or not a regular file, or two
    outputs that are one path (module docstring)."""
    _distinct_outputs(args)
    inputs = _inputs(args)
    for dest, (flag, kind) in OUTPUTS.items():
        value = getattr(args, dest, None)
        if value is None or isinstance(value, bool):
            continue
        out = Path(value)
        if dest == "out" and getattr(args, "out_folder", False):
            kind = "folder"
        if kind == "file":
            try:
                check_writable_target(out)
            except IsADirectoryError:
                continue            # check_out_file says it in the command's words
            except OSError as err:
                raise ValueError(f"{flag} {out}: {str(err).split(': ', 1)[-1]}") from None
            for name, path in inputs:
                if _same(out, path):
                    raise ValueError(f"{flag} {out} is the input {name} {path}: it would be overwritten; "
                                     "give another output name")
        elif kind == "folder":
            check_folder_holds_no_input(out, flag, inputs)
