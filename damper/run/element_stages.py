"""Element stages: the steady hysteresis loop and the FMUs of the element (``fmu_src``).

Both read the virgin curve from the tangential stage's result (the curve file's JSON
object, in memory) and build the Masing/Iwan element of the C core from it.
"""
from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np

from .graph import Kind, Result, Stage

#: The FMU check drives the element with u = 0.8 u_gs sin(2 pi t) for 5 s (5 cycles)
#: at the curve's normal load, sampled every 0.01 s, as the first demo did.
FMU_CHECK_AMPLITUDE = 0.8
FMU_CHECK_TIME = 5.0
FMU_CHECK_INTERVAL = 0.01


def curve_of(result: Result):
    """The VirginCurve of a tangential stage's result."""
    from contact_core.curve import VirginCurve

    return VirginCurve.from_dict(result.data["curve"], source="tangential stage")


class Loop(Kind):
    """Steady loop at a force amplitude, energy per cycle (the element of the curve)."""

    name = "loop"
    modules = ("fmu_src", "contact_core.curve", "damper.cli.loop")

    def instances(self, data):
        el = data.get("element")
        if not el or "loop_force_amplitude" not in el:
            return []
        return [Stage("loop", self, {"force_amplitude": el["loop_force_amplitude"], "samples": el["loop_samples"]},
                      deps=(f"tangential:{el['contact']}",), products=("loop",))]

    def compute(self, stage, inputs, ctx):
        from damper.cli.loop import amplitude_for_force, plot_loop
        from fmu_src.element import IwanElement

        curve = curve_of(inputs[stage.deps[0]])
        el = IwanElement.from_virgin_curve(curve)
        N = el.N_ref
        a = amplitude_for_force(el, stage.params["force_amplitude"], N)
        n = stage.params["samples"]
        u = a * np.cos(2.0 * np.pi * np.arange(n) / n)
        loop = el.periodic(u, N)
        with tempfile.TemporaryDirectory() as tmp:
            png = Path(plot_loop(tmp, el, u, loop.F, N)).read_bytes()
        data = {"energy_per_cycle": loop.W_cycle, "force_amplitude": 0.5 * float(np.ptp(loop.F)),
                "displacement_amplitude": a, "N": N, "n_sliders": el.n_sliders,
                "gross_slip_force": el.gross_slip_force(N) if math.isfinite(el.gross_slip_force(N)) else None,
                "samples": n}
        return Result(data, {"u": u, "F": np.asarray(loop.F)}, {"loop.png": png})

    def outputs(self, stage, result):
        return {"loop": "result.json"}

    def lines(self, stage, result):
        d = result.data
        return [f"displacement amplitude {d['displacement_amplitude']:.6g} m, force amplitude "
                f"{d['force_amplitude']:.6g} N, energy per cycle {d['energy_per_cycle']:.6g} J"]

    def scalars(self, stage, result):
        d = result.data
        return {"loop_displacement_amplitude_m": d["displacement_amplitude"],
                "loop_force_amplitude_N": d["force_amplitude"], "loop_energy_per_cycle_J": d["energy_per_cycle"]}


class FMU(Kind):
    """The element as an FMI 2.0 or 3.0 co-simulation FMU: built, validated by fmpy, run 5 cycles."""

    name = "fmu"
    modules = ("fmu_src", "contact_core.curve")

    def instances(self, data):
        el = data.get("element")
        if not el:
            return []
        return [Stage(f"fmu:fmi{v}", self, {"fmi_version": v}, deps=(f"tangential:{el['contact']}",),
                      products=("fmu",)) for v in el["fmi_versions"]]

    def compute(self, stage, inputs, ctx):
        from fmu_src.curve_fit import reduce_virgin_curve
        from fmu_src.fmu_build import build_fmu

        source = curve_of(inputs[stage.deps[0]])
        curve, error = reduce_virgin_curve(source)     # at most the C element's sliders
        v = stage.params["fmi_version"]
        curve_json = json.dumps(source.to_dict(), indent=1, allow_nan=False) + "\n"
        reduced = (f", reduced from {source.u.size} points, largest force error {error:.3g} N"
                   if curve is not source else "")
        description = (f"Masing/Iwan friction element from the virgin curve of {stage.deps[0]} "
                       f"({curve.u.size} points{reduced}, N_ref = {curve.N:g} N, mu = {curve.mu:g}"
                       + (", flat beyond its end: gross slip)" if curve.tail == "flat" else ")"))
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / f"damper_fmi{v}.fmu"
            build_fmu(curve.u, curve.T, curve.N, path, fmi_version=v, description=description,
                      tail=curve.tail, curve_json=curve_json)
            check = fmu_check(path, source)
            blob = path.read_bytes()
        return Result(check | {"curve_points": int(curve.u.size), "fit_error_N": error}, files={path.name: blob})

    def outputs(self, stage, result):
        return {"fmu": f"damper_fmi{stage.params['fmi_version']}.fmu"}

    def lines(self, stage, result):
        d = result.data
        return [f"   FMI {stage.params['fmi_version']}: {len(d['problems'])} validation problems, "
                f"W after 5 cycles {d['W_after_5_cycles']:.3e} J"]

    def scalars(self, stage, result):
        d = result.data
        return {"validation_problems": len(d["problems"]), "W_after_5_cycles_J": d["W_after_5_cycles"]}


def fmu_check(path: Path, curve) -> dict:
    """fmpy's validation problems and a short run of the FMU (5 cycles of u at 0.8 u_gs, N of the curve)."""
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(path))
    t = np.linspace(0.0, FMU_CHECK_TIME, int(round(FMU_CHECK_TIME / FMU_CHECK_INTERVAL)) + 1)
    u = FMU_CHECK_AMPLITUDE * curve.u[-1] * np.sin(2 * np.pi * t)
    signal = np.array(list(zip(t, u, np.full_like(t, curve.N))),
                      dtype=[("time", float), ("u", float), ("N", float)])
    res = simulate_fmu(str(path), stop_time=FMU_CHECK_TIME, output_interval=FMU_CHECK_INTERVAL,
                       input=signal, output=["F", "W"])
    return {"problems": list(problems), "W_after_5_cycles": float(res["W"][-1]), "F_max": float(np.max(res["F"]))}
