"""Child process of an FMU stress case: build the FMU of a curve, drive it, print one JSON line.

    python -c "from damper.stress.fmu_child import main; main()" CURVE FMI DT STEPS INPUT AMPLITUDE WORKDIR [P]

INPUT: ``sine`` (P samples a cycle, default 64), ``chatter`` (the sign of u reverses every
step), ``nan`` (a NaN at step 3: must be refused). Exit 0 with the summary on
stdout, 2 with a message when the FMU refused an input or a call failed.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

#: Samples per cycle of the sine input.
POINTS_PER_CYCLE = 64


def inputs(kind: str, steps: int, amplitude: float, per_cycle: int = POINTS_PER_CYCLE) -> np.ndarray:
    """The displacement history u_k, k = 1..steps [m]."""
    k = np.arange(1, steps + 1)
    if kind == "chatter":
        return amplitude * np.where(k % 2 == 0, 1.0, -1.0)
    u = amplitude * np.sin(2.0 * np.pi * k / per_cycle)
    if kind == "nan":
        u[min(2, steps - 1)] = np.nan
    return u


def simulate(fmu_path: Path, dt: float, u: np.ndarray, workdir: Path, per_cycle: int = POINTS_PER_CYCLE) -> dict:
    """Drive the FMI 2 co-simulation FMU step by step; return the invariants' raw numbers."""
    from fmpy import extract, read_model_description

    md = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzip = extract(str(fmu_path), unzipdir=str(workdir / f"unzip{md.fmiVersion[0]}"))
    ident = md.coSimulation.modelIdentifier
    if md.fmiVersion.startswith("3"):
        from fmpy.fmi3 import FMU3Slave

        fmu = FMU3Slave(guid=md.instantiationToken, unzipDirectory=unzip, modelIdentifier=ident,
                        instanceName="stress")
        fmu.instantiate()
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        fmu.setReal, fmu.getReal = fmu.setFloat64, fmu.getFloat64
    else:
        from fmpy.fmi2 import FMU2Slave

        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=ident, instanceName="stress")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
    out_vr = [vr["F"], vr["W"]] + ([vr["stored_energy"]] if "stored_energy" in vr else [])
    F_prev, u_prev, W_prev = 0.0, 0.0, 0.0
    work = slack = 0.0
    max_F, min_dW = 0.0, 0.0
    t = 0.0
    W_cycles = []  # W at the end of every cycle of the sine
    try:
        for k, uk in enumerate(u, 1):
            fmu.setReal([vr["u"]], [float(uk)])
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
            t += dt
            vals = fmu.getReal(out_vr)
            F, W = vals[0], vals[1]
            if not (math.isfinite(F) and math.isfinite(W)):
                return {"nan": True}
            du, dF = uk - u_prev, F - F_prev
            work += 0.5 * (F + F_prev) * du
            slack += 0.5 * abs(dF * du)
            max_F, min_dW = max(max_F, abs(F)), min(min_dW, W - W_prev)
            F_prev, u_prev, W_prev = F, uk, W
            if k % per_cycle == 0 and len(W_cycles) < 100:
                W_cycles.append(W)
        stored_out = vals[2] if len(vals) > 2 else None
        fmu.terminate()
    finally:
        fmu.freeInstance()
    return {"max_abs_F": max_F, "min_dW": min_dW, "W": W_prev, "work": work, "slack": slack,
            "stored": work - W_prev, "stored_output": stored_out, "time": t, "W_cycles": W_cycles}


def main(argv: list[str] | None = None) -> int:
    args = argv or sys.argv[1:]
    curve, fmi, dt, steps, kind, amplitude, workdir = args[:7]
    per_cycle = int(args[7]) if len(args) > 7 else POINTS_PER_CYCLE
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    from damper.cli import main as damper

    fmu_path = workdir / f"damper_fmi{fmi}.fmu"
    if not fmu_path.exists():
        code = damper(["fmu", "--curve", curve, "--fmi-version", fmi, "-o", str(fmu_path)])
        if code:
            return code
    data = json.loads(Path(curve).read_text())
    muN = float(data["T"][-1])  # flat-tailed curves: the gross-slip force
    u_end = float(data["u"][-1])
    u = inputs(kind, int(steps), float(amplitude), per_cycle)
    try:
        res = simulate(fmu_path, float(dt), u, workdir, per_cycle)
    except Exception as err:  # noqa: BLE001 - fmpy raises plain Exception on an FMU error status
        print(f"damper stress fmu: the FMU refused the input: {err}", file=sys.stderr)
        return 2
    if res.get("nan"):
        print(json.dumps({"F": float("nan")}))
        return 0
    res.update(slip_force=muN, stored_bound=muN * u_end,
               work_scale=max(res["W"], muN * float(amplitude)))
    print(json.dumps(res))
    return 0
