"""Drive one FMU (FMI 2 or 3) by variable names through fmpy."""
from __future__ import annotations

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave


class Slave:
    def __init__(self, path, version: int, name: str = "x"):
        md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.start = {v.name: float(v.start) for v in md.modelVariables if v.start is not None}
        d = extract(str(path))
        ident = md.coSimulation.modelIdentifier
        if version == 2:
            self.s = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=ident,
                               instanceName=name)
            self.s.instantiate()
            self.s.setupExperiment(startTime=0.0)
            self.s.enterInitializationMode()
        else:
            self.s = FMU3Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=ident,
                               instanceName=name)
            self.s.instantiate()
            self.s.enterInitializationMode(startTime=0.0)
        self.version, self.t = version, 0.0

    def start_stepping(self):
        self.s.exitInitializationMode()

    def set(self, **values):
        vrs, vals = [self.vr[k] for k in values], [float(v) for v in values.values()]
        (self.s.setReal if self.version == 2 else self.s.setFloat64)(vrs, vals)

    def get(self, *names):
        vals = (self.s.getReal if self.version == 2 else self.s.getFloat64)([self.vr[n] for n in names])
        return vals if len(names) > 1 else vals[0]

    def step(self, h: float):
        self.s.doStep(self.t, h)
        self.t += h

    def close(self):
        self.s.terminate()
        self.s.freeInstance()
