"""Where a result came from: code version of the modules a stage runs, git revision, inputs.

The code version is a hash of the source files themselves (not of the git
revision), so an uncommitted edit changes it and a commit that touches other
files does not: cache keys stay valid exactly as long as the code they depend on.
"""
from __future__ import annotations

import functools
import hashlib
import importlib.util
import platform
import subprocess
import sys
import time
from pathlib import Path

#: The repository root (the folder holding the packages).
ROOT = Path(__file__).resolve().parents[1]


@functools.cache
def _module_files(name: str) -> tuple[Path, ...]:
    """Source files of a module, or of every module below a package (sorted)."""
    spec = importlib.util.find_spec(name)
    if spec is None or spec.origin is None:
        raise ValueError(f"code version: no module named {name!r}")
    origin = Path(spec.origin)
    if spec.submodule_search_locations:  # a package: all its Python and C sources
        base = origin.parent
        files = [p for p in base.rglob("*") if p.suffix in (".py", ".c", ".h") and p.is_file()
                 and "__pycache__" not in p.parts]
        return tuple(sorted(files))
    return (origin,)


@functools.cache
def code_version(modules: tuple[str, ...]) -> str:
    """SHA-256 (16 hex digits) of the sources of ``modules`` (module or package names)."""
    h = hashlib.sha256()
    for name in sorted(set(modules)):
        for path in _module_files(name):
            h.update(str(path.relative_to(path.parents[len(name.split("."))])).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


@functools.lru_cache(maxsize=1)
def git_revision() -> dict:
    """``{"commit": sha or None, "dirty": bool or None}`` of the repository holding the code."""
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                                text=True, timeout=10, check=True).stdout.strip()
        status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                                capture_output=True, text=True, timeout=10, check=True).stdout
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}
    return {"commit": commit, "dirty": bool(status.strip())}


def environment() -> dict:
    """Python, platform and the versions of the numerical packages."""
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for name in ("numpy", "scipy", "scikit-fem", "fmpy"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = None
    return out


def record(**inputs) -> dict:
    """A provenance record: time (UTC), git revision, environment and the given inputs."""
    return {"created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "git": git_revision(),
            "environment": environment(), **inputs}
