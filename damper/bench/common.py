"""What every benchmark stage shares: rows, timing of a CLI call in a child process, stamps.

A benchmark row is ``{"case", "size", "error", "time_s", "memory_mb", "cached"}``
(plus optional keys such as ``default`` for the tool's default setting). Stages
call the ``damper`` CLI in a child process so that cold runs are cold (fresh
imports, empty caches) and peak memory is the child's own.
"""
from __future__ import annotations

import json
import os
import platform
import resource
import signal
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: Runs ``damper.cli.main`` on the child's argv and exits with its code.
_CLI = "import sys; from damper.cli import main; sys.exit(main(sys.argv[1:]))"


@dataclass
class Row:
    """One measured point of a stage: accuracy against cost."""

    case: str
    size: float
    error: float | None
    time_s: float
    memory_mb: float
    cached: bool = False
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        d = asdict(self)
        d.update(d.pop("extra"))
        return d


@dataclass
class ChildResult:
    """Outcome of one child process."""

    code: int | None          # exit code; None when it timed out
    stdout: str
    stderr: str
    time_s: float
    memory_mb: float

    def json(self) -> dict:
        """The last stdout line that parses as a JSON object (the CLI's --json output)."""
        text = self.stdout.strip()
        try:
            return json.loads(text)
        except ValueError:
            pass
        for line in reversed(text.splitlines()):
            try:
                return json.loads(line)
            except ValueError:
                continue
        raise ValueError(f"no JSON object in the output: {text[-300:]!r}")


def run_child(argv: list[str], timeout: float, env: dict | None = None, python_code: str = _CLI,
              cwd: str | Path | None = None, command: list[str] | None = None) -> ChildResult:
    """Run ``damper ARGV`` (or ``python -c python_code ARGV``, or any ``command``) in a child;
    wall time and peak RSS.

    The peak resident memory is read from ``ru_maxrss`` of a wrapper process
    that runs nothing else, so it is the child's own.
    """
    wrapper = ("import resource, subprocess, sys, json\n"
               "p = subprocess.run(sys.argv[1:])\n"
               "sys.stderr.write('\\n@@maxrss ' + str(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss))\n"
               "sys.exit(p.returncode)\n")
    full_env = dict(os.environ, OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS", "1"))
    full_env.update(env or {})
    inner = command if command is not None else [sys.executable, "-c", python_code, *map(str, argv)]
    cmd = [sys.executable, "-c", wrapper, *map(str, inner)]
    t0 = time.perf_counter()
    # own session: on a timeout the whole group (wrapper and command) is killed, no orphan left running
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=full_env, cwd=cwd,
                         start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        return ChildResult(None, out or "", "", time.perf_counter() - t0, float("nan"))
    wall = time.perf_counter() - t0
    stderr, _, tail = err.rpartition("\n@@maxrss ")
    try:
        mem = int(tail.strip()) / 1024.0  # kB -> MB (Linux)
    except ValueError:
        stderr, mem = err, float("nan")
    return ChildResult(p.returncode, out, stderr, wall, mem)


def self_peak_mb() -> float:
    """Peak resident memory of this process so far [MB]."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


#: Paths whose changes do not make a revision "dirty": the recorded documentation data
#: (a run that writes one data file must not mark the next run's revision as modified).
NOT_CODE = ("docs/data",)


def revision() -> str | None:
    """Short git revision of the code, with ``-dirty`` when tracked files outside
    :data:`NOT_CODE` differ from it; None outside a git checkout."""
    try:
        rev = subprocess.run(["git", "-C", str(ROOT), "describe", "--always"], capture_output=True,
                             text=True, timeout=10).stdout.strip() or None
        changed = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no", "--",
                                  ".", *(f":(exclude){p}" for p in NOT_CODE)], capture_output=True, text=True,
                                 timeout=10).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        return None
    return f"{rev}-dirty" if rev and changed else rev


def stamp() -> dict:
    """Machine, cores, library versions and code revision of a run."""
    from importlib import metadata

    versions = {}
    for pkg in ("numpy", "scipy", "scikit-fem", "fmpy", "casadi", "pypardiso", "scikit-sparse", "mkl"):
        try:
            versions[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            versions[pkg] = None
    rev = revision()
    from contact_core import linsolve

    mem_total = None
    try:
        import psutil
        mem_total = round(psutil.virtual_memory().total / 2**30, 1)
    except ImportError:
        pass
    return {"machine": platform.machine(), "processor": platform.processor() or platform.machine(),
            "system": platform.platform(), "python": platform.python_version(), "cores": os.cpu_count(),
            "memory_gb": mem_total, "load_average": list(os.getloadavg()), "versions": versions,
            "sparse_solvers": list(linsolve.available_backends()), "revision": rev,
            "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
