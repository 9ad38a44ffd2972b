"""The content-addressed cache that every stage uses.

An entry is one ``<key>.npz`` file in a folder: named arrays plus a JSON ``meta``
object (no pickle: a cache file never runs code). The key is a hash of what the
entry depends on: a stage's inputs and the code version of the modules it runs
(:func:`make_key`), so a changed input or changed code is a miss, never a stale hit.

The store implements the small ``get(key) -> (arrays, meta) | None`` /
``put(key, arrays, meta)`` protocol that ``contact_core``'s condensation takes, so
the condensed bodies live in the same folder, under the same size limit, as every
other stage's results.

Concurrency: each entry is written to a unique temporary file in the cache folder
and renamed into place (atomic on POSIX), so a reader sees the old entry, no entry,
or the whole new one; two runs writing the same key write the same content.
Eviction (least recently used first, above the size limit) holds an exclusive
``flock`` on ``.lock`` so two runs never evict at once; a file unlinked while another
process reads it stays readable to that reader.

Location: the ``folder`` argument, else ``$DAMPER_CACHE_DIR``, else ``.damper_cache``.
Size limit: the ``max_bytes`` argument, else ``$DAMPER_CACHE_MAX_MB`` [MiB], else
:data:`DEFAULT_MAX_MB`.
"""
from __future__ import annotations

import contextlib
import fcntl
import hashlib
import io
import json
import os
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

ENV_DIR = "DAMPER_CACHE_DIR"
ENV_MAX_MB = "DAMPER_CACHE_MAX_MB"
DEFAULT_DIR = ".damper_cache"
#: Default size limit [MiB]. For scale: every stage of the default scene (three
#: contacts on 21x21 grids, curve, loop, two FMUs, four FRFs) takes 5.2 MiB in 16 entries.
DEFAULT_MAX_MB = 4096
SUFFIX = ".npz"


def make_key(*parts) -> str:
    """SHA-256 (first 24 hex digits) of the canonical JSON text of ``parts``."""
    text = json.dumps(parts, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def default_folder() -> Path:
    """``$DAMPER_CACHE_DIR`` or ``./.damper_cache``."""
    return Path(os.environ.get(ENV_DIR) or DEFAULT_DIR)


def default_max_bytes() -> int:
    """``$DAMPER_CACHE_MAX_MB`` (MiB) or :data:`DEFAULT_MAX_MB`, in bytes."""
    text = os.environ.get(ENV_MAX_MB)
    try:
        mb = float(text) if text else DEFAULT_MAX_MB
    except ValueError:
        raise ValueError(f"${ENV_MAX_MB} must be a number of MiB, got {text!r}") from None
    if not mb > 0:
        raise ValueError(f"${ENV_MAX_MB} must be > 0, got {text!r}")
    return int(mb * 2**20)


class Store:
    """A folder of content-addressed entries with a size limit.

    Parameters
    ----------
    folder : path, optional
        Cache folder (created on the first write).
    max_bytes : int, optional
        Size limit; the least recently used entries go first when a write exceeds it.

    Attributes
    ----------
    hits, misses, writes : int
        Counters of this object (one process), for reports and tests.
    """

    def __init__(self, folder: str | os.PathLike | None = None, max_bytes: int | None = None):
        self.folder = Path(folder) if folder is not None else default_folder()
        self.max_bytes = int(max_bytes) if max_bytes is not None else default_max_bytes()
        if self.max_bytes <= 0:
            raise ValueError(f"cache size limit must be > 0 bytes, got {self.max_bytes}")
        self.hits = self.misses = self.writes = 0

    def path(self, key: str) -> Path:
        """File of ``key``."""
        if not key or not all(c in "0123456789abcdefghijklmnopqrstuvwxyz_-" for c in key):
            raise ValueError(f"bad cache key {key!r}")
        return self.folder / f"{key}{SUFFIX}"

    def contains(self, key: str) -> bool:
        """Whether an entry exists under ``key`` (not read; a torn file is impossible)."""
        return self.path(key).is_file()

    def get(self, key: str) -> tuple[dict, dict] | None:
        """Arrays (name -> ndarray) and meta stored under ``key``, or None on a miss.

        An unreadable entry (disk trouble, a foreign file) counts as a miss.
        """
        path = self.path(key)
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files if k != "meta"}
                meta = json.loads(str(data["meta"]))
        except (OSError, ValueError, KeyError, zipfile.BadZipFile):
            self.misses += 1
            return None
        with contextlib.suppress(OSError):
            os.utime(path)  # least-recently-used order for eviction
        self.hits += 1
        return arrays, meta

    def put(self, key: str, arrays: dict, meta: dict) -> Path:
        """Store ``arrays`` (name -> ndarray) and ``meta`` (JSON-able) under ``key``."""
        if "meta" in arrays:
            raise ValueError("'meta' is reserved for the entry's JSON object")
        buf = io.BytesIO()
        np.savez(buf, meta=np.array(json.dumps(meta, default=str, allow_nan=False)), **arrays)
        data = buf.getvalue()
        path = self.path(key)
        self.folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=self.folder, prefix=f".{key}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        self.writes += 1
        self._evict(keep=path)
        return path

    def delete(self, key: str) -> bool:
        """Remove the entry of ``key``; whether there was one."""
        try:
            self.path(key).unlink()
        except FileNotFoundError:
            return False
        return True

    def entries(self) -> list[tuple[Path, os.stat_result]]:
        """Every entry file with its stat, least recently used first."""
        out = []
        if not self.folder.is_dir():
            return out
        for p in self.folder.glob(f"*{SUFFIX}"):
            with contextlib.suppress(FileNotFoundError):
                out.append((p, p.stat()))
        out.sort(key=lambda e: e[1].st_mtime)
        return out

    def info(self) -> dict:
        """Folder, entry count, bytes used, limit, oldest and newest use (ISO UTC)."""
        ent = self.entries()
        size = sum(s.st_size for _, s in ent)
        iso = lambda t: time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(t))  # noqa: E731
        return {"folder": str(self.folder.resolve()), "entries": len(ent), "bytes": size,
                "max_bytes": self.max_bytes,
                "oldest_use": iso(ent[0][1].st_mtime) if ent else None,
                "newest_use": iso(ent[-1][1].st_mtime) if ent else None}

    def clear(self) -> int:
        """Remove every entry and stale temporary file; the number of entries removed."""
        n = 0
        with self._lock():
            for p, _ in self.entries():
                with contextlib.suppress(FileNotFoundError):
                    p.unlink()
                    n += 1
            for p in self.folder.glob(".*.tmp") if self.folder.is_dir() else ():
                with contextlib.suppress(FileNotFoundError):
                    p.unlink()
        return n

    @contextlib.contextmanager
    def _lock(self):
        self.folder.mkdir(parents=True, exist_ok=True)
        with open(self.folder / ".lock", "a") as fh:
            fcntl.flock(fh, fcntl.LOCK_EX)
            try:
                yield
            finally:
                fcntl.flock(fh, fcntl.LOCK_UN)

    def _evict(self, keep: Path) -> None:
        """Drop least recently used entries until the folder fits the limit (never ``keep``)."""
        ent = self.entries()
        total = sum(s.st_size for _, s in ent)
        if total <= self.max_bytes:
            return
        with self._lock():
            ent = self.entries()
            total = sum(s.st_size for _, s in ent)
            for p, s in ent:
                if total <= self.max_bytes:
                    break
                if p == keep:
                    continue
                with contextlib.suppress(FileNotFoundError):
                    p.unlink()
                    total -= s.st_size
