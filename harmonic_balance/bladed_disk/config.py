"""Configuration of a bladed disk with underplatform dampers (UPD), read from TOML.

The bundled default ``upd24.toml`` ("UPD-24") documents every key with its unit
(SI). A user file may give any subset of the keys; the others keep the default.

Symbols (used in the whole subpackage)
--------------------------------------
N_b blades, EO engine order, phi = 2 pi EO / N_b interblade phase [rad];
g face angle [rad]; k_n, k_t normal / tangential contact stiffness of a contact
point [N/m]; mu friction coefficient; CF centrifugal load on the damper [N];
F0 amplitude of the EO force on the blade's forced DOF (u_a of UPD-24) [N]; beta,
beta_c structural and contact stiffness-proportional damping [s].

The ``[blade]`` section is either UPD-24's lumped keys or a blade of reduced matrices
(``file`` / Matrix Market keys, :mod:`.blade`); relative paths are taken from the
TOML file's directory (resolved by :func:`load_config`). The keys, types and ranges
are :class:`.config_model.UPDFile`'s (strict: no booleans or strings as numbers, finite
numbers, unknown keys refused, the key's path in every message).
"""
from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass
from math import gcd
from pathlib import Path

import numpy as np

from contact_core.fileformat import parse
from contact_core.fileio import read_text_bounded

from .blade import MATRICES, Blade, load_blade
from .config_model import UPDFile

#: The bundled default model.
DEFAULT_CONFIG = Path(__file__).with_name("upd24.toml")


@dataclass
class ContactPoint:
    """One contact point of the damper (body-fixed, small rotation).

    Attributes
    ----------
    name : str
    r : (2,) array     position from the damper's centre of mass G [m]
    n : (2,) array     unit normal: force direction on the damper
    t : (2,) array     unit tangent
    kn, kt : float     normal and tangential stiffness [N/m]
    neighbour : bool   True when the point touches blade j+1's platform
    friction : IwanElement or None
        Tangential element of this point (slip strengths scale with N / N_ref), e.g.
        from a ``contact_core`` virgin curve; None: a Jenkins element k_t, mu N.
        With it, ``kt`` is its stuck stiffness (used by the linear stuck limit).
    """

    name: str
    r: np.ndarray
    n: np.ndarray
    t: np.ndarray
    kn: float
    kt: float
    neighbour: bool
    friction: object = None


@dataclass
class UPDConfig:
    """Numbers of a UPD bladed-disk model (SI units); see ``upd24.toml``.

    ``contacts`` optionally replaces the TOML's contact laws per point name
    ("left", "right1", "right2"): ``{"kn": float, "friction": IwanElement}`` (either
    key may be missing). It carries computed data (e.g. ``contact_core`` virgin
    curves), not TOML keys, and is kept by :meth:`with_values`. ``source`` names the
    file in messages.
    """

    data: dict
    contacts: dict | None = None
    source: str = "config"

    # ------------------------------------------------------------ access
    def blade(self) -> Blade:
        """The sector's blade (:mod:`.blade`), read once per config."""
        if getattr(self, "_blade", None) is None:
            self._blade = load_blade(self.data["blade"])
        return self._blade

    def __getitem__(self, key: str):
        section, _, name = key.partition(".")
        return self.data[section][name]

    @property
    def blades(self) -> int:
        return int(self["disk.blades"])

    @property
    def engine_order(self) -> int:
        return int(self["disk.engine_order"])

    @property
    def phi(self) -> float:
        """Interblade phase 2 pi EO / N_b [rad]."""
        return 2.0 * np.pi * self.engine_order / self.blades

    @property
    def ring_blades(self) -> int:
        """N_r = N_b / gcd(N_b, EO): the shortest ring that carries the EO pattern."""
        return self.blades // gcd(self.blades, self.engine_order)

    @property
    def cf(self) -> float:
        return float(self["load.cf"])

    @property
    def f0(self) -> float:
        return float(self["load.f0"])

    @property
    def mu(self) -> float:
        return float(self["damper.mu"])

    def with_values(self, **changes) -> UPDConfig:
        """Copy with ``section__key=value`` changes, e.g. ``load__cf=60``."""
        data = copy.deepcopy(self.data)
        for k, v in changes.items():
            sec, _, name = k.partition("__")
            data[sec][name] = v
        out = UPDConfig(data, self.contacts, self.source)
        if data["blade"] == self.data["blade"]:
            out._blade = getattr(self, "_blade", None)
        out.validate()
        return out

    def contact_points(self) -> list[ContactPoint]:
        """The cylinder line on blade j and the flat's two end points on blade j+1.

        Normals and tangents of the face angle g (x towards blade j+1, y outward):
        left n = (sin g, -cos g), t = (cos g, sin g); right n = (-sin g, -cos g),
        t = (cos g, -sin g). The flat's end points sit at its centre -/+ width / 2
        along t_R, each with half the flat's stiffness.
        """
        d = self.data["damper"]
        g = np.radians(float(d["angle_deg"]))
        s, c = np.sin(g), np.cos(g)
        kn = float(d["kn_per_length"]) * float(d["contact_length"])
        kt = float(d["kt_ratio"]) * kn
        nL, tL = np.array([s, -c]), np.array([c, s])
        nR, tR = np.array([-s, -c]), np.array([c, -s])
        rc = np.asarray(d["right_centre"], dtype=float)
        half = 0.5 * float(d["right_width"])
        pts = [ContactPoint("left", np.asarray(d["left_point"], float), nL, tL, kn, kt, False),
               ContactPoint("right1", rc - half * tR, nR, tR, kn / 2, kt / 2, True),
               ContactPoint("right2", rc + half * tR, nR, tR, kn / 2, kt / 2, True)]
        for c in pts:
            over = (self.contacts or {}).get(c.name, {})
            c.kn = float(over.get("kn", c.kn))
            if over.get("friction") is not None:
                c.friction = over["friction"]
                c.kt = float(np.sum(c.friction.k) + c.friction.k_res)
        return pts

    # ------------------------------------------------------------ checks
    def validate(self) -> None:
        """Raise ValueError with a message naming the key when a value is unusable."""
        for name, over in (self.contacts or {}).items():
            if name not in ("left", "right1", "right2") or set(over) - {"kn", "friction"}:
                raise ValueError(f"contact override {name}: {sorted(over)} (points left, right1, "
                                 "right2; keys kn, friction)")
            kn = over.get("kn", 1.0)
            if not (np.isfinite(kn) and kn > 0):
                raise ValueError(f"contact override {name}: kn = {kn} must be finite and > 0")
        parse(UPDFile, self.data, self.source)   # keys, types, ranges (config_model)
        self.blade()  # the blade's matrices and DOF names (ValueError naming the problem)


def load_config(path=None) -> UPDConfig:
    """Read a UPD config; keys missing from ``path`` keep the UPD-24 defaults.

    Parameters
    ----------
    path : str or Path, optional
        TOML file; None gives the bundled UPD-24.

    Raises
    ------
    ValueError
        Unreadable file, unknown section or key, or an unusable value.
    """
    data = tomllib.loads(DEFAULT_CONFIG.read_text())
    if path is not None:
        path = Path(path)
        try:
            user = tomllib.loads(read_text_bounded(path, what="config"))
        except OSError as err:
            raise ValueError(f"cannot read config {path}: {err.strerror}" if err.strerror else str(err)) from None
        except (UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
            raise ValueError(f"cannot read config {path} (TOML): {err}") from None
        for sec, table in user.items():   # unknown sections and keys: UPDFile refuses them
            if isinstance(data.get(sec), dict) and isinstance(table, dict):
                data[sec].update(table)
            else:
                data[sec] = table
        for k in ("file",) + MATRICES:  # blade files relative to the TOML's directory
            if (isinstance(data["blade"], dict) and isinstance(data["blade"].get(k), str)
                    and data["blade"][k] and isinstance(user.get("blade"), dict) and k in user["blade"]):
                data["blade"][k] = str(path.parent / data["blade"][k])
    cfg = UPDConfig(data, source=str(path) if path is not None else "config")
    cfg.validate()
    return cfg
