"""Where a batch of independent tasks runs: a Dask cluster, or this process.

``executor`` gives ``(submit, gather, close)``: a Dask local cluster (one single-threaded
worker process per core by default), an existing cluster at a scheduler address, or
plain calls in this process (``serial``, the reference tests compare against). Used by
the scene sweeps (:mod:`damper.sweep`) and the mistuning study (:mod:`damper.mistuning`).

The local cluster's workers keep their temporary files (``TMPDIR``) and Dask's scratch
space in one ``damper_workers_*`` folder that ``close`` removes: a worker stopped by
Ctrl-C in the middle of a task never runs its own cleanup.
"""
from __future__ import annotations

import logging
import os
import shutil
import signal
import tempfile

#: Seconds to wait for a scheduler given by address before giving up.
CONNECT_TIMEOUT = 10
#: Seconds beyond CONNECT_TIMEOUT for the scheduler's handshake: Dask bounds the TCP
#: connection but not its wait for the first reply, so a server that accepts and never
#: answers held the client forever (seen: over 300 s with ``timeout=5``).
HANDSHAKE_GRACE = 5


def _connect(scheduler: str):
    """A Dask client of the scheduler at ``scheduler``, made in a daemon thread whose wait is
    bounded by CONNECT_TIMEOUT + HANDSHAKE_GRACE (TimeoutError after: the thread is left to
    the process's end)."""
    import threading

    from dask.distributed import Client

    box = {}

    def connect():
        try:
            box["client"] = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except BaseException as err:  # noqa: BLE001 - handed to the caller's thread
            box["error"] = err

    thread = threading.Thread(target=connect, name="damper-dask-connect", daemon=True)
    thread.start()
    thread.join(CONNECT_TIMEOUT + HANDSHAKE_GRACE)
    if thread.is_alive():
        raise TimeoutError(f"no handshake within {CONNECT_TIMEOUT + HANDSHAKE_GRACE} s: something accepts "
                           "connections there but does not answer as a Dask scheduler")
    if "error" in box:
        raise box["error"]
    return box["client"]


def _ignore_sigint_plugin():
    """A Dask worker plugin that makes a local worker process ignore SIGINT (its setup runs
    in the worker's main thread, the only one that may set a signal handler)."""
    from distributed import WorkerPlugin

    class IgnoreSigint(WorkerPlugin):
        def setup(self, worker):
            signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreSigint()


def executor(scheduler, workers, serial, info: dict | None = None):
    """(submit, gather, close) for a Dask client, or plain calls for ``serial``.

    ``info``, when given, receives ``workers``: the number of processes that run tasks
    (1 for ``serial``; the cluster's workers when connected).

    Raises OSError (a clear message, exit 2) when the scheduler at ``scheduler`` cannot
    be reached within :data:`CONNECT_TIMEOUT` seconds, or does not answer as one within
    :data:`HANDSHAKE_GRACE` more.
    """
    info = {} if info is None else info
    if serial:
        info["workers"] = 1
        return (lambda f, *a: f(*a)), (lambda fs: fs), (lambda: None)
    import dask
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            client = _connect(scheduler)
        except Exception as err:  # noqa: BLE001 - any failure of the handshake is the address's
            # Besides OSError (refused, timed out) and ValueError (a malformed address), a
            # server that answers but is not a Dask scheduler makes Dask read its bytes as a
            # frame length: a MemoryError for exabytes (seen), or a decoding error.
            raise OSError(f"cannot reach the Dask scheduler at {scheduler!r} ({type(err).__name__}: "
                          f"{str(err)[:200]}); start it or give the right --scheduler address "
                          "(tcp://host:8786)") from None
        cluster = scratch = None
        info["workers"] = max(1, len(client.scheduler_info().get("workers", {})))
    else:
        n = workers or os.cpu_count() or 1
        scratch = tempfile.mkdtemp(prefix="damper_workers_")
        try:
            with dask.config.set({"temporary-directory": scratch}):   # the scheduler's scratch space too
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                       silence_logs=logging.CRITICAL, local_directory=scratch,
                                       env={"TMPDIR": scratch})
            client = Client(cluster)
            info["workers"] = n
            # A terminal's Ctrl-C reaches the whole process group: this process alone handles it
            # (one line, exit 130) and closes the cluster; each worker would print a traceback.
            client.register_plugin(_ignore_sigint_plugin(), name="damper-ignore-sigint")
        except BaseException:
            shutil.rmtree(scratch, ignore_errors=True)
            raise

    def close():
        # After Ctrl-C Dask's gather task ends with an exception nobody retrieves; asyncio
        # and distributed would log it with a traceback after our one-line message.
        for name in ("asyncio", "distributed"):
            logging.getLogger(name).setLevel(logging.CRITICAL)
        try:
            client.close()
            if cluster is not None:
                cluster.close()
        finally:
            if scratch is not None:
                shutil.rmtree(scratch, ignore_errors=True)

    return (lambda f, *a: client.submit(f, *a, pure=False)), client.gather, close
