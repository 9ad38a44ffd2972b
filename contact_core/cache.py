"""The condensation cache: its protocol and the on-disk default (.npz per key).

Any object with the ``get`` / ``put`` methods of ``CondensationCache`` can be
passed as ``cache=`` to ``condense.condense``, ``byo.condense_bodies`` and what
calls them (``api.run_normal``, ``tangential_run.run``): the application layer
passes its content-addressed store. Keys are built by the library
(``make_key``: a hash of everything that shapes the result, the code version
included), so a store only maps opaque keys to arrays and meta.

``DiskCache`` is the default implementation. Location: the ``cache_dir``
argument, else the environment variable ``DAMPER_CACHE_DIR``, else
``.damper_cache`` in the working directory. Files are written atomically, so an
interrupted run never leaves a torn entry; an unreadable entry is treated as a
miss and rebuilt.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import zipfile
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from .fileio import atomic_write

ENV_VAR = "DAMPER_CACHE_DIR"
DEFAULT_DIR = ".damper_cache"
#: The Cache Directory Tagging file (https://bford.info/cachedir/). A folder this cache
#: starts is tagged, so backup tools skip it and the damper application's store, whose
#: default folder is the same, takes it for a cache rather than a user's folder.
TAG_NAME = "CACHEDIR.TAG"
TAG_SIGNATURE = "Signature: 8a477f597d28d172789f06886806bc55"


@runtime_checkable
class CondensationCache(Protocol):
    """What the condensation needs from a cache (keys are opaque strings).

    ``get(key)`` returns ``(arrays, meta)`` stored under ``key`` (arrays: name ->
    ndarray, meta: a JSON-able dict), or None on a miss (an unreadable entry is
    a miss); ``put(key, arrays, meta)`` stores them atomically (a reader never
    sees a torn entry). An optional ``path(key)`` says where the entry lives,
    for the run's provenance.
    """

    def get(self, key: str) -> tuple[dict, dict] | None: ...

    def put(self, key: str, arrays: dict, meta: dict) -> object: ...


def resolve(cache) -> CondensationCache | None:
    """The store meant by a ``cache=`` argument.

    None: a DiskCache in the default folder; False: no cache; a str or path:
    a DiskCache there; any object with ``get`` and ``put``: that object.
    """
    if cache is False:
        return None
    if cache is None or isinstance(cache, (str, os.PathLike)):
        return DiskCache(cache)
    if isinstance(cache, CondensationCache):
        return cache
    raise TypeError(f"cache must be None, False, a folder or an object with get/put, got {cache!r}")


def entry_path(store, key: str) -> str | None:
    """Where ``store`` keeps ``key`` (None if it does not say)."""
    path = getattr(store, "path", None)
    return str(path(key)) if callable(path) else None


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
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
            return None
        return arrays, meta

    def put(self, key: str, arrays: dict, meta: dict) -> Path:
        """Store ``arrays`` (name -> ndarray) and ``meta`` (JSON-able) under ``key``."""
        self._tag_new_folder()
        buf = io.BytesIO()
        np.savez(buf, meta=np.array(json.dumps(meta, default=str)), **arrays)
        return atomic_write(self.path(key), buf.getvalue())

    def _tag_new_folder(self) -> None:
        """Create the folder with its TAG_NAME when it is new or empty (a folder already
        holding files is left as it is: it may be the user's)."""
        tag = self.folder / TAG_NAME
        if tag.exists() or (self.folder.is_dir() and any(self.folder.iterdir())):
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        atomic_write(tag, (f"{TAG_SIGNATURE}\n# This file is a cache directory tag created by "
                           "contact_core: its entries can be recomputed.\n").encode())
