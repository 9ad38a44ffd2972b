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

Unknown keys are kept in ``extra`` and written back unchanged.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from contact_core.fileio import atomic_write, read_text_bounded

#: Schema tag written to every normal-curve file.
SCHEMA = "damper-normal-curve/1"
_KNOWN = ("schema", "approach", "N", "load", "k_n", "geometry", "materials", "provenance")


def check_normal_table(p: np.ndarray, N: np.ndarray) -> None:
    """Raise ValueError unless p, N start at (0, 0) and both strictly increase."""
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
    geometry, materials, provenance, extra : dict
    """

    approach: np.ndarray
    N: np.ndarray
    load: float | None = None
    k_n: np.ndarray | None = None
    geometry: dict = field(default_factory=dict)
    materials: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)

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
        return {**out, **self.extra}

    @classmethod
    def from_dict(cls, data: dict, source: str = "normal curve") -> NormalCurve:
        if data.get("schema") != SCHEMA:
            raise ValueError(f"{source}: not a {SCHEMA} file (schema {data.get('schema')!r})")
        try:
            return cls(data["approach"], data["N"], data.get("load"), data.get("k_n"),
                       data.get("geometry", {}), data.get("materials", {}),
                       data.get("provenance", {}),
                       {k: v for k, v in data.items() if k not in _KNOWN})
        except KeyError as err:
            raise ValueError(f"{source}: missing key {err.args[0]!r}") from None
        except ValueError as err:
            raise ValueError(f"{source}: {err}") from None

    @classmethod
    def from_result(cls, result: dict) -> NormalCurve:
        """The curve of a ``damper normal`` result (its ``curve``: forces from 5 % to
        100 % of the solved load), with first touch (0, 0) prepended."""
        curve = result.get("curve")
        if not curve or not curve.get("force"):
            raise ValueError("the normal solution has no F-approach curve (pass --curve N > 0)")
        p = np.concatenate([[0.0], curve["approach"]])
        N = np.concatenate([[0.0], curve["force"]])
        k_n = np.concatenate([[curve["k_n"][0]], curve["k_n"]])
        meta = result.get("meta", {})
        return cls(p, N, float(result["force"]), k_n, geometry=meta.get("spec", {}),
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
