"""The elements file's tables, keys, types and ranges (typed, :mod:`contact_core.fileformat`).

One description of ``elements.toml`` (the format and an example of each element type
are in :mod:`harmonic_balance.model`): ``[[element]]`` tables, each of one ``type``
(``jenkins`` when omitted) with that type's keys only. What needs the model (a DOF
inside it, the curve file's content) is checked when the elements are built.
"""
from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from contact_core.fileformat import FileModel

#: Largest magnitude of an element parameter [SI]: the harmonic balance squares forces
#: and displacements, which overflows double precision near 1e154.
MAX_PARAMETER = 1e100
#: Most DOFs a model may number (a DOF index above it is a typo).
MAX_DOF = 100_000_000

Positive = Annotated[float, Field(gt=0.0, le=MAX_PARAMETER)]
NonNegative = Annotated[float, Field(ge=0.0, le=MAX_PARAMETER)]
Real = Annotated[float, Field(ge=-MAX_PARAMETER, le=MAX_PARAMETER)]
Dof = Annotated[int, Field(ge=0, le=MAX_DOF)]
Link = Annotated[list[Dof], Field(min_length=1, max_length=2)]
Vector = Annotated[list[Real], Field(min_length=1, max_length=3)]   # k = 1, 2 or 3 components


class Jenkins(FileModel):
    type: Literal["jenkins"] = Field("jenkins", description="spring k in series with a slider of strength fs "
                                     "(the type of a table without one)")
    name: str | None = Field(None, description="label in the output")
    dofs: Link = Field(description="[a] (to the ground) or [a, b]: u = x_a - x_b")
    k: Positive = Field(description="stiffness [N/m]")
    fs: Positive = Field(description="slip force [N]")


class Sliders(FileModel):
    type: Literal["sliders"] = Field(description="Iwan parallel sliders at the reference normal load")
    name: str | None = Field(None, description="label in the output")
    dofs: Link = Field(description="[a] (to the ground) or [a, b]: u = x_a - x_b")
    k: Annotated[list[Positive], Field(min_length=1, max_length=100_000)] = Field(description="[N/m] each")
    fs: Annotated[list[Positive], Field(min_length=1, max_length=100_000)] = Field(description="[N] each")
    k_res: NonNegative = Field(0.0, description="residual stiffness [N/m]")

    @model_validator(mode="after")
    def _equal_lengths(self):
        if len(self.k) != len(self.fs):
            raise ValueError(f"k and fs: {len(self.k)} and {len(self.fs)} values (one each per slider)")
        return self


class Curve(FileModel):
    type: Literal["curve"] = Field(description="a virgin curve file (contact_core.curve)")
    name: str | None = Field(None, description="label in the output")
    dofs: Link = Field(description="[a] (to the ground) or [a, b]: u = x_a - x_b")
    path: Annotated[str, Field(min_length=1)] = Field(description="curve JSON, relative to the .toml file")
    fit: Literal["reject", "concave"] = Field("reject", description="a non-concave curve: refused or its "
                                              "least concave majorant")
    scale: Positive = Field(1.0, description="friction scale on every slip strength")


class Contact(FileModel):
    type: Literal["contact"] = Field(description="penalty normal with lift-off + friction following N")
    name: str | None = Field(None, description="label in the output")
    dofs: Annotated[list[Dof], Field(min_length=1, max_length=6)] = Field(
        description="DOFs of the contact point's relative displacement")
    normal: Vector = Field(description="unit normal from body 2 into body 1")
    tangent: Vector | Annotated[list[Vector], Field(min_length=1, max_length=2)] | None = Field(
        None, description="unit tangent(s); omit for normal only")
    delta: Annotated[list[Annotated[list[Real], Field(min_length=1, max_length=6)]],
                     Field(min_length=1, max_length=3)] | None = Field(
        None, description="(k, len(dofs)): Delta = delta @ x[dofs] (default identity)")
    k_n: Positive = Field(description="normal penalty stiffness [N/m]")
    k_t: Positive | None = Field(None, description="Jenkins friction stiffness [N/m] (with mu)")
    mu: Annotated[float, Field(ge=0.0, le=100.0)] | None = Field(None, description="friction coefficient")
    curve: Annotated[str, Field(min_length=1)] | None = Field(None, description="curve JSON instead of k_t, mu")
    fit: Literal["reject", "concave"] | None = Field(None, description="with curve: as a curve element's")
    scale: Positive | None = Field(None, description="with curve: friction scale on every slip strength")
    preload: Real = Field(0.0, description="static penetration at x = 0 [m]")
    slip_ref: Real | Annotated[list[Real], Field(min_length=1, max_length=2)] = Field(
        0.0, description="prestress slip where the sliders are virgin [m]")
    beta_c: NonNegative = Field(0.0, description="contact dashpots beta_c k [s]")


Element = Annotated[Jenkins | Sliders | Curve | Contact, Field(discriminator="type")]


class ElementsFile(FileModel):
    """``elements.toml``: one ``[[element]]`` table per force element."""

    element: Annotated[list[Element], Field(min_length=1, max_length=10_000)] = Field(
        description="the force elements")

    @model_validator(mode="before")
    @classmethod
    def _jenkins_by_default(cls, data):
        """A table without ``type`` is a Jenkins element (the documented default)."""
        if isinstance(data, dict) and isinstance(data.get("element"), list):
            data = dict(data, element=[dict(t, type=t.get("type", "jenkins")) if isinstance(t, dict) else t
                                       for t in data["element"]])
        return data
