"""The main job (``make demo``): the whole chain on the bundled default scene.

1. Normal contact validation: sphere and cylinder FE models against Hertz
   (``examples/normal_validation.py``).
2. The default contact's virgin curve and k_t (``damper tangential``).
3. Its steady hysteresis loop and energy per cycle (``damper loop``).
4. The friction element as FMI 2.0 and 3.0 FMUs (``damper fmu``), validated and
   run by fmpy.
5. The damped forced response of the default blade-damper model for several
   excitation levels (``damper frf``, harmonic balance).

Every stage runs through the same ``damper`` command a user would type, and
writes its JSON and plots under ``--out`` (default ``out/``)::

    python examples/demo.py [--out out] [--scene examples/default_scene.toml]

The scene file (``examples/default_scene.toml``) documents the parameters.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from damper.cli import main as damper
from damper.cli.common import atomic_write, dumps

HERE = Path(__file__).resolve().parent


def run(args: list[str]) -> None:
    """Run one ``damper`` command in-process; stop the demo if it fails."""
    print("$ damper " + " ".join(args), flush=True)
    code = damper(args)
    if code != 0:
        raise SystemExit(f"demo: 'damper {args[0]}' failed with exit code {code}")


def contact_args(c: dict) -> list[str]:
    """Command-line options of the scene's contact (cylinder, sphere or flat)."""
    sizes = {"cylinder": ("diameter", "length"), "sphere": ("radius",), "flat": ("width", "length")}
    args = ["--body", c["body"]]
    for key in sizes[c["body"]]:
        args += [f"--{key}", repr(float(c[key]))]
    return args + ["--force", repr(float(c["force"])), "--mu", repr(float(c["mu"])),
                   "--grid", str(int(c["grid"]))]


def write_structure(s: dict, out: Path) -> tuple[Path, Path]:
    """Write the 2-DOF blade-damper model (a unit tip force) and its friction link (elements.toml)."""
    M = np.diag([s["m_tip"], s["m_platform"]])
    K = np.array([[s["k_blade"], -s["k_blade"]], [-s["k_blade"], s["k_blade"] + s["k_disk"]]])
    omega1 = math.sqrt(min(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    beta = 2.0 * s["zeta"] / omega1          # Rayleigh C = beta K: zeta at the first free mode
    model = out / "blade_damper.npz"
    buf = out / ".tmp_model.npz"
    np.savez(buf, M=M, K=K, C=beta * K, force=np.array([1.0, 0.0]), response_dof=0)
    buf.replace(model)
    elements = atomic_write(out / "elements.toml",
                            '[[element]]\ndofs = [1]          # platform against the damper (ground)\n'
                            'type = "curve"\npath = "curve.json"\n')
    return model, elements


def fmu_check(path: Path, curve: Path) -> dict:
    """fmpy validation problems and a short run of the FMU (5 cycles of u at 0.8 u_gs, N of the curve)."""
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(path))
    data = json.loads(curve.read_text())
    t = np.linspace(0.0, 5.0, 501)
    u = 0.8 * data["u"][-1] * np.sin(2 * np.pi * t)
    signal = np.array(list(zip(t, u, np.full_like(t, data["N"]))),
                      dtype=[("time", float), ("u", float), ("N", float)])
    res = simulate_fmu(str(path), stop_time=5.0, output_interval=0.01, input=signal, output=["F", "W"])
    return {"problems": problems, "W_after_5_cycles": float(res["W"][-1]), "F_max": float(np.max(res["F"]))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("out"))
    parser.add_argument("--scene", type=Path, default=HERE / "default_scene.toml")
    args = parser.parse_args(argv)
    scene = tomllib.loads(args.scene.read_text())
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    summary: dict = {"scene": str(args.scene)}

    print("== 1. normal contact validation (FE vs Hertz)")
    # examples/ is not a package: load the script beside this one by path
    spec = importlib.util.spec_from_file_location("normal_validation", HERE / "normal_validation.py")
    normal_validation = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(normal_validation)
    summary["normal_validation"] = normal_validation.main(out / "normal")

    print("== 2. virgin curve of the default contact")
    curve = out / "curve.json"
    run(["tangential", *contact_args(scene["contact"]), "--out", str(curve), "--plot", str(out / "tangential")])

    print("== 3. hysteresis loop")
    r = scene["response"]
    run(["loop", "--curve", str(curve), "--force-amplitude", repr(r["loop_force_amplitude"]),
         "--plot", str(out / "loop")])

    print("== 4. FMUs")
    summary["fmu"] = {}
    for version in ("2", "3"):
        fmu = out / f"damper_fmi{version}.fmu"
        run(["fmu", "--curve", str(curve), "--fmi-version", version, "-o", str(fmu)])
        summary["fmu"][version] = check = fmu_check(fmu, curve)
        print(f"   FMI {version}: {len(check['problems'])} validation problems, "
              f"W after 5 cycles {check['W_after_5_cycles']:.3e} J")

    print("== 5. forced response (harmonic balance)")
    summary["frf"] = {}
    w = [repr(2 * math.pi * r["f_min"]), repr(2 * math.pi * r["f_max"])]
    model, elements = write_structure(scene["structure"], out)
    for force in r["forces"]:
        frf_json = out / f"frf_{force:g}N.json"
        run(["frf", "--model", str(model), "--elements", str(elements), "--force-scale", repr(float(force)),
             "--harmonics", str(r["harmonics"]), "--omega", *w, "--out", str(frf_json),
             "--plot", str(out / f"frf_{force:g}N")])
        d = json.loads(frf_json.read_text())
        summary["frf"][f"{force:g}"] = {k: d[k] for k in ("peak_omega", "peak_amplitude", "points", "time_s")}
        print(f"   P = {force:g} N: peak {d['peak_amplitude']:.3e} m at {d['peak_omega'] / (2 * math.pi):.1f} Hz "
              f"({d['points']} points, {d['time_s']:.2f} s)")

    summary["time_s"] = time.perf_counter() - t0
    atomic_write(out / "demo_summary.json", dumps(summary, indent=1) + "\n")
    print(f"demo: done in {summary['time_s']:.0f} s; results in {out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
