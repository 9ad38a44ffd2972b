"""The virgin curve: a contact's tangential force-displacement curve as plain data.

The virgin curve T(u) is the tangential force T [N] of a contact loaded
monotonically from zero, against the rigid tangential displacement u [m] of the
distant faces, at a fixed normal load N [N] and friction coefficient mu [-].
Its initial slope is the tangential contact stiffness k_t [N/m]; a computed
curve ends at gross slip, T = mu N. Later stages (the hysteresis element, the
FMU, harmonic balance) read it.

File format (JSON, ``schema`` = ``SCHEMA``)::

    {
      "schema": "damper-virgin-curve/2",
      "u": [0.0, ...],          # m, strictly increasing, u[0] = 0
      "T": [0.0, ...],          # N, T[0] = 0, finite, non-negative
      "tail": "flat",           # beyond u[-1]: "flat" (T stays T[-1]: gross slip) or
                                # "slope" (the last segment's slope continues)
      "N": 200.0,               # normal load [N] (optional)
      "mu": 0.5,                # friction coefficient (optional)
      "k_t": 1.2e8,             # initial tangential stiffness [N/m] (optional)
      "k_n": 3.4e8,             # normal contact stiffness at N [N/m] (optional)
      "load_case": "CNF",       # CNF (constant normal force) or CND (optional)
      "geometry": {...}, "materials": {...}, "grid": {...},   # optional
      "provenance": {"code_version": "...", "date": "...", "command": "..."}
    }

Only ``u`` and ``T`` (and, in version 2, ``tail``) are required, so a
hand-made table works too. The file is typed (:class:`CurveFile`): numbers are JSON
numbers (not strings, not booleans), finite and within :data:`MAX_DISPLACEMENT`,
:data:`MAX_FORCE`, :data:`MAX_STIFFNESS` and :data:`MAX_MU`; an unknown key is
refused. A file that states mu > 0 and N must agree with them: no T above mu N (by more
than :data:`MU_N_RTOL`), the gross-slip force the curve cannot exceed.

Version 1 files (``"damper-virgin-curve/1"`` or no ``schema`` key) carry no tail:
it is decided once, here, by one rule (:func:`_v1_tail`):
flat when mu and N are declared and T[-1] = mu N to ``V1_GROSS_SLIP_RTOL``, else
slope. Version 2 files state it, written by the producer that knows it
(``contact_core.tangential_curve.to_virgin_curve``: flat, the curve ends at gross slip).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from contact_core.fileformat import FileModel, parse
from contact_core.fileio import atomic_write, read_text_bounded

#: Schema tag written to every curve file.
SCHEMA = "damper-virgin-curve/2"
#: Older schema still read (no ``tail`` key: :func:`_v1_tail` decides it).
SCHEMA_V1 = "damper-virgin-curve/1"
#: What the curve does beyond its last point (see the module docstring).
TAILS = ("flat", "slope")
#: Version 1 only: a curve ends at gross slip when T[-1] = mu N to this relative
#: tolerance (the file stores mu N rounded; the flat tail's force is T[-1] itself).
V1_GROSS_SLIP_RTOL = 1e-6
#: Largest |u| of a curve file [m]: a contact's tangential displacement to gross slip is
#: micrometres; a metre is a unit error.
MAX_DISPLACEMENT = 1.0
#: Largest |T| and N of a curve file [N]: far above any contact of a machine (1 GN), far
#: below where the harmonic balance's squares of forces overflow (~1e154).
MAX_FORCE = 1e9
#: Largest stiffness k_t, k_n of a curve file, and slope of its table [N/m] (a steel
#: contact is ~1e8-1e9).
MAX_STIFFNESS = 1e16
#: Largest friction coefficient: dry contacts have mu below a few; beyond 100 it is a typo.
MAX_MU = 100.0
#: T may exceed the stated mu N by this fraction of mu N: a computed curve ends at gross
#: slip to its step tolerance (``tangential_curve.CURVE_TOL`` = 1e-3 of mu N) and the
#: file stores mu and N rounded; a plateau at 3 mu N (a wrong mu or N) is far beyond it.
MU_N_RTOL = 1e-2
_KNOWN_SCALARS = ("N", "mu", "k_t", "k_n")
_KNOWN_TEXT = ("load_case",)
_KNOWN_DICTS = ("geometry", "materials", "grid", "provenance")


@dataclass(frozen=True)
class VirginCurve:
    """A validated virgin curve.

    Attributes
    ----------
    u : ndarray, shape (m,)
        Tangential displacement [m], strictly increasing, ``u[0] = 0``.
    T : ndarray, shape (m,)
        Tangential force [N], ``T[0] = 0``, non-negative.
    N, mu, k_t, k_n : float or None
        Normal load [N], friction coefficient [-], initial tangential and
        normal contact stiffness [N/m].
    load_case : str or None
        ``"CNF"`` or ``"CND"``.
    tail : {"slope", "flat"}
        Beyond ``u[-1]``: the last slope continues, or T stays at ``T[-1]`` (gross
        slip). A producer whose curve ends at gross slip says ``"flat"``.
    geometry, materials, grid, provenance : dict
        Descriptive metadata, written back unchanged.
    """

    u: np.ndarray
    T: np.ndarray
    N: float | None = None
    mu: float | None = None
    k_t: float | None = None
    k_n: float | None = None
    load_case: str | None = None
    tail: str = "slope"
    geometry: dict = field(default_factory=dict)
    materials: dict = field(default_factory=dict)
    grid: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)

    def __post_init__(self):
        u = np.array(self.u, dtype=float)
        T = np.array(self.T, dtype=float)
        check_table(u, T)
        check_slopes(u, T)
        u.setflags(write=False)
        T.setflags(write=False)
        object.__setattr__(self, "u", u)
        object.__setattr__(self, "T", T)
        for name in _KNOWN_SCALARS:
            value = getattr(self, name)
            if value is not None:
                value = float(value)
                if not math.isfinite(value):
                    raise ValueError(f"curve: {name} must be finite, got {value}")
                object.__setattr__(self, name, value)
        if self.N is not None and self.N <= 0:
            raise ValueError(f"curve: normal load N must be > 0, got {self.N}")
        if self.mu is not None and self.mu < 0:
            raise ValueError(f"curve: friction coefficient mu must be >= 0, got {self.mu}")
        if self.tail not in TAILS:
            raise ValueError(f"curve: tail must be one of {TAILS}, got {self.tail!r}")
        if self.load_case not in (None, "CNF", "CND"):
            raise ValueError(f"curve: load_case must be CNF or CND, got {self.load_case!r}")

    def to_dict(self) -> dict:
        """The file's JSON object (plain Python types)."""
        out = {"schema": SCHEMA, "u": self.u.tolist(), "T": self.T.tolist(), "tail": self.tail}
        for name in _KNOWN_SCALARS + _KNOWN_TEXT:
            if getattr(self, name) is not None:
                out[name] = getattr(self, name)
        for name in _KNOWN_DICTS:
            if getattr(self, name):
                out[name] = getattr(self, name)
        return out

    @classmethod
    def from_dict(cls, data: dict, source: str = "curve") -> VirginCurve:
        """Validate a JSON object and build the curve; ValueError names what is wrong."""
        if not isinstance(data, dict):
            raise ValueError(f"{source}: expected a JSON object, got {type(data).__name__}")
        schema = data.get("schema", SCHEMA_V1)   # schema-less tables predate version 2
        if not str(schema).startswith("damper-virgin-curve/"):
            raise ValueError(f"{source}: unknown schema {schema!r} (expected {SCHEMA!r})")
        if schema not in (SCHEMA, SCHEMA_V1):
            raise ValueError(f"{source}: schema {schema!r} is newer than this code reads ({SCHEMA!r})")
        if schema == SCHEMA and data.get("tail") not in TAILS:
            raise ValueError(f"{source}: schema {SCHEMA!r} needs \"tail\": one of {TAILS}, "
                             f"got {data.get('tail')!r}")
        fields = parse(CurveFile, data, source)
        kwargs = {"u": fields.u, "T": fields.T}
        for name in _KNOWN_SCALARS + _KNOWN_TEXT + _KNOWN_DICTS:
            if getattr(fields, name) not in (None, {}):
                kwargs[name] = getattr(fields, name)
        try:
            if schema == SCHEMA:
                kwargs["tail"] = data["tail"]
            else:
                kwargs["tail"] = _v1_tail(cls(**kwargs))
            return cls(**kwargs)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{source}: {err}") from None


_Displacement = Annotated[float, Field(ge=-MAX_DISPLACEMENT, le=MAX_DISPLACEMENT)]
_Force = Annotated[float, Field(ge=-MAX_FORCE, le=MAX_FORCE)]
_Stiffness = Annotated[float, Field(ge=0.0, le=MAX_STIFFNESS)]


class CurveFile(FileModel):
    """The curve file's keys and types (module docstring). The table's own rules (start
    at (0, 0), u increasing, T non-negative) are :func:`check_table`'s."""

    schema_: Literal["damper-virgin-curve/2", "damper-virgin-curve/1"] = Field(
        SCHEMA_V1, alias="schema", description="format tag; version 1 (or none) has no tail")
    u: list[_Displacement] = Field(description="tangential displacement [m], strictly increasing from 0",
                                   json_schema_extra={"why": "a contact slips within micrometres: metres "
                                                      "are a unit error"})
    T: list[_Force] = Field(description="tangential force [N] from 0, non-negative, at most mu N",
                            json_schema_extra={"why": "1 GN is far above any contact of a machine"})
    tail: Literal["flat", "slope"] | None = Field(
        None, description="beyond the last point: flat (gross slip) or the last slope (version 2: required)")
    N: Annotated[float, Field(gt=0.0, le=MAX_FORCE)] | None = Field(None, description="normal load [N]")
    mu: Annotated[float, Field(ge=0.0, le=MAX_MU)] | None = Field(None, description="friction coefficient")
    k_t: _Stiffness | None = Field(None, description="initial tangential stiffness [N/m]")
    k_n: _Stiffness | None = Field(None, description="normal contact stiffness at N [N/m]")
    load_case: Literal["CNF", "CND"] | None = Field(None, description="constant normal force or displacement")
    geometry: dict[str, Any] = Field(default_factory=dict, description="descriptive (body, sizes)")
    materials: dict[str, Any] = Field(default_factory=dict, description="descriptive (E, nu)")
    grid: dict[str, Any] = Field(default_factory=dict, description="descriptive (FE grid)")
    provenance: dict[str, Any] = Field(default_factory=dict, description="code version, date, command")

    @model_validator(mode="after")
    def _within_gross_slip(self):
        """No T above the gross-slip force mu N the file states (to :data:`MU_N_RTOL`); mu = 0
        states no friction law (as for the version 1 tail, :func:`_v1_tail`)."""
        if self.mu and self.N is not None and self.T:
            bound = self.mu * self.N
            i = int(np.argmax(self.T))
            if self.T[i] > bound + MU_N_RTOL * bound:
                raise ValueError(f"T[{i}] = {self.T[i]:.6g} N is above mu N = {self.mu:g} x {self.N:g} "
                                 f"= {bound:.6g} N (by more than {MU_N_RTOL:.0%}): the curve contradicts "
                                 "its own mu and N; correct mu, N or the table")
        return self


def _v1_tail(curve: VirginCurve) -> str:
    """Tail of a version 1 curve (the only place it is inferred): "flat" when
    mu and N are declared and T[-1] = mu N to ``V1_GROSS_SLIP_RTOL``, else "slope"."""
    mu, N = curve.mu, curve.N
    if mu is None or N is None or not mu > 0.0:
        return "slope"
    return "flat" if abs(float(curve.T[-1]) - mu * N) <= V1_GROSS_SLIP_RTOL * mu * N else "slope"


def check_table(u: np.ndarray, T: np.ndarray) -> None:
    """Raise ValueError unless (u, T) is a usable virgin-curve table.

    The one check of a table's basic rules (shape, at least 2 points, finite, starts at
    (0, 0), u strictly increasing, T non-negative), used by the curve file and by the
    friction element (``fmu_src.curve_fit.check_table`` adds the element's own rules).
    The message names the rule and the first point (0-based index) that breaks it.

    Parameters
    ----------
    u, T : ndarray, shape (m,)
        Displacement [m] and force [N].
    """
    if u.ndim != 1 or T.ndim != 1 or u.size != T.size:
        raise ValueError(f"curve: u and T must be 1-D of equal length, got shapes {u.shape}, {T.shape}"
                         + (" (they differ in length)" if u.size != T.size else ""))
    if u.size < 2:
        raise ValueError(f"curve: {'empty' if u.size == 0 else 'one point'}; "
                         "a virgin curve needs at least 2 points")
    for name, x in (("u", u), ("T", T)):
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise ValueError(f"curve: point {bad[0]}: {name} = {float(x[bad[0]])} is not finite")
    if u[0] != 0.0 or T[0] != 0.0:
        raise ValueError(f"curve: point 0 is ({float(u[0])!r}, {float(T[0])!r}); a virgin curve starts at (0, 0)")
    bad = np.flatnonzero(np.diff(u) <= 0.0)
    if bad.size:
        i = int(bad[0]) + 1
        raise ValueError(f"curve: point {i}: u = {float(u[i])!r} is not above u[{i - 1}] = {float(u[i - 1])!r} "
                         "(u must be strictly increasing)")
    bad = np.flatnonzero(T < 0.0)
    if bad.size:
        raise ValueError(f"curve: point {bad[0]}: T = {float(T[bad[0]])!r} is negative (T must be non-negative)")


def check_slopes(u: np.ndarray, T: np.ndarray) -> None:
    """Raise ValueError when a segment of a checked table (SI units) is steeper than
    :data:`MAX_STIFFNESS`: a unit error (u scaled by 1e-300 gave slopes of 6e307 N/m and an
    element whose input bound was 1e-297 m). The element itself takes any units."""
    slope = np.abs(np.diff(T)) / np.diff(u)
    i = int(np.argmax(slope))
    if slope[i] > MAX_STIFFNESS:
        raise ValueError(f"curve: points {i}-{i + 1}: a slope of {float(slope[i]):.3g} N/m, above {MAX_STIFFNESS:g} "
                         "N/m (a steel contact's stiffness is ~1e8-1e9): u in metres, T in newtons?")


def read_curve(path: str | Path) -> VirginCurve:
    """Read and validate a curve file.

    Raises
    ------
    ValueError
        Malformed, truncated or invalid file (the message names the file and
        the problem).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    try:
        text = read_text_bounded(path, what="curve file")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file (a curve file is JSON)") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise ValueError(f"{path}: not valid JSON (truncated?): {err}") from None
    return VirginCurve.from_dict(data, source=str(path))


def write_curve(curve: VirginCurve, path: str | Path) -> Path:
    """Write ``curve`` to ``path`` (JSON; all or nothing)."""
    text = json.dumps(curve.to_dict(), indent=1, allow_nan=False)
    return atomic_write(path, text + "\n")
