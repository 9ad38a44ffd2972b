"""Progress of a run: a live bar on a terminal, plain lines otherwise.

The bar counts the plan's stages and shows the running stage with its elapsed time
(refreshed by a background thread, so a long FE condensation or continuation still
shows that it is alive). Without a terminal (CI, a pipe, ``--json``) each stage is one
line when it starts and one when it ends. Inside a stage the library may report its own
steps (:meth:`step`, the ``progress(done, total, label)`` callback of ``contact_core``'s
condensation and tangential march): on a terminal the bar shows the step count and label,
otherwise one line per quarter of the steps. Summary lines go through :meth:`echo`, which
clears the bar first so the two never mix.
"""
from __future__ import annotations

import sys
import threading
import time

BAR = 24
REFRESH_S = 0.2
#: Plain (non-terminal) step lines: one each time another 1/PLAIN_PARTS of a stage's steps is done.
PLAIN_PARTS = 4


class Progress:
    """Stage progress on ``stream`` (a live bar when ``live``; default: whether it is a terminal);
    result lines go to ``emit`` (default: print on ``out``, standard output)."""

    def __init__(self, total: int, stream=None, live: bool | None = None, out=None, emit=None):
        self.total, self.done = total, 0
        self.stream = stream or sys.stderr
        self.out = out or sys.stdout
        self.emit = emit or (lambda text: print(text, file=self.out, flush=True))
        self.live = self.stream.isatty() if live is None else live
        self.current, self.t0 = None, 0.0
        self.sub = None                      # (done, total, label) of the running stage's steps
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None

    def start(self, name: str, action: str) -> None:
        with self._lock:
            self.current, self.action, self.t0 = name, action, time.perf_counter()
            self.sub = None
        if self.live:
            if self._thread is None:
                self._thread = threading.Thread(target=self._loop, daemon=True)
                self._thread.start()
            self._draw()
        else:
            print(f"[{self.done + 1}/{self.total}] {name}: {action} ...", file=self.stream, flush=True)

    def finish(self, name: str, seconds: float) -> None:
        with self._lock:
            self.done += 1
            self.current, self.sub = None, None
        if self.live:
            self._draw()
        else:
            print(f"[{self.done}/{self.total}] {name}: done in {seconds:.2f} s", file=self.stream, flush=True)

    def step(self, done: int, total: int, label: str = "") -> None:
        """A step inside the running stage (the libraries' ``progress`` callback)."""
        with self._lock:
            before = self.sub[0] if self.sub and self.sub[1] == total else 0
            self.sub = (done, total, label)
        if self.live:
            self._draw()
        elif PLAIN_PARTS * done // max(total, 1) > PLAIN_PARTS * before // max(total, 1):
            print(f"    {self.current or ''}: {done}/{total} {label}", file=self.stream, flush=True)

    __call__ = step

    def note(self, text: str) -> None:
        """A line from inside the running stage (a cost estimate, a step's summary) on ``stream``,
        as the commands print theirs to standard error (above the bar on a terminal)."""
        with self._lock:
            if self.live:
                self.stream.write("\r\033[K")
            print(text, file=self.stream, flush=True)
        if self.live and self.current:
            self._draw()

    def echo(self, text: str) -> None:
        """Print a result line (above the bar on a terminal)."""
        with self._lock:
            if self.live:
                self.stream.write("\r\033[K")
                self.stream.flush()
            self.emit(text)
        if self.live and self.current:
            self._draw()

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        if self.live:
            self.stream.write("\r\033[K")
            self.stream.flush()

    def _draw(self) -> None:
        with self._lock:
            filled = BAR * self.done // max(self.total, 1)
            text = f"[{'#' * filled}{'.' * (BAR - filled)}] {self.done}/{self.total}"
            if self.current:
                text += f"  {self.current} ({self.action}) {time.perf_counter() - self.t0:5.1f} s"
                if self.sub:
                    text += f"  {self.sub[0]}/{self.sub[1]} {self.sub[2]}"
            self.stream.write("\r\033[K" + text)
            self.stream.flush()

    def _loop(self) -> None:
        while not self._stop.wait(REFRESH_S):
            if self.current:
                self._draw()
