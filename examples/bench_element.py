"""Benchmark: cost of the Iwan element's time-series entry point (iwan_series).
============================================================================

For each slider count, one 10,000-sample history (two incommensurate sines,
partial slip: about half the sliders slip in every cycle) is run through

* the C driver ``bench_iwan`` (``fmu_src/core/bench_iwan.c``, built by CMake):
  ``iwan_series`` called from C, best of ``--repeats`` runs;
* the Python array API ``IwanElement.series`` (one ctypes call plus numpy
  allocation and checks), best of ``--repeats`` runs.

Goals: at most 2 ns per slider update; the Python entry point within
2x of the C driver. The error column checks the numbers: relative difference of
the last F + W between the two paths (same C code: round-off only) -- and the
loop energy of a harmonic cycle against Masing's integral 8 int g - 4 a g(a) of
the model's own virgin curve (an independent formula).

Run: ``.venv/bin/python examples/bench_element.py`` (a few seconds); a smoke
version with tiny sizes runs in the tests.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from fmu_src.element import IwanElement

ROOT = Path(__file__).resolve().parents[1]
#: Where `make` (build/c) or a helper's own build put the C driver.
DRIVER_DIRS = ("build/c", "build/element", "build/bench_element")
GOAL_NS_PER_SLIDER = 2.0
GOAL_PY_OVER_C = 2.0


def find_or_build_driver() -> Path:
    """Path of an up-to-date bench_iwan executable (incremental CMake build)."""
    cmake = shutil.which("cmake")
    if cmake is None:
        raise RuntimeError("cmake not found: cannot build fmu_src/core/bench_iwan.c")
    build = next((ROOT / d for d in DRIVER_DIRS if (ROOT / d / "CMakeCache.txt").exists()),
                 ROOT / "build" / "bench_element")
    if not (build / "CMakeCache.txt").exists():
        subprocess.run([cmake, "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release"],
                       check=True, capture_output=True)
    subprocess.run([cmake, "--build", str(build), "--target", "bench_iwan"], check=True,
                   capture_output=True)
    return build / "fmu_src" / "core" / "bench_iwan"


def sliders(ns: int):
    """The C driver's model: k_j = 1e6/ns N/m, slip radii 1e-7 .. 2e-6 m, k_res = 1e5 N/m."""
    k = np.full(ns, 1e6 / ns)
    fs = k * (1e-7 + 1.9e-6 * np.arange(ns) / max(ns - 1, 1))
    return IwanElement.from_sliders(k, fs, k_res=1e5, N_ref=1.0)


def history(n: int) -> np.ndarray:
    """Same history as bench_iwan.c: 10 periods of 2e-6 (0.8 sin t + 0.3 sin 3.7 t) m."""
    t = 20.0 * np.pi * np.arange(n) / n
    return 2e-6 * (0.8 * np.sin(t) + 0.3 * np.sin(3.7 * t))


def time_python(el, u, repeats: int):
    best, res = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = el.series(u)
        best = min(best, time.perf_counter() - t0)
    return best, res.F[-1] + res.W[-1]


def masing_error(el) -> float:
    """Relative error of the periodic loop energy vs 8 int_0^a g - 4 a g(a)."""
    a = 1.3e-6
    grid = np.union1d(np.linspace(0.0, a, 5), el.slip_radii()[el.slip_radii() < a])
    g = el.virgin(grid)                   # piecewise linear between these points: exact trapezoid
    W_masing = 8.0 * np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(grid)) - 4.0 * a * g[-1]
    W = el.periodic(a * np.cos(2 * np.pi * np.arange(256) / 256)).W_cycle
    return abs(W / W_masing - 1.0)


def run(sizes, n_samples: int, repeats: int) -> list[dict]:
    exe = find_or_build_driver()
    rows = []
    for ns in sizes:
        out = subprocess.run([str(exe), str(ns), str(n_samples), str(repeats)], check=True,
                             capture_output=True, text=True).stdout.split()
        c_ns_sample, c_check = float(out[2]), float(out[4])
        el = sliders(ns)
        t_py, py_check = time_python(el, history(n_samples), repeats)
        rows.append(dict(sliders=ns, samples=n_samples, c_ns_sample=c_ns_sample,
                         c_ns_slider=c_ns_sample / ns, py_ns_sample=1e9 * t_py / n_samples,
                         py_over_c=1e9 * t_py / n_samples / c_ns_sample,
                         diff=abs(py_check - c_check / repeats) / abs(c_check / repeats),
                         masing_err=masing_error(el)))
    return rows


def print_table(rows) -> None:
    print(f"{'sliders':>7} {'samples':>7} {'C ns/sample':>11} {'C ns/slider':>11} "
          f"{'Py ns/sample':>12} {'Py/C':>5} {'Py-C diff':>9} {'W vs Masing':>11}")
    for r in rows:
        print(f"{r['sliders']:7d} {r['samples']:7d} {r['c_ns_sample']:11.1f} "
              f"{r['c_ns_slider']:11.2f} {r['py_ns_sample']:12.1f} {r['py_over_c']:5.2f} "
              f"{r['diff']:9.1e} {r['masing_err']:11.1e}")
    print(f"goals: <= {GOAL_NS_PER_SLIDER} ns per slider update (C driver, >= 8 sliders); "
          f"Python within {GOAL_PY_OVER_C}x of C")


def main(argv=None) -> int:
    from damper.script import count

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=count(1), nargs="+", default=[1, 4, 16, 64, 128, 256])
    p.add_argument("--samples", type=count(1), default=10_000)
    p.add_argument("--repeats", type=count(1), default=30)
    args = p.parse_args(argv)
    print_table(run(args.sizes, args.samples, args.repeats))
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
