"""The UPD sector's blade and damper as FMU descriptions (the co-simulated ring's parts).

From the same :class:`~.sector.Sector` the harmonic balance uses (the blade's matrices
and named DOFs, the damper's mass, the contact rows ``Sector.Q`` and their laws) this
module fills :class:`fmu_src.blade_fmu.BladeSpec` and :class:`fmu_src.upd_fmu.DamperSpec`,
so the FMUs carry the HB's kinematics and laws exactly:

* blade: M, K, C = the blade's (C = beta K by default), K_next, C_next to its
  neighbours; platform points ``left`` / ``right``, forced and response DOFs;
* damper: m_d, I_d, CF on y_d, each contact's rows of slip and penetration on
  [x_d, y_d, theta_d, P_u, P_v] (P: blade j's ``left`` point or blade j+1's ``right``),
  k_n, its friction element (Jenkins k_t, mu N, or the contact's own Iwan element),
  beta_c, and the slip s_0 of the frictionless prestress where the sliders are virgin.

Both start at rest in the frictionless (mu = 0) prestress state under CF (the HB's and
the ring time integration's convention, :func:`harmonic_balance.contact.frictionless_statics`):
the blade at its static displacement with the static contact forces on its platform
points, the damper at its static position.
"""
from __future__ import annotations

import numpy as np

from fmu_src.blade_fmu import BladeSpec
from fmu_src.upd_fmu import ContactSpec, DamperSpec

from ..contact import frictionless_statics
from .hb import sector_model
from .sector import Sector


def planar(sector: Sector) -> None:
    """Refuse a sector the FMUs cannot represent: the damper FMU's contacts slip in the
    plane only (one tangent each), so a blade with an axial platform DOF is refused."""
    if sector.rows_per_point != 2:
        raise ValueError("the blade's platform points carry an axial DOF (left/right = [u, v, w]): "
                         "the damper FMU slips in the plane only; name two DOFs [u, v] per point "
                         "for damper system")


def statics(sector: Sector, cf: float) -> dict:
    """Frictionless prestress of the tuned sector under CF [N] (every blade alike).

    Returns
    -------
    dict: q (n_dof,) static displacements, P_left / P_right (2,) the platform points' (u, v)
    [m], and per contact s0 (slip), p0 (penetration) [m].
    """
    planar(sector)
    model = sector_model(sector, cf, sector.cfg.f0, sector.cfg.mu)
    x, _ = frictionless_statics(model)
    b = sector.blade
    P_left, P_right = x[list(b.left)], x[list(b.right)]
    q_ext = np.concatenate([x, P_right])  # blade j+1's right point: the same in statics
    return {"q": x, "P_left": P_left, "P_right": P_right,
            "s0": sector.Q[1::2] @ q_ext, "p0": sector.Q[0::2] @ q_ext}


def _rows(sector: Sector, i: int) -> tuple[np.ndarray, np.ndarray]:
    """Slip and penetration rows (5,) of contact i on [x_d, y_d, theta_d, P_u, P_v]."""
    n, b, c = sector.n_blade, sector.blade, sector.points[i]
    cols = [n, n + 1, n + 2] + ([n + 3, n + 4] if c.neighbour else list(b.left))
    Qp, Qs = sector.Q[2 * i], sector.Q[2 * i + 1]
    return Qs[cols].copy(), Qp[cols].copy()


def damper_spec(sector: Sector, cf: float, st: dict | None = None) -> DamperSpec:
    """The damper FMU's description at CF [N] (prestress ``st`` from :func:`statics`)."""
    st = statics(sector, cf) if st is None else st
    d = sector.cfg.data["damper"]
    n = sector.n_blade
    contacts = []
    for i, c in enumerate(sector.points):
        Qs, Qp = _rows(sector, i)
        if c.friction is None:  # Jenkins point: k_t, slip force mu N (N_ref = 1)
            k, fs, k_res, n_ref, scale = [c.kt], [sector.cfg.mu], 0.0, 1.0, 1.0
        else:
            f = c.friction
            k, fs, k_res, n_ref, scale = f.k, f.fs, f.k_res, f.N_ref, f.scale
        contacts.append(ContactSpec(c.name, int(c.neighbour), Qs, Qp, float(c.kn), float(c.kt),
                                    float(sector.beta_c), float(st["s0"][i]),
                                    np.asarray(k, float), np.asarray(fs, float), float(k_res),
                                    float(n_ref), float(scale)))
    return DamperSpec(float(d["m_d"]), float(d["I_d"]), float(cf), st["q"][n:n + 3].copy(),
                      np.array([st["P_left"], st["P_right"]]), contacts)


def platform_forces(sector: Sector, st: dict) -> dict:
    """Static forces [N] of the dampers on blade j's ``left`` and ``right`` points: the
    normal loads k_n p0 of the frictionless prestress (the sliders carry nothing there)."""
    out = {"left": np.zeros(2), "right": np.zeros(2)}
    for i, c in enumerate(sector.points):
        _, Qp = _rows(sector, i)
        N = c.kn * max(st["p0"][i], 0.0)
        out["right" if c.neighbour else "left"] -= Qp[3:] * N
    return out


def blade_spec(sector: Sector, cf: float, st: dict | None = None) -> BladeSpec:
    """The blade FMU's description at CF [N] (prestress ``st`` from :func:`statics`)."""
    st = statics(sector, cf) if st is None else st
    b = sector.blade
    C, C_next = b.damping_parts(sector.beta)
    q0 = st["q"][:b.n].copy()
    return BladeSpec(b.M, b.K, C, b.K_next, C_next, tuple(b.dofs),
                     {"left": tuple(b.left), "right": tuple(b.right)}, int(b.forced),
                     int(b.response), q0, platform_forces(sector, st), q0)
