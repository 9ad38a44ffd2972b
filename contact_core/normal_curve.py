"""The normal approach curve: a contact's normal load against its approach, as plain data.

N(p) [N] is the normal load of a contact pressed to the approach p [m] (the
penetration of the contact-point element, positive pressed) from first touch, where
p = N = 0. ``damper normal --normal-curve FILE`` writes it from the FE solution (the
F-approach curve up to the solved load, with (0, 0) first); the contact-point FMU
(``damper fmu --normal FILE``) reads it as its normal law, beyond the last point with
the last slope.

File format (JSON, ``schema`` = ``SCHEMA``)::

    {
      "schema": "damper-normal-curve/1",
      "approach": [0.0, ...],   # m, strictly increasing from 0
      "N": [0.0, ...],          # N, strictly increasing from 0 (monotone)
      "load": 200.0,            # the load the curve was computed up to [N] (optional;
                                # default: its last N)
      "k_n": [...],             # dN/dp at each point [N/m] (optional)
      "geometry": {...}, "materials": {...}, "provenance": {...}   # optional
    }

The file is typed (:class:`NormalCurveFile`): JSON numbers (not strings, not
booleans), finite and within the curve file's bounds (``contact_core.curve``:
:data:`~contact_core.curve.MAX_DISPLACEMENT`, :data:`~contact_core.curve.MAX_FORCE`,
:data:`~contact_core.curve.MAX_STIFFNESS`); an unknown key is refused.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field

from contact_core.curve import MAX_DISPLACEMENT, MAX_FORCE, MAX_STIFFNESS
from contact_core.fileformat import FileModel, parse
from contact_core.fileio import atomic_write, read_text_bounded

#: Schema tag written to every normal-curve file.
SCHEMA = "damper-normal-curve/1"


class NormalCurveFile(FileModel):
    """The normal-curve file's keys and types (module docstring); the table's own rules
    (from (0, 0), both strictly increasing) are :func:`check_normal_table`'s."""

    schema_: Literal["damper-normal-curve/1"] = Field(alias="schema", description="format tag")
    approach: list[Annotated[float, Field(ge=-MAX_DISPLACEMENT, le=MAX_DISPLACEMENT)]] = Field(
        description="approach p [m], strictly increasing from 0")
    N: list[Annotated[float, Field(ge=-MAX_FORCE, le=MAX_FORCE)]] = Field(
        description="normal load [N], strictly increasing from 0")
    load: Annotated[float, Field(gt=0.0, le=MAX_FORCE)] | None = Field(
        None, description="the load the curve was computed up to [N] (default: the last N)")
    k_n: list[Annotated[float, Field(ge=-MAX_STIFFNESS, le=MAX_STIFFNESS)]] | None = Field(
        None, description="dN/dp at each point [N/m]")
    geometry: dict[str, Any] = Field(default_factory=dict, description="descriptive")
    materials: dict[str, Any] = Field(default_factory=dict, description="descriptive")
    provenance: dict[str, Any] = Field(default_factory=dict, description="code version, date, command")


def check_normal_table(p: np.ndarray, N: np.ndarray) -> None:
    """Raise ValueError unless p, N start at (0, 0) and both strictly increase, with no
    segment stiffer than :data:`~contact_core.curve.MAX_STIFFNESS`."""
    if p.ndim != 1 or p.shape != N.shape or p.size < 2:
        raise ValueError(f"normal curve: approach and N must be 1-D of equal length >= 2, "
                         f"got {p.shape} and {N.shape}")
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(N))):
        raise ValueError("normal curve: approach and N must be finite")
    if p[0] != 0.0 or N[0] != 0.0:
        raise ValueError(f"normal curve: must start at (0, 0) (first touch), got ({p[0]}, {N[0]})")
    for name, x in (("approach", p), ("N", N)):
        bad = np.flatnonzero(np.diff(x) <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise ValueError(f"normal curve: {name} must increase strictly (a monotone curve, no "
                             f"negative approach); point {i} has {name} = {x[i]!r} after {x[i - 1]!r}")
    slope = np.diff(N) / np.diff(p)
    i = int(np.argmax(slope))
    if slope[i] > MAX_STIFFNESS:  # a unit error: p scaled by 1e-300 gave 1e308 N/m
        raise ValueError(f"normal curve: points {i}-{i + 1}: a stiffness of {float(slope[i]):.3g} N/m, above "
                         f"{MAX_STIFFNESS:g} N/m (a steel contact's is ~1e8-1e10): approach in metres, N in newtons?")


@dataclass(frozen=True)
class NormalCurve:
    """A validated normal approach curve.

    Attributes
    ----------
    approach, N : ndarray, shape (m,)
        Approach p [m] and normal load [N], from (0, 0), both strictly increasing.
    load : float
        The load the curve was computed up to [N] (default N[-1]).
    k_n : ndarray or None
        Normal stiffness dN/dp at each point [N/m].
    geometry, materials, provenance : dict
    """

    approach: np.ndarray
    N: np.ndarray
    load: float | None = None
    k_n: np.ndarray | None = None
    geometry: dict = field(default_factory=dict)
    materials: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)

    def __post_init__(self):
        p, N = np.array(self.approach, dtype=float), np.array(self.N, dtype=float)
        check_normal_table(p, N)
        for a in (p, N):
            a.setflags(write=False)
        object.__setattr__(self, "approach", p)
        object.__setattr__(self, "N", N)
        load = float(N[-1]) if self.load is None else float(self.load)
        if not (math.isfinite(load) and load > 0):
            raise ValueError(f"normal curve: load must be finite and > 0, got {self.load!r}")
        object.__setattr__(self, "load", load)
        if self.k_n is not None:
            object.__setattr__(self, "k_n", np.array(self.k_n, dtype=float))

    def to_dict(self) -> dict:
        out = {"schema": SCHEMA, "approach": self.approach.tolist(), "N": self.N.tolist(),
               "load": self.load}
        if self.k_n is not None:
            out["k_n"] = self.k_n.tolist()
        for name in ("geometry", "materials", "provenance"):
            if getattr(self, name):
                out[name] = getattr(self, name)
        return out

    @classmethod
    def from_dict(cls, data: dict, source: str = "normal curve") -> NormalCurve:
        """Validate a JSON object (:class:`NormalCurveFile`) and build the curve; ValueError
        names the file and the key."""
        if not isinstance(data, dict) or data.get("schema") != SCHEMA:
            got = data.get("schema") if isinstance(data, dict) else type(data).__name__
            raise ValueError(f"{source}: not a {SCHEMA} file (schema {got!r})")
        f = parse(NormalCurveFile, data, source)
        try:
            return cls(f.approach, f.N, f.load, f.k_n, f.geometry, f.materials, f.provenance)
        except ValueError as err:
            raise ValueError(f"{source}: {err}") from None

    @classmethod
    def from_result(cls, result: dict) -> NormalCurve:
        """The curve of a ``damper normal`` result (its ``curve``: forces from 5 % to
        100 % of the solved load), with first touch (0, 0) prepended."""
        curve = result.get("curve")
        if not curve or not curve.get("force"):
            raise ValueError("the normal solution has no F-approach curve (pass --curve N > 0)")
        load = float(result["force"])
        if not abs(curve["force"][-1] - load) <= 1e-9 * load:  # one point was 5 % of the load only
            raise ValueError(f"the F-approach curve ends at {curve['force'][-1]:.4g} N, not at the load {load:.4g} N: "
                             "a normal law up to the load needs a curve to it (--curve 2 or more)")
        p = np.concatenate([[0.0], curve["approach"]])
        N = np.concatenate([[0.0], curve["force"]])
        k_n = np.concatenate([[curve["k_n"][0]], curve["k_n"]])
        meta = result.get("meta", {})
        return cls(p, N, load, k_n, geometry=meta.get("spec", {}),
                   provenance={"command": "damper normal"})


def read_normal_curve(path: str | Path) -> NormalCurve:
    """Read and validate a normal-curve JSON file (ValueError with the path on bad content)."""
    path = Path(path)
    try:
        data = json.loads(read_text_bounded(path, what="normal-curve file"))
    except json.JSONDecodeError as err:
        raise ValueError(f"{path}: not JSON ({err})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file (a normal curve is JSON)") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: not a {SCHEMA} file")
    return NormalCurve.from_dict(data, str(path))


def write_normal_curve(curve: NormalCurve, path: str | Path) -> Path:
    """Write ``curve`` as JSON (atomically)."""
    return atomic_write(path, json.dumps(curve.to_dict(), indent=1) + "\n")
