"""Helpers shared by the subcommands: JSON output and all-or-nothing file writes."""
from __future__ import annotations

import json
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
