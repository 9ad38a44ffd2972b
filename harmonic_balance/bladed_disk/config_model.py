"""The UPD model file's keys, types and ranges (typed, :mod:`contact_core.fileformat`).

One description of the TOML that :func:`.config.load_config` reads (the bundled
``upd24.toml`` documents each key): a user file gives any subset of the keys, the
others keep UPD-24's, and the merged model is checked here. Symbols as in
:mod:`.config`. What needs the blade's matrices (DOF names, definiteness) is
:mod:`.blade`'s check.
"""
from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, model_validator

from contact_core.fileformat import FileModel
from contact_core.spec import MAX_GRID

#: Most blades of a disk: the ring of N_b / gcd(N_b, EO) blades is built with dense
#: statics ((7 N_b)^2 numbers per matrix: 190 MB for three at 400 blades) and its FMU
#: archive holds one blade and one damper per ring blade; real disks hold below ~150.
MAX_BLADES = 400
BLADES_WHY = ("the ring's statics are dense ((7 N_b)^2 numbers per matrix) and its archive holds a blade "
              "and a damper FMU per ring blade")
#: Largest magnitude of a model parameter [SI]: the harmonic balance squares forces and
#: displacements (residual norms, omega^2 M), which overflows double precision near 1e154.
MAX_PARAMETER = 1e100
#: Highest band frequency [Hz]: 1e9 rad/s, far above any mode of a blade model.
MAX_BAND_HZ = 1e9 / (2 * math.pi)

Positive = Annotated[float, Field(gt=0.0, le=MAX_PARAMETER)]
NonNegative = Annotated[float, Field(ge=0.0, le=MAX_PARAMETER)]
Coordinate = Annotated[float, Field(ge=-1.0, le=1.0)]   # [m] from the damper's centre of mass
Poisson = Annotated[float, Field(gt=-1.0, lt=0.5)]
DofName = Annotated[str, Field(min_length=1, max_length=200)]


class Disk(FileModel):
    blades: Annotated[int, Field(ge=2, le=MAX_BLADES)] = Field(
        description="N_b, blades of the disk", json_schema_extra={"why": BLADES_WHY})
    engine_order: Annotated[int, Field(ge=0, le=MAX_BLADES // 2)] = Field(description="EO, 0..N_b/2")


class BladeSection(FileModel):
    m_r: Positive = Field(description="rim share [kg]")
    k_g: Positive = Field(description="rim to hub [N/m]")
    k_c: NonNegative = Field(description="rim to rim of the neighbours [N/m]")
    m_p: Positive = Field(description="platform mass [kg]")
    k_rp: Positive = Field(description="shank u_r - u_p [N/m]")
    k_v: Positive = Field(description="v_p to ground [N/m]")
    m_a: Positive = Field(description="airfoil modal mass [kg]")
    k_pa: Positive = Field(description="u_p - u_a [N/m]")
    beta: NonNegative = Field(description="structural damping C = beta K [s]")
    file: str = Field(description=".npz blade file (relative to the TOML); empty: lumped blade")
    M: str = Field(description="Matrix Market mass [kg]")
    K: str = Field(description="Matrix Market stiffness [N/m]")
    C: str = Field(description="Matrix Market damping [N s/m] (empty: beta K)")
    K_next: str = Field(description="Matrix Market coupling to blade j+1 [N/m]")
    C_next: str = Field(description="its damping [N s/m]")
    dofs: list[DofName] = Field(description="DOF names")
    left: Annotated[list[DofName], Field(max_length=3)] = Field(description="[u, v(, w)] of the cylinder contact")
    right: Annotated[list[DofName], Field(max_length=3)] = Field(description="[u, v(, w)] of the flat contact")
    forced: str = Field(description="DOF of the EO force")
    response: str = Field(description="DOF of the amplitude output (default: forced)")


class DamperSection(FileModel):
    m_d: Positive = Field(description="mass [kg]")
    I_d: Positive = Field(description="moment of inertia about G [kg m^2]")
    R_d: NonNegative = Field(description="radius of the centre of mass [m]")
    angle_deg: Annotated[float, Field(gt=0.0, lt=90.0)] = Field(description="face angle g [deg]")
    left_point: Annotated[list[Coordinate], Field(min_length=2, max_length=2)] = Field(
        description="[x, y] of the cylinder line contact from G [m]")
    right_centre: Annotated[list[Coordinate], Field(min_length=2, max_length=2)] = Field(
        description="[x, y] of the flat's centre from G [m]")
    right_width: NonNegative = Field(description="flat width [m]")
    contact_length: Positive = Field(description="contact length [m]")
    kn_per_length: Positive = Field(description="normal stiffness per length [N/m/m]")
    kt_ratio: Positive = Field(description="k_t / k_n")
    mu: Annotated[float, Field(ge=0.0, le=100.0)] = Field(description="friction coefficient (a typo above 100)")
    beta_c: NonNegative = Field(description="contact dashpots beta_c k [s]")


class LoadSection(FileModel):
    f0: Positive = Field(description="EO force amplitude [N]")
    cf: NonNegative = Field(description="centrifugal load on the damper [N]")
    band_hz: Annotated[list[Annotated[float, Field(gt=0.0, le=MAX_BAND_HZ)]],
                       Field(min_length=2, max_length=2)] = Field(description="[low, high] band [Hz]")

    @model_validator(mode="after")
    def _band_increases(self):
        if not self.band_hz[1] > self.band_hz[0]:
            raise ValueError(f"band_hz: must be [low, high] with high > low, got {self.band_hz}")
        return self


class GeometrySection(FileModel):
    cylinder_radius: Positive = Field(description="radius of the damper's cylinder [m]")
    flat_height: Positive = Field(description="damper body height above its flat face [m]")
    E_damper: Positive = Field(description="Young's modulus of the damper [Pa]")
    nu_damper: Poisson = Field(description="Poisson ratio of the damper")
    E_blade: Positive = Field(description="Young's modulus of the platforms [Pa]")
    nu_blade: Poisson = Field(description="Poisson ratio of the platforms")
    normal_load_left: NonNegative = Field(description="nominal N of the cylinder [N] (0: from CF)")
    normal_load_flat: NonNegative = Field(description="nominal N of the flat [N] (0: from CF)")
    grid: Annotated[int, Field(ge=3, le=MAX_GRID)] = Field(description="contact-zone nodes per side")
    cylinder_model: Literal["real", "halfspace"] = Field(description="FE model of the cylinder contact")


class UPDFile(FileModel):
    """A UPD model TOML (every key; a user file's missing keys keep UPD-24's)."""

    disk: Disk
    blade: BladeSection
    damper: DamperSection
    load: LoadSection
    geometry: GeometrySection

    @model_validator(mode="after")
    def _engine_order_fits(self):
        if self.disk.engine_order > self.disk.blades // 2:
            raise ValueError(f"disk.engine_order: {self.disk.engine_order} must lie in 0..blades/2 = "
                             f"{self.disk.blades // 2}")
        return self
