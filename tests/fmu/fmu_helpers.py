"""Shared pieces of the FMU tests: a test curve, a direct FMI driver, the Masing energy.

The curve is the Cattaneo-Mindlin virgin curve of a sphere (references.md),
T(u) = mu N [1 - (1 - u/u_s)^(3/2)], sampled at 51 points: concave, so the
element reproduces the piecewise-linear table exactly (Iwan).
"""
from __future__ import annotations

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

#: Curve parameters: friction coefficient, normal load [N], slip displacement [m].
MU, N_CURVE, U_SLIP = 0.5, 200.0, 2.0e-6
#: Value references (fmu_src/fmi/damper_vr.h; the header's own test checks them).
VR = {"time": 0, "u": 1, "N": 2, "F": 3, "kt": 4, "W": 5, "slip": 6, "scale": 7, "N_ref": 8,
      "stored_energy": 9}
#: Seed of the random histories (written out, see GUIDE.md).
SEED = 20251122


def curve_table(n: int = 51) -> tuple[np.ndarray, np.ndarray]:
    """Cattaneo-Mindlin virgin curve (u [m], T [N]) at ``n`` points up to gross slip."""
    u = np.linspace(0.0, U_SLIP, n)
    return u, MU * N_CURVE * (1.0 - (1.0 - u / U_SLIP) ** 1.5)


def masing_energy(u_tab, T_tab, a: float) -> float:
    """Energy per cycle [J] of a displacement cycle of amplitude ``a`` (Masing).

    W(a) = 8 int_0^a g(s) ds - 4 a g(a) for the piecewise-linear virgin curve g
    (references.md); the integral is exact (trapezoids on the breakpoints).
    """
    s = np.append(u_tab[u_tab < a], a)
    g = np.interp(s, u_tab, T_tab)
    integral = float(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(s)))
    return 8.0 * integral - 4.0 * a * float(g[-1])


class Slave:
    """One FMU instance driven directly through fmpy's FMU2Slave / FMU3Slave.

    ``step(u, N)`` sets the inputs at the current time, does one step of ``h`` and
    returns the outputs (F, kt, W, slip) at those inputs, i.e. the same sample the
    array API returns (no fmpy recording delay).
    """

    def __init__(self, fmu_path, fmi_version: int, name: str = "inst", unzipdir=None):
        md = read_model_description(fmu_path)
        self.dir = unzipdir or extract(fmu_path)
        self.v = fmi_version
        if fmi_version == 2:
            self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.dir,
                                 modelIdentifier=md.coSimulation.modelIdentifier,
                                 instanceName=name)
        else:
            self.fmu = FMU3Slave(guid=md.instantiationToken, unzipDirectory=self.dir,
                                 modelIdentifier=md.coSimulation.modelIdentifier,
                                 instanceName=name)
        self.fmu.instantiate()
        self.t = 0.0

    def set(self, names, values):
        vrs = [VR[n] for n in names]
        (self.fmu.setReal if self.v == 2 else self.fmu.setFloat64)(vrs, list(values))

    def get(self, names):
        vrs = [VR[n] for n in names]
        return (self.fmu.getReal if self.v == 2 else self.fmu.getFloat64)(vrs)

    def initialize(self, u0: float = 0.0, N0: float | None = None, **params):
        if self.v == 2:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=0.0)
        if params:
            self.set(params.keys(), params.values())
        self.set(["u"] + (["N"] if N0 is not None else []),
                 [u0] + ([N0] if N0 is not None else []))
        self.fmu.exitInitializationMode()
        return self

    def step(self, u: float, N: float | None = None, h: float = 1e-3):
        self.set(["u"] + (["N"] if N is not None else []), [u] + ([N] if N is not None else []))
        self.fmu.doStep(self.t, h)
        self.t += h
        return self.get(["F", "kt", "W", "slip"])

    def run(self, u, N=None, h: float = 1e-3) -> np.ndarray:
        """Outputs (F, kt, W, slip) after each sample, shape (4, n)."""
        out = [self.step(uk, None if N is None else N[k], h) for k, uk in enumerate(u)]
        return np.array(out).T

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
