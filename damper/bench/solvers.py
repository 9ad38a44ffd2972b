"""Sparse back ends on the contact condensation: cold time of the same case per back end.

The goal: the 41x41 sphere (normal + tangential condensation, real
bodies) with the pip-only fast solver within 1.5x of the system's CHOLMOD,
measured in the same run. Each back end runs ``damper tangential`` cold (no
cache) in its own child process with ``DAMPER_SOLVER`` set; the error column is
the largest relative difference of k_n, k_t and the curve's end against the
first back end (the same FE problem: round-off only).
"""
from __future__ import annotations

from contact_core import linsolve

from .common import Row, run_child

#: Time limit of one cold run [s] (SuperLU at 41x41 needs several minutes on 2 busy cores).
TIMEOUT_S = 1800.0


def sphere_argv(grid: int) -> list[str]:
    """Sphere R = 10 mm on a plane, steel, N = 200 N, mu = 0.5, real bodies, no cache."""
    return ["tangential", "--body", "sphere", "--radius", "0.01", "--force", "200", "--mu", "0.5",
            "--model", "real", "--grid", str(grid), "--no-cache", "--json"]


def _numbers(out: dict) -> dict:
    """The comparable scalars of a ``damper tangential --json`` result."""
    keys = ("k_n", "k_t", "approach")
    flat = {k: out[k] for k in keys if isinstance(out.get(k), (int, float))}
    for k in keys:
        if k not in flat and isinstance(out.get("normal"), dict) and k in out["normal"]:
            flat[k] = out["normal"][k]
    return flat


def run(grids=(21, 41), backends=None, timeout: float = TIMEOUT_S, log=print) -> list[Row]:
    """One cold row per grid and available back end (``backends`` default: all available)."""
    backends = backends or linsolve.available_backends()
    rows = []
    for grid in grids:
        ref = None
        for name in backends:
            r = run_child(sphere_argv(grid), timeout, env={"DAMPER_SOLVER": name})
            if r.code != 0:
                log(f"  solver {name} grid {grid}: failed (exit {r.code}): {r.stderr.strip()[-200:]}")
                continue
            nums = _numbers(r.json())
            if ref is None:
                ref = nums
            err = max((abs(nums[k] / ref[k] - 1.0) for k in nums if k in ref and ref[k]), default=None)
            rows.append(Row(case=f"sphere real {name}", size=grid * grid, error=err, time_s=r.time_s,
                            memory_mb=r.memory_mb, extra={"solver": name, "grid": grid}))
            log(f"  solver {name:8s} grid {grid:3d}: {r.time_s:7.1f} s cold, {r.memory_mb:6.0f} MB, "
                f"diff {err if err is None else f'{err:.1e}'}")
    return rows
