"""The description of a ring archive, ``resources/system.json`` (typed).

``damper system`` writes it next to the FMUs of the ring SSP; ``damper cosim`` reads
it back for the components, the response connector, the step and its coupling limit.
An archive may come from anywhere, so the file is checked as any input file is
(:class:`RingInfo`): every key present with its type, numbers finite and in range, the
component lists as long as the ring, the coupling block square on the coupling DOFs.
Symbols as in :mod:`damper.ring_system`.
"""
from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, model_validator

from contact_core.fileformat import FileModel
from damper import limits

_Positive = Annotated[float, Field(gt=0.0, le=limits.MAX_MAGNITUDE)]
_Name = Annotated[str, Field(min_length=1, max_length=200)]


class RingInfo(FileModel):
    """``resources/system.json`` of a ring archive (SI units)."""

    kind: Literal["damper-ring"] = Field(description="format tag")
    config: str = Field(description="the UPD model the ring was built from")
    blades: Annotated[int, Field(ge=1, le=limits.MAX_RING_BLADES)] = Field(description="N_b of the disk")
    engine_order: Annotated[int, Field(ge=0, le=limits.MAX_RING_BLADES)] = Field(description="EO")
    ring_blades: Annotated[int, Field(ge=1, le=limits.MAX_RING_BLADES)] = Field(
        description="blades in the archive, N_b / gcd(N_b, EO)")
    interblade_phase: Annotated[float, Field(ge=-7.0, le=7.0)] = Field(description="phi = 2 pi EO / N_b [rad]")
    cf: _Positive = Field(description="centrifugal load on each damper [N]")
    f0: _Positive = Field(description="EO force amplitude [N]")
    frequency_hz: Annotated[float, Field(gt=0.0, le=limits.MAX_OMEGA / (2 * math.pi))] = Field(
        description="excitation frequency the FMUs start with [Hz]")
    fmi_version: Literal[2, 3] = Field(description="FMI version of the FMUs")
    omega_max: _Positive = Field(description="highest frequency of the damper on its stuck contacts [rad/s]")
    step_limit: _Positive = Field(description="coupling limit 2 / omega_max [s]")
    default_step: _Positive = Field(description="default communication step [s]")
    step_fraction: Annotated[float, Field(gt=0.0, le=1.0)] = Field(description="default step / limit")
    damper_substep: _Positive = Field(description="the damper FMU's internal step [s]")
    blades_components: list[_Name] = Field(description="blade component names, one per ring blade")
    damper_components: list[_Name] = Field(description="damper component names, one per ring blade")
    response: _Name = Field(description="the blades' response output connector")
    response_dof: _Name = Field(description="its DOF name")
    contacts: list[_Name] = Field(description="contact point names of a damper")
    coupling_dofs: list[_Name] = Field(description="blade DOFs coupled to the next blade")
    K_next_coupling: list[list[Annotated[float, Field(ge=-limits.MAX_MAGNITUDE, le=limits.MAX_MAGNITUDE)]]] = \
        Field(description="K_next on the coupling DOFs [N/m] (rows blade j, columns blade j+1)")

    @model_validator(mode="after")
    def _consistent(self):
        """Component lists as long as the ring, the coupling block square on its DOFs."""
        n = self.ring_blades
        for key in ("blades_components", "damper_components"):
            if len(getattr(self, key)) != n:
                raise ValueError(f"{key}: {len(getattr(self, key))} names for ring_blades = {n}")
        names = self.blades_components + self.damper_components
        if len(set(names)) != len(names):
            raise ValueError("blades_components, damper_components: the names must differ")
        c = len(self.coupling_dofs)
        if self.K_next_coupling and (len(self.K_next_coupling) != c
                                     or any(len(row) != c for row in self.K_next_coupling)):
            raise ValueError(f"K_next_coupling: must be {c} x {c} (coupling_dofs), or empty")
        return self
