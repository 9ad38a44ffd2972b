"""Benchmark: the 2D element and the contact point against the 1D element, and their FMUs.
=======================================================================================

Table 1 (C driver ``fmu_src/core/bench_iwan2d.c``, every case in one process, best of
``--repeats``): one step with outputs and tangent, per slider count, for the 1D element
on a line (``line1d``), the 2D element on the same line (``line2d``), on a circle at
constant N (``circle``: the tractrix), on the circle with N varying (``circleN``: the
quadrature of the work) and the contact point on the circle with p varying (``point``).
Columns: ns per step, ns per slider update, the ratio to ``line1d`` of the same run, and
with ``--instructions`` the instructions per slider update (callgrind: not disturbed by
other load on the machine). The check column: line2d's cycle energy against line1d's
(round-off), the circle's against the steady circles' sum 2 pi f_s sqrt(a^2 - r^2)
(the inscribed polygon's own error ~1e-6 at 1000 steps a cycle), point's against
circleN's (the same path through the penalty law: equal).

Table 2 (C master ``fmu_src/fmi/bench_driver.c`` on the FMI 2 binaries): ns per doStep
of the 1D FMU (set u, doStep, get F, W) and the contact-point FMU (set u_x, u_y, p on a
circle with p varying, doStep, get F_x, W), for the same curve.

Run: ``.venv/bin/python examples/bench_contact2d.py`` (about a minute); a smoke version
with tiny sizes runs in the tests.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))
from bench_element import find_or_build_driver  # noqa: E402  (the same CMake build)

from fmu_src import fmu_xml  # noqa: E402
from fmu_src.fmu_build import build_fmu  # noqa: E402
from fmu_src.fmu_point import build_point_fmu, penalty_table  # noqa: E402

CASES = ("line1d", "line2d", "circle", "circleN", "point")
AMP = 1.5e-6   # bench_iwan2d.c AMP [m]


def driver() -> Path:
    exe = find_or_build_driver()  # builds bench_iwan; bench_iwan2d lives beside it
    build = exe.parents[2]
    subprocess.run(["cmake", "--build", str(build), "--target", "bench_iwan2d"], check=True,
                   capture_output=True)
    return exe.with_name("bench_iwan2d")


def circle_energy(ns: int) -> float:
    """Steady circle of radius AMP: sum over slipping sliders of 2 pi f_s sqrt(a^2 - r^2)."""
    k = np.full(ns, 1e6 / ns)
    r = 1e-7 + 1.9e-6 * np.arange(ns) / max(ns - 1, 1)
    s = r < AMP
    return float(np.sum(2 * np.pi * k[s] * r[s] * np.sqrt(AMP**2 - r[s] ** 2)))


def instructions(exe: Path, ns: int, per: int, cycles: int, case: str) -> float | None:
    """Instructions per slider update of one case (callgrind), or None without valgrind."""
    if shutil.which("valgrind") is None:
        return None
    counts = []
    for c in (cycles, 2 * cycles):  # the difference cancels the setup
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "cg.out"
            subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                            str(exe), str(ns), str(per), str(c), "1", case], check=True,
                           capture_output=True)
            line = next(ln for ln in out.read_text().splitlines() if ln.startswith("summary:"))
            counts.append(int(line.split()[1]))
    return (counts[1] - counts[0]) / (per * cycles * ns)


def element_rows(sizes, per: int, cycles: int, repeats: int, count: bool) -> list[dict]:
    exe = driver()
    rows = []
    for ns in sizes:
        out = subprocess.run([str(exe), str(ns), str(per), str(cycles), str(repeats)],
                             check=True, capture_output=True, text=True).stdout.split("\n")
        got = {f[0]: (float(f[3]), float(f[4]), float(f[5])) for f in (ln.split() for ln in out) if f}
        base = got["line1d"][0]
        checks = {"line2d": abs(got["line2d"][2] / got["line1d"][2] - 1),
                  "circle": abs(got["circle"][2] / circle_energy(ns) - 1),
                  "point": abs(got["point"][2] / got["circleN"][2] - 1)}
        for case in CASES:
            ns_step, ns_slider, _ = got[case]
            rows.append(dict(case=case, sliders=ns, samples=per * cycles, ns_step=ns_step,
                             ns_slider=ns_slider, ratio=ns_step / base,
                             instr=instructions(exe, ns, per, max(cycles // 5, 1), case) if count else None,
                             check=checks.get(case)))
    return rows


def fmu_rows(n_sliders: int, steps: int, repeats: int) -> list[dict]:
    """ns per doStep of the 1D and the contact-point FMU (FMI 2, C master)."""
    from bench_fmu import compile_driver, curve_with_sliders, run_c_master
    from fmpy import extract

    u, T = curve_with_sliders(n_sliders)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_contact2d_") as tmp:
        tmp = Path(tmp)
        one = build_fmu(u, T, 200.0, tmp / "damper.fmu", fmi_version=2)
        point = build_point_fmu(u, T, 200.0, *penalty_table(1e8), tmp / "point.fmu", fmi_version=2)
        (tmp / "d1").mkdir()
        (tmp / "d2").mkdir()
        exe1 = compile_driver(tmp / "d1", fmu_xml.DAMPER)
        exe2 = compile_driver(tmp / "d2", fmu_xml.POINT)
        for name, exe, path, ident in (("1D FMU", exe1, one, "damper"),
                                       ("point FMU", exe2, point, "contact_point")):
            ns, F, W, rss = run_c_master(exe, extract(path), steps, repeats, name=ident,
                                         amplitude=1.6e-6)
            rows.append(dict(fmu=name, sliders=n_sliders, steps=steps, ns_step=ns, W=W, rss=rss))
    return rows


def print_tables(rows, frows) -> None:
    print(f"{'case':>8} {'sliders':>7} {'samples':>7} {'ns/step':>9} {'ns/slider':>9} "
          f"{'x line1d':>8} {'instr/slider':>12} {'check':>9}")
    for r in rows:
        instr = f"{r['instr']:12.0f}" if r["instr"] is not None else f"{'-':>12}"
        check = f"{r['check']:9.1e}" if r["check"] is not None else f"{'-':>9}"
        print(f"{r['case']:>8} {r['sliders']:7d} {r['samples']:7d} {r['ns_step']:9.1f} "
              f"{r['ns_slider']:9.2f} {r['ratio']:8.1f} {instr} {check}")
    print(f"\n{'FMU':>10} {'sliders':>7} {'steps':>7} {'ns/doStep':>10} {'W [J]':>10} {'RSS MiB':>8}")
    for r in frows:
        print(f"{r['fmu']:>10} {r['sliders']:7d} {r['steps']:7d} {r['ns_step']:10.1f} "
              f"{r['W']:10.3e} {r['rss']:8.1f}")


def main(argv=None) -> int:
    from damper.script import count

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=count(1), nargs="+", default=[1, 4, 16, 64])
    p.add_argument("--samples-per-cycle", type=count(1), default=1000)
    p.add_argument("--cycles", type=count(1), default=10)
    p.add_argument("--repeats", type=count(1), default=5)
    p.add_argument("--instructions", action="store_true", help="callgrind instruction counts")
    p.add_argument("--fmu-sliders", type=count(1), default=16)
    p.add_argument("--fmu-steps", type=count(1), default=100_000)
    args = p.parse_args(argv)
    rows = element_rows(args.sizes, args.samples_per_cycle, args.cycles, args.repeats,
                        args.instructions)
    print_tables(rows, fmu_rows(args.fmu_sliders, args.fmu_steps, args.repeats))
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
