"""The UPD ring as a system of FMUs in an SSP 1.0 archive (``damper system``).

A tuned engine-order response needs only N_r = N_b / gcd(N_b, EO) blades closed in a
ring (4 for UPD-24 at EO 6): blade j is forced by F0 cos(Omega t + j phi), phi =
2 pi EO / N_b, and damper j sits between blade j's ``left`` platform point and blade
j+1's ``right`` one. The archive holds one blade FMU (:mod:`fmu_src.blade_fmu`, its
``blade_index`` set per component) and one damper FMU (:mod:`fmu_src.upd_fmu`), both
from :mod:`harmonic_balance.bladed_disk.fmus` (the HB's matrices, kinematics and laws,
starting in the frictionless prestress at the given CF), wired as::

    damper j  <- blade j:     q_left_{x,y}, v_left_{x,y}   (its left platform point)
    damper j  <- blade j+1:   q_right_{x,y}, v_right_{x,y} (its right platform point)
    blade j   <- damper j:    F_left_{x,y} and their rates
    blade j   <- damper j-1:  F_right_{x,y} and their rates
    blade j   <- blade j+-1:  q_/v_{next,prev}_<coupling DOF> (the rim coupling)

Step rule. The exchange is explicit (Jacobi: every FMU steps from the others' outputs
at the step's start, each with a first-order hold). Across a contact of stiffness k
between bodies of mass m this is stable only for h < ~2 / sqrt(k / m); here the
stiffest such mode is the damper on its stuck contacts with the platforms held, of
frequency omega_max (``DamperSpec.omega_max``: stuck k_t, k_n against m_d, I_d), so the
coupling limit is h_max = 2 / omega_max (7.4e-6 s for UPD-24) and the default step is
:data:`STEP_FRACTION` of it (accuracy, not stability, sets the fraction: see
``damper cosim``). ``resources/system.json`` records both and what ``damper cosim``
needs (components, response connector, loads).
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from damper.ring_info import RingInfo
from damper.ssp import Component, ssd_text, write_ssp

#: Default communication step as a fraction of the coupling limit 2 / omega_max.
STEP_FRACTION = 0.125


def coupling_limit(damper) -> float:
    """h_max = 2 / omega_max [s]: the explicit coupling's stability limit (module docstring)."""
    return 2.0 / damper.omega_max()


def _coupling_block(spec) -> list:
    """K_next on the coupling DOFs (rows: blade j, columns: blade j+1) [N/m]."""
    c = spec.coupling_dofs()
    if spec.K_next is None or not c:
        return []
    return np.asarray(spec.K_next, dtype=float)[np.ix_(c, c)].tolist()


def _components(cfg, blade_itf, damper_itf, f0, frequency_hz):
    nr = cfg.ring_blades
    b_con = {v.name: v.causality for v in blade_itf.variables if v.causality != "independent"}
    d_con = {v.name: v.causality for v in damper_itf.variables if v.causality != "independent"}
    comps = []
    for j in range(nr):
        comps.append(Component(f"blade{j}", "blade.fmu", dict(b_con),
                               {"blade_index": j, "interblade_phase": cfg.phi, "F0": f0,
                                "frequency": frequency_hz}))
    comps += [Component(f"damper{j}", "damper.fmu", dict(d_con)) for j in range(nr)]
    return comps


def _connections(nr: int, spec) -> list[tuple]:
    """Ring wiring (module docstring) for blade DOF names of ``spec`` (BladeSpec)."""
    names = spec.dofs
    left = [names[i] for i in spec.points["left"]]
    right = [names[i] for i in spec.points["right"]]
    con = []
    for j in range(nr):
        nxt, prv = (j + 1) % nr, (j - 1) % nr
        for axis, dl, dr in zip(("x", "y"), left, right):
            con += [(f"blade{j}", f"q_{dl}", f"damper{j}", f"q_left_{axis}"),
                    (f"blade{j}", f"v_{dl}", f"damper{j}", f"v_left_{axis}"),
                    (f"blade{nxt}", f"q_{dr}", f"damper{j}", f"q_right_{axis}"),
                    (f"blade{nxt}", f"v_{dr}", f"damper{j}", f"v_right_{axis}")]
            for kind in ("", "_rate"):
                con += [(f"damper{j}", f"F_left_{axis}{kind}", f"blade{j}", f"F_left_{axis}{kind}"),
                        (f"damper{prv}", f"F_right_{axis}{kind}", f"blade{j}",
                         f"F_right_{axis}{kind}")]
        for d in spec.coupling_dofs():
            name = names[d]
            for kind in ("q", "v"):
                con += [(f"blade{nxt}", f"{kind}_{name}", f"blade{j}", f"{kind}_next_{name}"),
                        (f"blade{prv}", f"{kind}_{name}", f"blade{j}", f"{kind}_prev_{name}")]
    return con


def build_ring(cfg, cf: float, f0: float, out, fmi_version: int = 2,
               frequency_hz: float | None = None, config_name: str = "UPD-24") -> dict:
    """Write the ring's SSP archive to ``out`` (atomic; nothing written on bad input).

    Parameters
    ----------
    cfg : UPDConfig
    cf, f0 : float               centrifugal load and EO force amplitude [N] (> 0)
    out : path                   the ``.ssp`` file
    fmi_version : {2, 3}         of the FMUs (libcosim runs FMI 2 only)
    frequency_hz : float         default excitation frequency (``damper cosim`` sets its own)

    Returns
    -------
    dict: the archive's ``system.json`` (and ``path``).

    Raises
    ------
    ValueError
        A blade or damper the FMUs cannot represent, bad loads.
    """
    from fmu_src.blade_fmu import build_blade_fmu
    from fmu_src.blade_fmu import interface as blade_interface
    from fmu_src.upd_fmu import build_damper_fmu
    from fmu_src.upd_fmu import interface as damper_interface
    from harmonic_balance.bladed_disk import fmus
    from harmonic_balance.bladed_disk.sector import Sector

    for label, v in (("--cf", cf), ("--f0", f0)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{label} must be finite and > 0, got {v}")
    sector = Sector(cfg)
    band = cfg["load.band_hz"]
    freq = float(frequency_hz if frequency_hz is not None else 0.5 * (band[0] + band[1]))
    st = fmus.statics(sector, cf)
    bspec, dspec = fmus.blade_spec(sector, cf, st), fmus.damper_spec(sector, cf, st)
    h_max = coupling_limit(dspec)
    step = STEP_FRACTION * h_max
    nr = cfg.ring_blades
    b_itf = blade_interface(bspec, f0, freq, 0.0, cfg.phi)[0]
    comps = _components(cfg, b_itf, damper_interface(dspec), f0, freq)
    response = f"q_{bspec.dofs[bspec.response]}"
    info = {"kind": "damper-ring", "config": config_name, "blades": cfg.blades,
            "engine_order": cfg.engine_order, "ring_blades": nr, "interblade_phase": cfg.phi,
            "cf": cf, "f0": f0, "frequency_hz": freq, "fmi_version": fmi_version,
            "omega_max": dspec.omega_max(), "step_limit": h_max, "default_step": step,
            "step_fraction": STEP_FRACTION, "damper_substep": dspec.substep(),
            "blades_components": [f"blade{j}" for j in range(nr)],
            "damper_components": [f"damper{j}" for j in range(nr)],
            "response": response, "response_dof": bspec.dofs[bspec.response],
            "contacts": [c.name for c in dspec.contacts],
            # the ring's coupling energy sum_j q_j^T K_next q_(j+1) (on these DOFs) closes
            # the energy balance of a transient
            "coupling_dofs": [bspec.dofs[d] for d in bspec.coupling_dofs()],
            "K_next_coupling": _coupling_block(bspec)}
    RingInfo.model_validate(info)   # what damper cosim will read back (no archive it would refuse)
    ssd = ssd_text("upd_ring", comps, _connections(nr, bspec), step, 100.0 / freq,
                   f"{config_name}: {nr} blades of {cfg.blades} (EO {cfg.engine_order}) "
                   f"with underplatform dampers, CF {cf} N, F0 {f0} N")
    with tempfile.TemporaryDirectory(prefix="damper_ssp_") as tmp:
        tmp = Path(tmp)
        build_blade_fmu(bspec, tmp / "blade.fmu", F0=f0, frequency=freq, phase=cfg.phi,
                        fmi_version=fmi_version, description=f"{config_name} blade")
        build_damper_fmu(dspec, tmp / "damper.fmu", fmi_version=fmi_version,
                         description=f"{config_name} underplatform damper at CF {cf} N")
        path = write_ssp(out, ssd, {"blade.fmu": tmp / "blade.fmu", "damper.fmu": tmp / "damper.fmu",
                                    "system.json": json.dumps(info, indent=1)})
    return info | {"path": str(path)}
