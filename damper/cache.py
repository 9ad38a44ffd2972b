"""The content-addressed cache that every stage uses.

An entry is one ``entry-<key>.damper-cache`` file in a folder (an ``.npz`` archive:
named arrays plus one JSON object, no pickle: a cache file never runs code). The key
is a hash of what the entry depends on: a stage's inputs and the code version of the
modules it runs (:func:`make_key`), so a changed input or changed code is a miss,
never a stale hit. The JSON object holds the key and the stage kind next to the
entry's own meta, and a read checks both: an entry copied or renamed over another
key is a miss, as is any entry that does not read back whole (empty, truncated,
foreign); the first such miss of a run prints one warning.

The store implements the small ``get(key) -> (arrays, meta) | None`` /
``put(key, arrays, meta)`` protocol that ``contact_core``'s condensation takes, so
the condensed bodies live in the same folder, under the same size limit, as every
other stage's results.

The folder is the cache's own: it holds a ``CACHEDIR.TAG`` (the Cache Directory
Tagging convention, so backup tools skip it), written when the store first uses a
new or empty folder. A folder that holds other files and no tag is not a cache: the
store refuses to write there, ``clear`` refuses to touch it, and eviction and
``clear`` only ever delete files named as entries (or the store's own temporary
files) in a tagged folder, so a user's file in the folder is never deleted.

Concurrency: each entry is written to a unique temporary file in the cache folder
and renamed into place (atomic on POSIX), so a reader sees the old entry, no entry,
or the whole new one; two runs writing the same key write the same content.
Eviction (least recently used first, above the size limit) holds an exclusive
``flock`` on ``.lock`` so two runs never evict at once; a file unlinked while another
process reads it stays readable to that reader. Files are created with the mode the
umask gives (``contact_core.fileio``), so a cache folder shared by a group works.

Writing: a folder the user cannot write (read-only, another user's) is detected
before any work (:meth:`Store.prepare`); the store then reads it and keeps new
results in memory for the run, and says so once. ``Store(memory=True)`` (``damper
run --no-cache``) never touches the disk.

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
import re
import stat
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from contact_core.cache import TAG_NAME, TAG_SIGNATURE
from contact_core.fileio import atomic_write, new_file_mode

ENV_DIR = "DAMPER_CACHE_DIR"
ENV_MAX_MB = "DAMPER_CACHE_MAX_MB"
DEFAULT_DIR = ".damper_cache"
#: Default size limit [MiB]. For scale: every stage of the default scene (three
#: contacts on 21x21 grids, curve, loop, two FMUs, four FRFs) takes 5.2 MiB in 16 entries.
DEFAULT_MAX_MB = 4096
#: Entry file names: ``entry-<key>.damper-cache`` (nothing a user names a file).
PREFIX, SUFFIX = "entry-", ".damper-cache"
KEY_CHARS = "0123456789abcdefghijklmnopqrstuvwxyz_-"
ENTRY_NAME = re.compile(r"^entry-[0-9a-z_-]+\.damper-cache$")
TEMP_NAME = re.compile(r"^\.entry-[0-9a-z_-]+\.damper-cache\..*\.tmp$")
#: The tag while another run writes it, and the eviction lock (a folder holding only
#: these, entries and their temporary files is being made a cache by another run).
TAG_TEMP = re.compile(r"^(CACHEDIR\.TAG|\.CACHEDIR\.TAG\..*\.tmp|\.lock)$")
TAG_TEXT = (f"{TAG_SIGNATURE}\n# This file is a cache directory tag created by damper (the friction-damper\n"
            "# toolkit): its entries can be recomputed. See https://bford.info/cachedir/\n")
#: Format of the JSON object inside an entry (key, stage, meta).
ENTRY_SCHEMA = "damper-cache-entry/1"


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
    from damper import limits

    return limits.cache_bytes(f"${ENV_MAX_MB}", mb)


class NotACacheError(ValueError):
    """A folder that holds other files and no ``CACHEDIR.TAG``: the store will not use it."""


def is_cache_folder(folder: Path) -> bool:
    """Whether ``folder`` holds the damper cache tag."""
    try:
        return (folder / TAG_NAME).read_text(errors="replace").startswith(TAG_SIGNATURE)
    except OSError:
        return False


def _open_entry(path: Path, blob: bytes | None):
    """The entry's bytes as a file object: ``blob`` (in memory) or the file at ``path``.

    The file is opened without blocking and must be a regular file: a FIFO or a device
    named like an entry would block the run or never end (OSError: a miss).
    """
    if blob is not None:
        return io.BytesIO(blob)
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(f"{path.name} is not a regular file")
    return os.fdopen(fd, "rb")


def _stderr_warning(text: str) -> None:
    print(f"damper: warning: {text}", file=sys.stderr, flush=True)


class Store:
    """A folder of content-addressed entries with a size limit.

    Parameters
    ----------
    folder : path, optional
        Cache folder (created, and tagged, on the first write).
    max_bytes : int, optional
        Size limit; the least recently used entries go first when a write exceeds it.
    memory : bool
        Keep entries in this object only (``--no-cache``): nothing read from or written
        to disk.
    warn : callable(str), optional
        Where the store's warnings go (default: one line on standard error).

    Attributes
    ----------
    hits, misses, writes : int
        Counters of this object (one process), for reports and tests.
    readonly : bool or None
        Whether new entries stay in memory because the folder cannot be written (set by
        :meth:`prepare` or by a failed write; None before either).
    """

    def __init__(self, folder: str | os.PathLike | None = None, max_bytes: int | None = None,
                 memory: bool = False, warn=None):
        self.folder = Path(folder) if folder is not None else default_folder()
        self.max_bytes = int(max_bytes) if max_bytes is not None else default_max_bytes()
        if self.max_bytes <= 0:
            raise ValueError(f"cache size limit must be > 0 bytes, got {self.max_bytes}")
        self.memory = bool(memory)
        self.readonly: bool | None = True if memory else None
        self.hits = self.misses = self.writes = 0
        self._mem: dict[str, bytes] = {}
        self._warned: set[str] = set()
        self._warn = warn

    def __getstate__(self):   # sent to sweep workers: not the in-memory entries or the callback
        return dict(self.__dict__, _mem={}, _warn=None, _warned=set())

    # -- warnings ----------------------------------------------------------------
    def warn_once(self, cause: str, text: str) -> None:
        """One warning per ``cause`` and store object."""
        if cause in self._warned:
            return
        self._warned.add(cause)
        (self._warn or _stderr_warning)(text)

    # -- the folder ----------------------------------------------------------------
    def prepare(self) -> Store:
        """Check the folder before any work: refuse a folder that is not a cache; detect
        one this user cannot write (new entries then stay in memory, said once)."""
        if self.memory:
            return self
        self._check_owned()
        probe = self.folder
        while not probe.exists() and probe != probe.parent:
            probe = probe.parent
        if probe.exists() and not probe.is_dir():
            raise ValueError(f"cache folder {self.folder}: {probe} is a file, not a folder")
        writable = os.access(probe, os.W_OK | os.X_OK)
        if writable and probe == self.folder and is_cache_folder(self.folder):
            writable = os.access(self.folder / TAG_NAME, os.R_OK)
        self.readonly = not writable
        if self.readonly:
            self.warn_once("readonly", f"cache folder {self.folder} cannot be written (read-only or no "
                           "permission): reading it, keeping new results in memory for this run only")
        return self

    def owned(self) -> bool:
        """Whether the folder is (or may become) this cache: missing, tagged, or holding only its files."""
        try:
            self._check_owned()
        except NotACacheError:
            return False
        return True

    def _check_owned(self) -> None:
        """NotACacheError if the folder exists, holds files of its own and no cache tag."""
        if not self.folder.is_dir() or is_cache_folder(self.folder):
            return
        try:
            names = os.listdir(self.folder)
        except OSError:
            return
        ours = (TAG_TEMP, ENTRY_NAME, TEMP_NAME)
        foreign = sorted(n for n in names if not any(p.match(n) for p in ours))
        if foreign and not is_cache_folder(self.folder):   # (another run may have tagged it meanwhile)
            shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
            raise NotACacheError(f"cache folder {self.folder} is not a damper cache (no {TAG_NAME}) and holds "
                                 f"other files ({shown}): give a new or empty folder (--cache-dir or "
                                 f"${ENV_DIR}); the cache never writes into or deletes from a folder of yours")

    def _ensure_tag(self) -> None:
        """Create the folder and its CACHEDIR.TAG (a new or empty folder becomes a cache)."""
        if is_cache_folder(self.folder):
            return
        self._check_owned()
        self.folder.mkdir(parents=True, exist_ok=True)
        # whole or absent: written aside, then linked into place (never over another run's tag)
        fd, tmp = tempfile.mkstemp(dir=self.folder, prefix=f".{TAG_NAME}.", suffix=".tmp")
        try:
            os.fchmod(fd, new_file_mode())
            with os.fdopen(fd, "w") as fh:
                fh.write(TAG_TEXT)
            with contextlib.suppress(FileExistsError):
                os.link(tmp, self.folder / TAG_NAME)
        finally:
            Path(tmp).unlink(missing_ok=True)

    # -- entries -------------------------------------------------------------------
    def path(self, key: str) -> Path:
        """File of ``key``."""
        if not key or not all(c in KEY_CHARS for c in key):
            raise ValueError(f"bad cache key {key!r}")
        return self.folder / f"{PREFIX}{key}{SUFFIX}"

    @staticmethod
    def key_of(path: Path) -> str:
        """The key of an entry file (inverse of :meth:`path`)."""
        return Path(path).name.removeprefix(PREFIX).removesuffix(SUFFIX)

    def contains(self, key: str) -> bool:
        """Whether an entry exists under ``key`` (not read; a torn file is impossible)."""
        return key in self._mem or (not self.memory and self.path(key).is_file())

    def get(self, key: str, stage: str | None = None) -> tuple[dict, dict] | None:
        """Arrays (name -> ndarray) and meta stored under ``key`` (by ``stage``), or None on a miss.

        An entry that does not read back whole, or that holds another key or stage, is a
        miss (the caller recomputes it); the first of a run is reported by one warning.
        """
        path = self.path(key)
        blob = self._mem.get(key)
        try:
            if blob is None and self.memory:
                self.misses += 1
                return None
            with _open_entry(path, blob) as source, np.load(source, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files if k != "meta"}
                head = json.loads(str(data["meta"]))
        except FileNotFoundError:
            self.misses += 1
            return None
        except Exception as err:  # noqa: BLE001 - any unreadable entry (EOFError, BadZipFile, ...) is a miss
            self.misses += 1
            self.warn_once("unreadable", f"cache entry {path.name} is unreadable ({type(err).__name__}: "
                           f"{str(err)[:80]}): computing it again (said once per run)")
            return None
        if not isinstance(head, dict) or head.get("schema") != ENTRY_SCHEMA or head.get("key") != key \
                or head.get("stage") != stage or not isinstance(head.get("meta"), dict):
            self.misses += 1
            found = head.get("stage") if isinstance(head, dict) else None
            self.warn_once("mismatch", f"cache entry {path.name} holds another result (stage {found!r}, "
                           f"key {head.get('key') if isinstance(head, dict) else None!r}), not {stage!r} "
                           f"under its own key: computing it again (said once per run)")
            return None
        if blob is None:
            with contextlib.suppress(OSError):
                os.utime(path)  # least-recently-used order for eviction
        self.hits += 1
        return arrays, head["meta"]

    def put(self, key: str, arrays: dict, meta: dict, stage: str | None = None, evict: bool = True) -> Path:
        """Store ``arrays`` (name -> ndarray) and ``meta`` (JSON-able) under ``key`` (of ``stage``).

        ``evict=False`` leaves the size limit to a later :meth:`evict`: a batch of many small
        entries (each eviction check lists and stats the whole folder).
        """
        if "meta" in arrays:
            raise ValueError("'meta' is reserved for the entry's JSON object")
        head = {"schema": ENTRY_SCHEMA, "key": key, "stage": stage, "meta": meta}
        buf = io.BytesIO()
        np.savez(buf, meta=np.array(json.dumps(head, default=str, allow_nan=False)), **arrays)
        path = self.path(key)
        if self.readonly is None:
            self.prepare()
        if not self.readonly:
            try:
                self._ensure_tag()
                atomic_write(path, buf.getvalue())
            except NotACacheError:
                raise
            except OSError as err:   # a shared folder whose entry another user owns, a full disk
                self.readonly = True
                self.warn_once("write", f"cannot write to cache folder {self.folder} ({err.strerror or err}): "
                               "keeping new results in memory for this run only")
            else:
                self.writes += 1
                if evict:
                    self._evict(keep=path)
                return path
        self._mem[key] = buf.getvalue()
        self.writes += 1
        return path

    def evict(self) -> None:
        """Drop least recently used entries until the folder fits the size limit."""
        if not self.memory and not self.readonly:
            self._evict(keep=None)

    def delete(self, key: str) -> bool:
        """Remove the entry of ``key``; whether there was one."""
        had = self._mem.pop(key, None) is not None
        if self.memory:
            return had
        try:
            self.path(key).unlink()
        except FileNotFoundError:
            return had
        return True

    def entries(self) -> list[tuple[Path, os.stat_result]]:
        """Every entry file with its stat, least recently used first (files named as entries only)."""
        out = []
        if self.memory or not self.folder.is_dir():
            return out
        for p in self.folder.glob(f"{PREFIX}*{SUFFIX}"):
            if ENTRY_NAME.match(p.name):
                with contextlib.suppress(FileNotFoundError):
                    out.append((p, p.stat()))
        out.sort(key=lambda e: e[1].st_mtime)
        return out

    def info(self) -> dict:
        """Folder, whether it is a cache, entry count, bytes used, limit, oldest and newest use (ISO UTC)."""
        ent = self.entries()
        size = sum(s.st_size for _, s in ent)
        iso = lambda t: time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(t))  # noqa: E731
        return {"folder": str(self.folder.resolve()), "is_cache": is_cache_folder(self.folder),
                "entries": len(ent), "bytes": size, "max_bytes": self.max_bytes,
                "oldest_use": iso(ent[0][1].st_mtime) if ent else None,
                "newest_use": iso(ent[-1][1].st_mtime) if ent else None}

    def clear(self) -> int:
        """Remove every entry and stale temporary file of a cache folder; the number of entries removed.

        Raises NotACacheError for a folder that holds other files and no cache tag (nothing
        is removed); files not named as entries stay, whatever the folder.
        """
        self._mem.clear()
        if self.folder.exists() and not self.folder.is_dir():
            raise NotACacheError(f"cache folder {self.folder} is a file, not a folder: nothing removed")
        if self.memory or not self.folder.is_dir():
            return 0
        if not is_cache_folder(self.folder):
            self._check_owned()              # refuses a folder of the user's
            if not os.listdir(self.folder):
                return 0                     # an empty folder: nothing to do, not tagged
            self._ensure_tag()               # entries of a run that is tagging it: ours
        n = 0
        with self._lock():
            for p, _ in self.entries():
                with contextlib.suppress(FileNotFoundError):
                    p.unlink()
                    n += 1
            for p in self.folder.iterdir():
                if TEMP_NAME.match(p.name):
                    with contextlib.suppress(FileNotFoundError):
                        p.unlink()
        return n

    @contextlib.contextmanager
    def _lock(self):
        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.folder / ".lock"
        try:
            fd = os.open(path, os.O_RDONLY | os.O_CREAT, 0o666)
        except PermissionError:   # another user's lock file we cannot create or read: lock the folder
            fd = os.open(self.folder, os.O_RDONLY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            yield
        finally:
            fcntl.flock(fd, fcntl.LOCK_UN)
            os.close(fd)

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
                with contextlib.suppress(FileNotFoundError, PermissionError):
                    p.unlink()
                    total -= s.st_size


def store_of(opts) -> Store:
    """The cache of a run's condensations: ``opts.store`` (a scene's), else the default one."""
    store = getattr(opts, "store", None)
    return Store().prepare() if store is None else store
