"""On-disk cache of condensed matrices (.npz), keyed by a content hash.

Location: the ``cache_dir`` argument, else the environment variable
``DAMPER_CACHE_DIR``, else ``.damper_cache`` in the working directory.
Files are written atomically, so an interrupted run never leaves a torn entry;
an unreadable entry is treated as a miss and rebuilt.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np

from .fileio import atomic_write

ENV_VAR = "DAMPER_CACHE_DIR"
DEFAULT_DIR = ".damper_cache"


def default_dir() -> Path:
    """The cache folder from ``DAMPER_CACHE_DIR`` or ``./.damper_cache``."""
    return Path(os.environ.get(ENV_VAR) or DEFAULT_DIR)


def make_key(*parts) -> str:
    """SHA-256 (first 24 hex digits) of the JSON text of ``parts``."""
    text = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


class DiskCache:
    """A folder of ``<key>.npz`` files holding arrays and a JSON ``meta`` entry."""

    def __init__(self, folder: str | os.PathLike | None = None):
        self.folder = Path(folder) if folder is not None else default_dir()

    def path(self, key: str) -> Path:
        """File of ``key``."""
        return self.folder / f"{key}.npz"

    def get(self, key: str) -> tuple[dict, dict] | None:
        """Arrays and meta stored under ``key``, or None on a miss."""
        path = self.path(key)
        if not path.is_file():
            return None
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files if k != "meta"}
                meta = json.loads(str(data["meta"]))
        except (OSError, ValueError, KeyError, zipfile.BadZipFile):
            return None
        return arrays, meta

    def put(self, key: str, arrays: dict, meta: dict) -> Path:
        """Store ``arrays`` (name -> ndarray) and ``meta`` (JSON-able) under ``key``."""
        buf = io.BytesIO()
        np.savez(buf, meta=np.array(json.dumps(meta, default=str)), **arrays)
        return atomic_write(self.path(key), buf.getvalue())
