"""Benchmark: the cost of one doStep of the friction-element FMU.
==============================================================

Two masters drive the FMI 2 binary: a small C master (``fmu_src/fmi/bench_driver.c``:
set u, doStep, get F and W per step) and fmpy's ``FMU2Slave`` from Python. Each
runs the friction element and a pass-through FMU (F = u) built the same way, so
the element's own cost is the difference. Goal: the element adds less
than 100 ns a step for a 50-slider curve.

The error column checks the numbers: the FMU's last F and W against the array API
(``fmu_src.element``) for the same history (pass-through: against u).

Run: ``.venv/bin/python examples/bench_fmu.py`` (about a minute; ``--sliders``
chooses the element sizes); a smoke version with tiny settings runs in the tests.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmu_src import fmu_xml
from fmu_src.element import IwanElement
from fmu_src.fmu_build import FMI_DIR, build_fmu

#: Curve: Cattaneo-Mindlin virgin curve of a sphere (references.md), mu N = 100 N.
MU, N_REF, U_SLIP = 0.5, 200.0, 2.0e-6
#: Amplitude of the sinusoidal displacement: partial slip, every slider active.
AMPLITUDE = 0.8 * U_SLIP
#: Samples per cycle of the sinusoid.
POINTS_PER_CYCLE = 64
#: The element's budget per step [ns].
GOAL_NS = 100.0


def curve_with_sliders(n_sliders: int) -> tuple[np.ndarray, np.ndarray]:
    """Cattaneo-Mindlin table whose Iwan model has exactly ``n_sliders`` sliders."""
    for m in range(n_sliders + 1, n_sliders + 4):
        u = np.linspace(0.0, U_SLIP, m)
        T = MU * N_REF * (1.0 - (1.0 - u / U_SLIP) ** 1.5)
        if IwanElement.from_curve(u, T, N_REF).n_sliders == n_sliders:
            return u, T
    raise ValueError(f"no table with {n_sliders} sliders found")


def history(steps: int) -> np.ndarray:
    """u of the benchmark, the same formula as bench_driver.c (one tabulated cycle) [m]."""
    return AMPLITUDE * np.sin(2.0 * np.pi / POINTS_PER_CYCLE * (np.arange(steps) % POINTS_PER_CYCLE))


def compile_driver(workdir: Path, iface=fmu_xml.DAMPER) -> Path:
    """The C master for the FMUs of ``iface`` (its fmu_vars.h written into ``workdir``)."""
    exe = workdir / f"bench_driver_{iface.model_identifier}"
    (workdir / "fmu_vars.h").write_text(fmu_xml.render_fmu_vars(iface))
    cmd = [os.environ.get("CC", "cc"), "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror",
           f"-I{workdir}", f"-I{FMI_DIR}", f"-I{FMI_DIR / 'headers'}",
           str(FMI_DIR / "bench_driver.c"), "-o", str(exe), "-ldl", "-lm"]
    subprocess.run(cmd, check=True)
    return exe


def run_c_master(exe: Path, unzipdir: str, steps: int, repeats: int, name: str = "damper",
                 amplitude: float = AMPLITUDE):
    """(ns per step, last F, last W, peak RSS in MiB) from the C master."""
    binary = Path(unzipdir) / "binaries" / "linux64" / f"{name}.so"
    uri = Path(unzipdir, "resources").as_uri()
    out = subprocess.run([str(exe), str(binary), uri, str(steps), repr(amplitude),
                          str(POINTS_PER_CYCLE), str(repeats)],
                         check=True, capture_output=True, text=True).stdout
    ns, F, W, kib = (float(x) for x in out.split())
    return ns, F, W, kib / 1024.0


def run_fmpy(fmu: Path, unzipdir: str, steps: int) -> float:
    """Seconds per step of set/doStep/get through fmpy's FMU2Slave."""
    md = read_model_description(str(fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="damper",
                  instanceName="bench")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    u = history(steps)
    t0 = time.perf_counter()
    for k in range(steps):
        s.setReal([1], [u[k]])
        s.doStep(k * 1e-3, 1e-3)
        s.getReal([3, 5])
    elapsed = time.perf_counter() - t0
    s.terminate()
    s.freeInstance()
    return elapsed / steps


def _row(exe, tmp: Path, model: str, n_sliders: int, steps: int, py_steps: int,
         repeats: int) -> dict:
    """Build one FMU, time it through both masters, check its last F and W."""
    u_tab, T_tab = curve_with_sliders(max(n_sliders, 1))
    name = f"{model}{n_sliders}"
    fmu = build_fmu(u_tab, T_tab, N_REF, tmp / f"{name}.fmu", model=model)
    unzipdir = extract(str(fmu), str(tmp / name))
    ns, F, W, rss = run_c_master(exe, unzipdir, steps, repeats)
    if model == "iwan":
        ref = IwanElement.from_curve(u_tab, T_tab, N_REF).series(history(steps))
        err = max(abs(F - ref.F[-1]) / abs(ref.F).max(), abs(W - ref.W[-1]) / ref.W[-1])
    else:
        err = abs(F - history(steps)[-1]) / AMPLITUDE
    return {"case": model, "sliders": n_sliders, "steps": steps, "error": err, "c_ns": ns,
            "fmpy_us": 1e6 * run_fmpy(fmu, unzipdir, py_steps), "rss_mib": rss}


def measure(sliders, steps: int, py_steps: int, repeats: int) -> list[dict]:
    """The pass-through row, then one element row per slider count in ``sliders``."""
    with tempfile.TemporaryDirectory(prefix="bench_fmu_") as tmp:
        exe = compile_driver(Path(tmp))
        rows = [_row(exe, Path(tmp), "passthrough", 0, steps, py_steps, repeats)]
        rows += [_row(exe, Path(tmp), "iwan", n, steps, py_steps, repeats) for n in sliders]
    return rows


def print_table(rows: list[dict]) -> dict:
    """Print the table; return {sliders: element's own cost through the C master [ns]}."""
    base = rows[0]["c_ns"]
    print(f"{'case':<12}{'sliders':>8}{'steps':>10}{'rel. error':>12}{'C master ns/step':>18}"
          f"{'element ns':>12}{'fmpy us/step':>14}{'peak RSS MiB':>14}")
    for r in rows:
        extra = r["c_ns"] - base if r["case"] == "iwan" else 0.0
        print(f"{r['case']:<12}{r['sliders']:>8}{r['steps']:>10}{r['error']:>12.1e}"
              f"{r['c_ns']:>18.1f}{extra:>12.1f}{r['fmpy_us']:>14.2f}{r['rss_mib']:>14.1f}")
    costs = {r["sliders"]: r["c_ns"] - base for r in rows[1:]}
    if 50 in costs:
        print(f"element's own cost through the C master at 50 sliders: {costs[50]:.1f} ns/step "
              f"(goal < {GOAL_NS:.0f} ns): {'met' if costs[50] < GOAL_NS else 'NOT met'}")
    return costs


def main(argv: list[str] | None = None) -> int:
    from damper.script import count, numbers

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sliders", type=numbers(int, 0), default="1,10,50,200",
                        help="comma-separated slider counts of the element")
    parser.add_argument("--steps", type=count(1), default=1_000_000, help="C master steps")
    parser.add_argument("--py-steps", type=count(1), default=20_000, help="fmpy steps")
    parser.add_argument("--repeats", type=count(1), default=5, help="C runs; the best counts")
    args = parser.parse_args(argv)
    print_table(measure(args.sliders, args.steps, args.py_steps, args.repeats))
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
