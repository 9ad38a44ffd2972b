"""File helpers shared by every stage that reads inputs or writes results.

Reading: every input file a user names is read through :func:`read_bounded` (or one of
its wrappers): it must be a regular file (a device, FIFO or socket is refused, never
opened blocking), no larger than a cap stated below, and at most cap + 1 bytes are
read, so ``/dev/zero`` or a file that grows while read is caught without filling the
memory. Archives (``.npz``) and Matrix Market files have their declared sizes checked
before any array is made (:func:`check_zip_members`, :func:`check_matrix_market`).

Writing: :func:`atomic_write` writes through a temporary file and a rename. It never
renames over something that is not a regular file (``/dev/null``, a FIFO, a socket:
refused, :class:`NotRegularFileError`) and never over a file this process has read as
an input while :func:`guard_inputs` is on (the ``damper`` command turns it on; every
bounded read then protects its file), whatever the spelling of the path (symlinks,
hard links: files are compared by device and inode).
"""
from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
import threading
import zipfile
from pathlib import Path

#: Bytes of a text input (curve and normal-curve JSON, scene and configuration TOML,
#: element tables): a virgin curve of 20000 points is ~1 MB of JSON and a scene a few
#: kB; parsing 16 MiB of JSON numbers already makes ~80 MB of Python objects.
MAX_TEXT_FILE_BYTES = 16 * 2**20
#: Bytes of array data in an input file (.npz members uncompressed, a Matrix Market
#: file, and the arrays its header declares): three dense matrices of 9500 DOFs take
#: 2 GiB, far above a reduced blade or damper model, and the harmonic balance holds
#: several matrices of that size again.
MAX_ARRAY_FILE_BYTES = 2 * 2**30
#: Members of an input archive (.npz, .ssp): a model holds a few arrays and a ring SSP
#: a few FMUs; tens of thousands of members is a forged archive.
MAX_ARCHIVE_MEMBERS = 4096
#: Bytes of a co-simulation archive (.ssp) unpacked: the UPD-24 ring's (``damper system``,
#: 4 members) unpacks to 0.2 MB; 1 GiB is a forged archive (a zip bomb).
MAX_SSP_BYTES = 2**30

_UMASK_LOCK = threading.Lock()


def umask() -> int:
    """The process's file-creation mask (read without changing it where Linux allows)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    with _UMASK_LOCK:  # elsewhere: set and restore (the only portable way to read it)
        mask = os.umask(0o022)
        os.umask(mask)
    return mask


def new_file_mode() -> int:
    """Mode of a new regular file as ``open`` would create it: 0666 less the umask."""
    return 0o666 & ~umask()


class NotRegularFileError(OSError):
    """A path that is a device, FIFO or socket where a regular file is read or written."""


class InputOverwriteError(OSError):
    """An output path that is a file this process read as an input."""


#: (device, inode) -> path of the inputs read while :func:`guard_inputs` is on (None: off).
_PROTECTED: dict[tuple[int, int], str] | None = None
_PROTECTED_LOCK = threading.Lock()


@contextlib.contextmanager
def guard_inputs():
    """Within this block, files read through this module are never replaced by :func:`atomic_write`.

    Off by default: a library user may read a file, edit it and write it back; a
    command line whose output names one of its inputs is a mistake.
    """
    global _PROTECTED
    old = _PROTECTED
    _PROTECTED = {}
    try:
        yield
    finally:
        _PROTECTED = old


def _remember(st: os.stat_result, path) -> None:
    with _PROTECTED_LOCK:
        if _PROTECTED is not None:
            _PROTECTED.setdefault((st.st_dev, st.st_ino), str(path))


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def _size_text(n: float) -> str:
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n} bytes"  # pragma: no cover


def protect(path: str | os.PathLike) -> None:
    """Remember ``path`` (by device and inode) as an input: :func:`atomic_write` will not replace it
    (while :func:`guard_inputs` is on)."""
    try:
        st = os.stat(path)
    except OSError:
        return
    _remember(st, path)


def check_writable_target(path: str | os.PathLike) -> None:
    """Refuse a write target that is not a regular file, or that is an input of this process.

    Raises NotRegularFileError (a device, FIFO, socket: a rename would replace it with a
    regular file) or InputOverwriteError; a missing path or a regular file passes.
    """
    try:
        st = os.stat(path)
    except OSError:
        return
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(f"cannot write {path}: it is a folder; give a file name")
    if not stat.S_ISREG(st.st_mode):
        raise NotRegularFileError(f"cannot write {path}: it is {_kind(st.st_mode)}, not a regular file; "
                                  "give the name of a file to write")
    source = (_PROTECTED or {}).get((st.st_dev, st.st_ino))
    if source is not None:
        raise InputOverwriteError(f"cannot write {path}: it is the input file {source} of this command; "
                                  "give another output name")


def _checked_stat(fd: int, path, cap: int, what: str) -> os.stat_result:
    """Stat of the open ``fd``: a regular file of at most ``cap`` bytes, else the error naming ``path``."""
    st = os.fstat(fd)
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(errno.EISDIR, "is a folder, not a file", str(path))
    if not stat.S_ISREG(st.st_mode):
        raise NotRegularFileError(f"{what} {path} is {_kind(st.st_mode)}, not a regular file: give a file")
    if st.st_size > cap:
        raise ValueError(f"{what} {path} is {_size_text(st.st_size)}, above the limit of {_size_text(cap)}")
    return st


def read_bounded(path: str | os.PathLike, cap: int, what: str = "input file", protect: bool = True) -> bytes:
    """The bytes of the regular file ``path``, at most ``cap`` of them.

    The file's size is checked before reading (stat of the open file), then at most
    ``cap + 1`` bytes are read, so a file that grows meanwhile is caught too. A device,
    FIFO or socket is refused without blocking (opened with O_NONBLOCK). With
    ``protect`` the file is then protected from being overwritten by this process's
    outputs (:func:`protect`; not for a command's own earlier output that it rewrites).

    Raises
    ------
    OSError
        The file cannot be opened (missing, no permission), is a folder
        (IsADirectoryError) or not a regular file (NotRegularFileError).
    ValueError
        The file is larger than ``cap`` (the message names the file, its size and the cap).
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = _checked_stat(fd, path, cap, what)
        chunks, total = [], 0
        while total <= cap:
            chunk = os.read(fd, min(cap + 1 - total, 1 << 20))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
        if total > cap:
            raise ValueError(f"{what} {path} grew above the limit of {_size_text(cap)} while read")
    finally:
        os.close(fd)
    if protect:
        _remember(st, path)
    return b"".join(chunks)


def read_text_bounded(path: str | os.PathLike, cap: int = MAX_TEXT_FILE_BYTES, what: str = "input file") -> str:
    """The UTF-8 text of ``path`` through :func:`read_bounded` (UnicodeDecodeError if not text)."""
    return read_bounded(path, cap, what).decode("utf-8")


def check_regular_input(path: str | os.PathLike, cap: int, what: str = "input file") -> os.stat_result:
    """Stat an input that a library reads itself (``np.load``, ``mmread``): a regular file of at most ``cap``.

    Protects it (:func:`protect`) and returns its stat; errors as :func:`read_bounded`.
    """
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = _checked_stat(fd, path, cap, what)
    finally:
        os.close(fd)
    _remember(st, path)
    return st


def check_zip_members(zf: zipfile.ZipFile, cap: int, what: str, max_members: int = MAX_ARCHIVE_MEMBERS) -> int:
    """Refuse an archive of more than ``max_members`` members or more than ``cap`` bytes unpacked.

    The sizes are those the archive declares (``ZipInfo.file_size``); ``zipfile`` never
    inflates a member beyond its declared size (it raises BadZipFile), so the bound holds
    for what is then read. Returns the declared total [bytes].
    """
    infos = zf.infolist()
    if len(infos) > max_members:
        raise ValueError(f"{what}: {len(infos)} members, above the limit of {max_members}")
    total = sum(i.file_size for i in infos)
    if total > cap:
        raise ValueError(f"{what}: its members unpack to {_size_text(total)}, above the limit of {_size_text(cap)}")
    return total


def open_npz(path: str | os.PathLike, what: str = "input file", cap: int = MAX_ARRAY_FILE_BYTES):
    """``np.load`` of an .npz archive of arrays after its sizes are checked (never pickles).

    Returns the open ``NpzFile`` (use it in a ``with``). Raises ValueError for a file that
    is not an .npz archive of arrays (garbage, a pickle, a truncated zip) or whose
    members unpack to more than ``cap`` bytes, OSError as :func:`check_regular_input`.
    """
    import numpy as np

    check_regular_input(path, cap, what)
    try:
        with zipfile.ZipFile(path) as zf:
            check_zip_members(zf, cap, f"{what} {path}")
    except (zipfile.BadZipFile, EOFError):
        raise ValueError(f"{what} {path} is not an .npz archive of arrays (numpy.savez writes one)") from None
    try:
        return np.load(path, allow_pickle=False)
    except ValueError:   # numpy's own text would offer to load pickles: never
        raise ValueError(f"{what} {path} is not an .npz archive of arrays (numpy.savez writes one)") from None


def check_matrix_market(path: str | os.PathLike, dense: bool, what: str = "matrix file",
                        cap: int = MAX_ARRAY_FILE_BYTES) -> tuple[int, int, int]:
    """The (rows, cols, entries) a Matrix Market file declares, refused above ``cap`` bytes.

    Only the header is read. ``dense``: the caller makes a dense array (rows x cols
    doubles); otherwise a sparse one (16 bytes an entry, 8 a row).
    """
    check_regular_input(path, cap, what)
    with open(path, "rb") as fh:
        first = fh.readline(1024)
        if not first.lower().startswith(b"%%matrixmarket"):
            raise ValueError(f"{what} {path}: not a Matrix Market file (no %%MatrixMarket header)")
        fmt = first.split()[2].lower() if len(first.split()) > 2 else b""
        line = b"%"
        while line.startswith(b"%") or not line.strip():
            line = fh.readline(1024)
            if not line:
                raise ValueError(f"{what} {path}: no size line after the Matrix Market header")
    try:
        sizes = [int(v) for v in line.split()]
    except ValueError:
        raise ValueError(f"{what} {path}: bad size line {line[:80]!r}") from None
    if len(sizes) not in (2, 3) or min(sizes) < 0:
        raise ValueError(f"{what} {path}: bad size line {line[:80]!r}")
    rows, cols = sizes[0], sizes[1]
    nnz = sizes[2] if len(sizes) == 3 else rows * cols
    need = 8 * rows * cols if dense or fmt == b"array" else 16 * nnz + 8 * (rows + 1)
    if need > cap:
        raise ValueError(f"{what} {path}: its header declares a {rows} x {cols} matrix ({nnz} entries), "
                         f"{_size_text(need)} in memory, above the limit of {_size_text(cap)}")
    return rows, cols, nnz


def atomic_write(path: str | os.PathLike, data: str | bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename.

    A crash or an error never leaves a half-written file at ``path``. The file gets the
    mode a plain ``open`` would give it (0666 less the umask), not the temporary file's
    0600, so colleagues sharing a folder can read it. Errors name ``path``, never the
    temporary file. A ``path`` that is not a regular file (``/dev/null``, a FIFO) or
    that is an input of this process is refused (:func:`check_writable_target`): the
    rename would replace it. A symbolic link is written through: its target is replaced.
    """
    path = Path(path)
    check_writable_target(path)
    if path.is_symlink():   # write through the link, as open() does (the rename would replace the link)
        path = Path(os.path.realpath(path))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise NotADirectoryError(f"cannot write {path}: a file stands where its folder should be") from None
    except OSError as err:
        raise type(err)(f"cannot write {path}: {err.strerror or err}") from None
    mode = "wb" if isinstance(data, bytes) else "w"
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as err:
        raise type(err)(f"cannot write {path}: {err.strerror or err}") from None
    try:
        os.fchmod(fd, new_file_mode())
        with os.fdopen(fd, mode) as fh:
            fh.write(data)
        os.replace(tmp, path)
    except OSError as err:
        Path(tmp).unlink(missing_ok=True)
        raise type(err)(f"cannot write {path}: {err.strerror or err}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def save_png(fig, path: str | os.PathLike, dpi: int = 120) -> Path:
    """Write matplotlib figure ``fig`` as a PNG at ``path`` through :func:`atomic_write` (a
    failure leaves no half-written image); the one figure saver of every package's plots.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        Drawn; not closed here (the caller may save it twice or close it).
    path : path
        The image; its folder is created.
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    Path
        ``path``.
    """
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return atomic_write(path, buf.getvalue())
