"""Closed loop: the damper FMU coupled to a mass-spring oscillator by a fixed-step master.
=======================================================================================

The oscillator m x'' + c x' + k x + F(x) = P sin(w t) carries a friction contact to
ground (u = x) whose force F comes from the FMI 2 FMU of a Cattaneo-Mindlin virgin
curve with contact stiffness kt0 = 100 k (a stiff contact, ordinary for dampers).
The master integrates the mass with the Newmark average-acceleration rule (no
numerical damping, unconditionally stable for the linear part) in two ways:

- ``explicit``: the FMU's force at the start of the step is held over the step
  (what a master that ignores the FMU's ``kt`` output does). The contact stiffness
  then acts explicitly and the step must resolve it: h < ~2 / sqrt(kt0 / m).
- ``kt``: the master linearises the contact with the FMU's tangent, F(x1) ~ F0 + kt
  (x1 - x0), solves the step with it, then commits x1 to the FMU and uses the FMU's
  exact force there for the acceleration. Stable at steps far beyond the contact's
  period.

Energy balance per forcing cycle. The Newmark identity holds exactly per step for the
force the master applied (F0 + kt dx at the end of a step, trapezoid over it): input
work = viscous work + applied damper work + change of kinetic and spring energy. The
FMU integrates its own path exactly: W (dissipated) + change of ``stored_energy`` is
the true work on the contact. The column "closure" is input work - viscous - W -
dE_mech - dE_stored, relative to the input work: the coupling's energy defect (the
trapezoid and linearisation error of the applied force), which vanishes as h -> 0.

Run: ``.venv/bin/python examples/fmu_closed_loop.py`` (a few seconds); prints the
energy balance of the last cycles and the largest stable step of each coupling.
The smoke test (tests/fmu/test_fmu_closed_loop.py) runs it with ``--quick``.
"""
from __future__ import annotations

import argparse
import math
import tempfile
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from fmu_src.fmu_build import build_fmu

# Oscillator (SI): mass [kg], spring [N/m], damping ratio, forcing amplitude [N].
M, K, ZETA, P0 = 1.0, 1.0e6, 0.05, 40.0
C = 2.0 * ZETA * math.sqrt(K * M)
W0 = math.sqrt(K / M)                 # 1000 rad/s
OMEGA = 0.9 * W0                      # forcing frequency [rad/s]
# Contact: mu N = 50 N, initial stiffness kt0 = 100 k (Cattaneo-Mindlin curve).
MU_N, N_REF, KT0 = 50.0, 100.0, 100.0 * K
U_S = 1.5 * MU_N / KT0                # gross-slip displacement of the curve [m]
VR = {"u": 1, "F": 3, "kt": 4, "W": 5, "stored_energy": 9}


def build(directory: Path) -> Path:
    """The FMI 2 FMU of the contact (31-point Cattaneo-Mindlin curve, flat at mu N)."""
    u = np.linspace(0.0, U_S, 31)
    T = MU_N * (1.0 - (1.0 - u / U_S) ** 1.5)
    return build_fmu(u, T, N_REF, directory / "contact.fmu", fmi_version=2, tail="flat")


class Contact:
    """One FMU instance: commit(x, h) steps it to displacement x, returns (F, kt, W, E)."""

    def __init__(self, path: Path, unzipdir: str):
        md = read_model_description(path)
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName="c")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.t = 0.0

    def commit(self, x: float, h: float):
        self.fmu.setReal([VR["u"]], [x])
        self.fmu.doStep(self.t, h)
        self.t += h
        return self.fmu.getReal([VR["F"], VR["kt"], VR["W"], VR["stored_energy"]])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def simulate(path: Path, unzipdir: str, h: float, cycles: int, coupling: str) -> dict:
    """March ``cycles`` forcing periods at step h; energy terms per cycle.

    Returns dict with x (shape (n+1,)), per-cycle arrays (shape (cycles,)) input,
    viscous, damper (trapezoid), W, dE_mech, dE_stored, and ``ok`` (False if the
    motion diverged or the FMU refused an input).
    """
    n_per = max(1, round(2.0 * math.pi / OMEGA / h))
    h = 2.0 * math.pi / OMEGA / n_per                 # whole steps per cycle
    use_kt = coupling == "kt"
    c = Contact(path, unzipdir)
    x, v, F, kt, W, E = 0.0, 0.0, 0.0, KT0, 0.0, 0.0
    P = 0.0
    a = (P - C * v - K * x - F) / M
    xs = [x]
    terms = np.zeros((cycles, 6))   # input, viscous, damper, W, dE_mech, dE_stored
    ok = True
    try:
        for cyc in range(cycles):
            W_start, E_start, mech_start = W, E, 0.5 * M * v * v + 0.5 * K * x * x
            for _ in range(n_per):
                t1 = c.t + h
                P1 = P0 * math.sin(OMEGA * t1)
                k_lin = kt if use_kt else 0.0
                lhs = 4.0 * M / h**2 + 2.0 * C / h + K + k_lin
                rhs = (P1 - F + k_lin * x + M * (4.0 / h**2 * (x + h * v) + a)
                       + C * (2.0 / h * x + v))
                x1 = rhs / lhs
                v1 = 2.0 / h * (x1 - x) - v
                F1, kt1, W, E = c.commit(x1, h)
                a1 = (P1 - C * v1 - K * x1 - F1) / M       # the FMU's exact force at x1
                dx = x1 - x
                terms[cyc, 0] += 0.5 * (P + P1) * dx
                terms[cyc, 1] += C * h * (0.5 * (v + v1)) ** 2
                # the force the master applied over the step: F0 + kt dx at its end
                terms[cyc, 2] += (F + 0.5 * k_lin * dx) * dx
                x, v, a, F, kt, P = x1, v1, a1, F1, kt1, P1
                xs.append(x)
                if not abs(x) < 1e3 * P0 / K:
                    raise FloatingPointError("diverged")
            terms[cyc, 3] = W - W_start
            terms[cyc, 4] = 0.5 * M * v * v + 0.5 * K * x * x - mech_start
            terms[cyc, 5] = E - E_start
    except (FMICallException, FloatingPointError, OverflowError):
        ok = False
    c.close()
    names = ("input", "viscous", "damper", "W", "dE_mech", "dE_stored")
    return {"ok": ok, "x": np.array(xs), "h": h, **{k: terms[:, i] for i, k in enumerate(names)}}


def amplitude(run: dict, last: int) -> float:
    """Displacement amplitude over the last ``last`` cycles [m] (inf if diverged)."""
    if not run["ok"]:
        return math.inf
    n_per = round(2.0 * math.pi / OMEGA / run["h"])
    return float(np.max(np.abs(run["x"][-last * n_per:])))


def largest_stable_step(path, unzipdir, coupling, cycles, ref_amp, h_lo, h_hi, iters):
    """Bisection on h: stable = no divergence and the steady amplitude within 50 % of
    the reference (fine-step) amplitude. h_lo must be stable."""
    for _ in range(iters):
        h = math.sqrt(h_lo * h_hi)
        amp = amplitude(simulate(path, unzipdir, h, cycles, coupling), 3)
        if abs(amp - ref_amp) <= 0.5 * ref_amp:
            h_lo = h
        else:
            h_hi = h
    return h_lo


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smoke-test sizes")
    args = parser.parse_args(argv)
    cycles, iters = (6, 5) if args.quick else (30, 14)
    period = 2.0 * math.pi / OMEGA
    contact_period = 2.0 * math.pi / math.sqrt((K + KT0) / M)
    with tempfile.TemporaryDirectory() as tmp:
        path = build(Path(tmp))
        unzipdir = extract(path)
        h_ref = contact_period / 40.0
        ref = simulate(path, unzipdir, h_ref, cycles, "kt")
        ref_amp = amplitude(ref, 3)
        print(f"oscillator: m = {M} kg, k = {K:.3g} N/m, zeta = {ZETA}, P0 = {P0} N at "
              f"{OMEGA / W0:.2f} w0; contact: mu N = {MU_N} N, kt0 = {KT0:.3g} N/m (100 k)")
        print(f"reference: h = {ref['h']:.3e} s (contact period / 40), amplitude "
              f"{ref_amp:.6e} m\n")
        print("energy balance per cycle (kt coupling, reference step) [J]:")
        print(f"{'cycle':>5} {'input':>12} {'viscous':>12} {'W (FMU)':>12} {'dE_mech':>12} "
              f"{'dE_stored':>12} {'closure':>10}")
        for i in range(cycles - 4, cycles):
            out = ref["viscous"][i] + ref["W"][i] + ref["dE_mech"][i] + ref["dE_stored"][i]
            closure = (ref["input"][i] - out) / ref["input"][i]
            print(f"{i + 1:>5} {ref['input'][i]:12.6e} {ref['viscous'][i]:12.6e} "
                  f"{ref['W'][i]:12.6e} {ref['dE_mech'][i]:12.4e} {ref['dE_stored'][i]:12.4e} "
                  f"{closure:10.2e}")
        stable = {}
        for coupling in ("explicit", "kt"):
            stable[coupling] = largest_stable_step(path, unzipdir, coupling, cycles, ref_amp,
                                                   h_ref, period / 4.0, iters)
        print(f"\nlargest stable step (steady amplitude within 50 % of the reference, "
              f"{cycles} cycles):")
        for coupling, h in stable.items():
            print(f"  {coupling:>8} coupling: h = {h:.3e} s = {h / contact_period:.3g} contact "
                  f"periods = {period / h:.1f} steps per forcing cycle")
        print(f"  the FMU's kt lets the master take {stable['kt'] / stable['explicit']:.1f}x "
              "larger steps")
    return {"ref": ref, "ref_amp": ref_amp, "stable": stable, "contact_period": contact_period}


if __name__ == "__main__":
    import sys

    from damper.script import run as run_script

    sys.exit(run_script(main))
