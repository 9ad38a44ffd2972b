"""An underplatform damper between two platforms as an FMI 2.0 / 3.0 co-simulation FMU.

The damper body (planar: x_d, y_d, theta_d) with its mass and moment of inertia, the
centrifugal load CF on y_d and its contact points, each with a penalty normal law with
lift-off, a Masing/Iwan friction element whose slip strengths follow the normal load
(the C core) and dashpots: ``fmu_src/fmi/model_upd.c`` has the equations. This module
packages it from plain numbers (:class:`DamperSpec`); the rows of the contact
kinematics come from the UPD description (``harmonic_balance.bladed_disk``).

Variables: inputs ``q_left_x``, ``q_left_y``, ``v_left_x``, ``v_left_y`` (blade j's
platform point the damper touches: displacement [m] and velocity [m/s]) and the same
for ``right`` (blade j+1's); outputs ``F_<side>_<axis>`` [N] (force on that platform
point) with ``..._rate`` [N/s] (its secant over the last step: the first-order hold the
blade FMU applies over the next step), ``x_d``, ``y_d`` [m], ``theta_d`` [rad], the
normal load ``N_<contact>`` [N] of each contact, ``W_friction``, ``W_dashpots``,
``W_platforms`` (work of the platforms on the damper) and ``energy`` (kinetic +
contact springs + stored in the sliders - CF (y_d - y_d,0), relative to the start) [J];
parameter ``CF`` [N].
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fmu_src import fmu_build, fmu_xml

#: Fraction of the damper's own stability limit used as its largest substep (central
#: differences with dashpots: dt < 2 / w (sqrt(1 + z^2) - z)), as the ring time
#: integration's CFL.
SUBSTEP_CFL = 0.5
SIDES = ("left", "right")


@dataclass
class ContactSpec:
    """One contact point of the damper.

    Attributes
    ----------
    name : str
    side : int                  0: blade j's platform point (left), 1: blade j+1's (right)
    Qs, Qp : (5,) arrays        slip and penetration rows on [x_d, y_d, theta_d, P_u, P_v]
    kn, kt : float              normal penalty and stuck tangential stiffness [N/m]
    beta_c : float              dashpots beta_c kt, beta_c kn [s]
    s0 : float                  slip where the sliders are virgin (prestress) [m]
    k, fs : arrays              slider stiffnesses [N/m] and slip strengths at n_ref [N]
    k_res, n_ref, scale : float residual spring [N/m], reference load [N], friction scale
    """

    name: str
    side: int
    Qs: np.ndarray
    Qp: np.ndarray
    kn: float
    kt: float
    beta_c: float
    s0: float
    k: np.ndarray
    fs: np.ndarray
    k_res: float
    n_ref: float
    scale: float = 1.0


@dataclass
class DamperSpec:
    """The damper FMU's data: mass (m_d, I_d), CF, prestress state, contacts.

    Attributes
    ----------
    m_d, I_d : float            [kg], [kg m^2]
    cf : float                  centrifugal load [N]
    q0 : (3,) array             prestress position [m, m, rad]
    platforms0 : (2, 2) array   platform points (u, v) at the start, per side [m]
    contacts : list of ContactSpec
    """

    m_d: float
    I_d: float
    cf: float
    q0: np.ndarray
    platforms0: np.ndarray
    contacts: list = field(default_factory=list)

    def stuck_stiffness(self) -> np.ndarray:
        """Stiffness (3, 3) of the damper on its stuck contacts, platforms held [N/m]."""
        K = np.zeros((3, 3))
        for c in self.contacts:
            K += c.kt * np.outer(c.Qs[:3], c.Qs[:3]) + c.kn * np.outer(c.Qp[:3], c.Qp[:3])
        return K

    def omega_max(self) -> float:
        """Highest natural frequency [rad/s] of the damper on its stuck contacts with the
        platforms held: the frequency an explicit coupling across the contacts must
        resolve (the co-simulation's step rule) and the damper's own substep limit."""
        Minv = 1.0 / np.array([self.m_d, self.m_d, self.I_d])
        w2 = np.linalg.eigvals(np.sqrt(Minv)[:, None] * self.stuck_stiffness()
                               * np.sqrt(Minv)[None, :]).real
        return float(np.sqrt(max(w2.max(), 0.0)))

    def zeta_max(self) -> float:
        """Damping ratio of the contact dashpots at omega_max (beta_c omega / 2)."""
        beta = max((c.beta_c for c in self.contacts), default=0.0)
        return 0.5 * beta * self.omega_max()

    def substep(self) -> float:
        """Largest internal substep [s] (:data:`SUBSTEP_CFL` of the damped limit)."""
        w, z = self.omega_max(), self.zeta_max()
        if not w > 0:
            raise ValueError("damper: the contacts hold the damper with zero stiffness")
        return SUBSTEP_CFL * 2.0 / w * (np.sqrt(1.0 + z * z) - z)


def check_spec(d: DamperSpec) -> None:
    """Refuse what the damper FMU cannot represent (ValueError naming it)."""
    for label, v in (("m_d", d.m_d), ("I_d", d.I_d)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"damper {label} = {v} must be finite and > 0 (the damper FMU "
                             "integrates the damper with its mass)")
    if not (np.isfinite(d.cf) and d.cf >= 0):
        raise ValueError(f"damper CF = {d.cf} must be finite and >= 0")
    if not 1 <= len(d.contacts) <= 8:
        raise ValueError(f"damper needs 1..8 contacts, got {len(d.contacts)}")
    for c in d.contacts:
        arrays = [c.Qs, c.Qp, c.k, c.fs, [c.kn, c.kt, c.beta_c, c.s0, c.k_res, c.n_ref, c.scale]]
        if not all(np.all(np.isfinite(np.asarray(a, float))) for a in arrays):
            raise ValueError(f"damper contact {c.name}: non-finite number")
        if c.kn <= 0 or c.kt < 0 or c.beta_c < 0 or c.n_ref <= 0 or c.side not in (0, 1):
            raise ValueError(f"damper contact {c.name}: needs kn > 0, kt >= 0, beta_c >= 0, "
                             "n_ref > 0 and side 0 or 1")


def _num(x) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(np.asarray(x, dtype=float)).ravel())


def resource_text(d: DamperSpec) -> str:
    """Text of ``resources/upd.txt`` (read by model_upd.c)."""
    lines = ["damper-upd 1", f"mass {_num([d.m_d, d.m_d, d.I_d])}", f"dt_max {_num(d.substep())}",
             f"q0 {_num(d.q0)}", f"contacts {len(d.contacts)}"]
    for c in d.contacts:
        lines.append(f"contact {c.side} {_num(c.Qs[:3])} {_num(c.Qs[3:])} {_num(c.Qp[:3])} "
                     f"{_num(c.Qp[3:])} {_num([c.kn, c.kt, c.beta_c, c.s0])}")
        lines.append(f"law {len(c.k)} {_num([c.k_res, c.n_ref, c.scale])}")
        lines += [_num([k, f]) for k, f in zip(c.k, c.fs)]
    return "\n".join(lines) + "\n"


def _var(name, vr, causality, unit, description, value=0.0):
    start = "none" if causality == "output" else "value"
    var = "fixed" if causality == "parameter" else "continuous"
    return fmu_xml.Variable(name, vr, causality, var, unit, start, description, float(value))


def interface(d: DamperSpec, initial_forces: np.ndarray | None = None) -> fmu_xml.Interface:
    """The damper's variable table (names fixed; one normal-load output per contact)."""
    v = [fmu_xml.Variable("time", 0, "independent", "continuous", "s", "none", "Simulation time")]
    for j, side in enumerate(SIDES):
        who = "blade j" if j == 0 else "blade j+1"
        for k, axis in enumerate(("x", "y")):
            v.append(_var(f"q_{side}_{axis}", len(v), "input", "m",
                          f"Displacement {axis} of {who}'s platform point", d.platforms0[j][k]))
        for axis in ("x", "y"):
            v.append(_var(f"v_{side}_{axis}", len(v), "input", "m/s",
                          f"Velocity {axis} of {who}'s platform point"))
    for side in SIDES:
        for axis in ("x", "y"):
            v.append(_var(f"F_{side}_{axis}", len(v), "output", "N",
                          f"Force of the damper on the {side} platform point, {axis}"))
            v.append(_var(f"F_{side}_{axis}_rate", len(v), "output", "N/s",
                          f"Rate of F_{side}_{axis} over the last step (secant)"))
    for name, unit in (("x_d", "m"), ("y_d", "m"), ("theta_d", "rad")):
        v.append(_var(name, len(v), "output", unit, f"Damper {name}"))
    for c in d.contacts:
        v.append(_var(f"N_{c.name}", len(v), "output", "N", f"Normal load of contact {c.name}"))
    for name, desc in (("W_friction", "Energy dissipated by friction (cumulative)"),
                       ("W_dashpots", "Energy dissipated by the contact dashpots (cumulative)"),
                       ("W_platforms", "Work of the platforms on the damper (cumulative)"),
                       ("energy", "Energy of the damper and its contacts since the start")):
        v.append(_var(name, len(v), "output", "J", desc))
    v.append(_var("CF", len(v), "parameter", "N", "Centrifugal load on the damper (y_d)", d.cf))
    return fmu_xml.Interface("upd_damper", "damper underplatform damper", tuple(v),
                             fmu_xml.VALUE_START_RULES, "upd_vr.h", feedthrough=False,
                             directional=False, interpolates=False)


def build_damper_fmu(d: DamperSpec, out: str | os.PathLike, *, fmi_version: int = 2,
                     description: str = "", compiler: str | None = None) -> Path:
    """Write the damper FMU (atomically; nothing is written on a refused damper).

    Raises
    ------
    ValueError
        A damper the FMU cannot represent (:func:`check_spec`).
    """
    check_spec(d)
    doc = ("<html><body><h1>damper underplatform damper</h1><p>A rigid planar damper with its "
           "mass between two platform points: penalty normal law with lift-off, a "
           "Masing/Iwan friction element per contact whose slip strengths follow the normal "
           "load, dashpots; integrated by central differences in substeps below its own "
           f"stability limit ({d.substep():.3g} s). Platform inputs are taken as straight "
           "lines (value + velocity) over a step; the force outputs come with their secant "
           "rate. Outputs are states (no direct feedthrough).</p></body></html>\n")
    return fmu_build.package_fmu(out, fmi_version, "upd", interface(d),
                                 {"upd.txt": resource_text(d)}, description=description,
                                 documentation=doc, compiler=compiler)
