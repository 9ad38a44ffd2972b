"""Helpers shared by the subcommands: JSON output, all-or-nothing file writes, output paths
checked before any work."""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np

from contact_core.fileio import atomic_write  # noqa: F401  (re-exported for subcommands)


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
    """JSON text of ``obj``; NaN and infinity are refused (never a silent bad number)."""
    return json.dumps(to_jsonable(obj), indent=indent, allow_nan=False)


def print_json(obj) -> None:
    """Print one JSON object on stdout."""
    sys.stdout.write(dumps(obj) + "\n")


def _writable_parent(path: Path, flag: str) -> None:
    """The nearest existing folder above ``path`` must be a folder this user can write."""
    probe = path.parent
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        raise ValueError(f"{flag} {path}: {probe} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise ValueError(f"{flag} {path}: cannot write in {probe} (permission denied)")


def check_out_file(path, flag: str) -> None:
    """Refuse, before any work, an output file that cannot be written (a folder, no permission)."""
    if path is None:
        return
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
        if not os.access(path, os.W_OK | os.X_OK):
            raise ValueError(f"{flag} {path}: cannot write in this folder (permission denied)")
        return
    _writable_parent(path, flag)
