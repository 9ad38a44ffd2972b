"""A linear reduced blade as an FMI 2.0 / 3.0 co-simulation FMU, integrated exactly.

The blade ``M q'' + C q' + K q = f`` (n DOFs, M symmetric positive definite, K and C
symmetric) is diagonalised here, at build time, in its first-order form (z = [q, q']):
``A z' = B z + [f, 0]``, ``A = [[C, M], [M, 0]]``, ``B = [[-K, 0], [0, M]]``,
``A^-1 B = V diag(lambda) V^-1``; the C model (``fmu_src/fmi/model_blade.c``) advances
the modal coordinates eta = V^-1 z over each communication step in closed form with a
first-order hold of its inputs and the exact engine-order excitation, so any step size
gives the exact solution of that input path and the blade imposes no step limit.

Inputs, per communication step held as straight lines x + x_rate (s - t):

* interface forces: ``F_<point>_x``, ``F_<point>_y`` [N] on each platform point's
  (u, v) DOFs (UPD: ``left`` and ``right``), with ``..._rate`` [N/s];
* the neighbours' coupling DOFs (those K_next or C_next touch):
  ``q_next_<dof>``, ``v_next_<dof>`` of blade j+1 and ``q_prev_<dof>``,
  ``v_prev_<dof>`` of blade j-1 [m, m/s]; the force on blade j is
  ``-(K_next q_(j+1) + C_next q'_(j+1)) - (K_next^T q_(j-1) + C_next^T q'_(j-1))``
  with q_(j+-1)(s) = q + v (s - t) (so its rate is -K_next v).

Outputs ``q_<dof>``, ``v_<dof>`` [m, m/s] of the platform points, the response and
the coupling DOFs, and the energies [J]: ``W_excitation`` (work of the EO force),
``W_interface`` (of the interface forces), ``W_neighbours_stiffness`` and
``W_neighbours_damping`` (of the coupling forces' K_next and C_next parts),
``W_damping`` (dissipated by C: the balance of the others and ``energy``), ``energy``
(q'^T M q' + q^T K q) / 2. Over a ring in a periodic state the neighbours' stiffness
works sum to zero and their damping works to minus the dissipation of C_next.
Parameters: ``F0`` [N], ``frequency`` [Hz], ``blade_index`` and ``interblade_phase``
[rad]: the EO force
``F0 cos(2 pi frequency t + blade_index interblade_phase)`` on the forced DOF.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from fmu_src import fmu_build, fmu_xml

#: Largest condition number of the eigenvector matrix V accepted: beyond it the modal
#: coordinates lose more than ~1e-6 of the state to round-off (a nearly defective
#: system: repeated eigenvalues with one eigenvector, e.g. rigid-body modes).
MAX_COND_V = 1e10
#: Relative asymmetry accepted in M, K, C (round-off of a reduction T^T A T).
SYM_RTOL = 1e-8
#: Names of the energy outputs, in the order model_blade.c expects them last.
ENERGY_OUTPUTS = (
    ("W_excitation", "J", "Work of the engine-order force (cumulative)"),
    ("W_damping", "J", "Energy dissipated by the blade's damping C (cumulative)"),
    ("W_interface", "J", "Work of the interface forces on the blade (cumulative)"),
    ("W_neighbours_stiffness", "J", "Work of the neighbours' K_next coupling forces (cumulative)"),
    ("W_neighbours_damping", "J", "Work of the neighbours' C_next coupling forces (cumulative)"),
    ("energy", "J", "Mechanical energy (q'^T M q' + q^T K q) / 2"),
)
#: Work groups of the inputs (resource blocks work_<group>_value / _rate, in this order).
GROUPS = ("interface", "stiffness", "damping")
AXES = ("x", "y")


@dataclass
class BladeSpec:
    """What the blade FMU is built from (shapes (n, n); indices into 0..n-1).

    Attributes
    ----------
    M, K : arrays; C : array (viscous damping); K_next, C_next : arrays or None
    dofs : sequence of str (n)      DOF names
    points : dict name -> (iu, iv)  platform points receiving interface forces
    forced, response : int          DOF of the EO force and the response output
    q0 : (n,) array                 initial displacement (at rest) [m]
    f_points : dict name -> (2,)    start values of the interface forces [N]
    q_neighbour : (n,) array        start displacement of the neighbours [m]
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    K_next: np.ndarray | None
    C_next: np.ndarray | None
    dofs: tuple
    points: dict
    forced: int
    response: int
    q0: np.ndarray
    f_points: dict
    q_neighbour: np.ndarray

    @property
    def n(self) -> int:
        return self.M.shape[0]

    def coupling_dofs(self) -> list[int]:
        """DOFs K_next or C_next touch (rows or columns), ascending."""
        used = np.zeros(self.n, dtype=bool)
        for A in (self.K_next, self.C_next):
            if A is not None:
                used |= np.any(A != 0.0, axis=0) | np.any(A != 0.0, axis=1)
        return [int(i) for i in np.flatnonzero(used)]

    def output_dofs(self) -> list[int]:
        """Platform points, response, coupling DOFs (each once, in that order)."""
        out = []
        for d in [i for p in self.points.values() for i in p] + [self.response] \
                + self.coupling_dofs():
            if d not in out:
                out.append(int(d))
        return out


def check_spec(b: BladeSpec) -> None:
    """Refuse what the modal integrator cannot represent (ValueError naming it)."""
    n = b.n
    for name in ("M", "K", "C", "K_next", "C_next"):
        A = getattr(b, name)
        if A is None:
            continue
        A = np.asarray(A, dtype=float)
        if A.shape != (n, n) or not np.all(np.isfinite(A)):
            raise ValueError(f"blade {name} must be a finite {n} x {n} matrix, got {A.shape}")
        if name in ("M", "K", "C") and np.abs(A - A.T).max() > SYM_RTOL * max(np.abs(A).max(), 1e-300):
            raise ValueError(f"blade {name} is not symmetric")
    try:
        np.linalg.cholesky(b.M)
    except np.linalg.LinAlgError:
        raise ValueError("blade M is not symmetric positive definite: the blade FMU needs "
                         "a mass on every DOF") from None
    if len(b.dofs) != n:
        raise ValueError(f"blade has {n} DOFs but {len(b.dofs)} names")
    for name, p in b.points.items():
        if len(p) != 2 or not all(0 <= int(i) < n for i in p):
            raise ValueError(f"platform point {name} must name two DOFs of the blade, got {p}")
    for role in ("forced", "response"):
        if not 0 <= int(getattr(b, role)) < n:
            raise ValueError(f"blade {role} DOF {getattr(b, role)} is not a DOF of the blade")


def modal_data(b: BladeSpec) -> dict:
    """lambda (m,), V (m, m), G = V^-1 A^-1 [I; 0] (m, n) of the first-order system.

    Raises
    ------
    ValueError
        V too ill-conditioned (:data:`MAX_COND_V`): a (nearly) defective system.
    """
    n = b.n
    Z = np.zeros((n, n))
    A = np.block([[b.C, b.M], [b.M, Z]])
    B = np.block([[-b.K, Z], [Z, b.M]])
    lam, V = sla.eig(np.linalg.solve(A, B))
    cond = np.linalg.cond(V)
    if not np.isfinite(cond) or cond > MAX_COND_V:
        raise ValueError(f"the blade's first-order system is (nearly) defective (cond(V) = "
                         f"{cond:.3g} > {MAX_COND_V:g}): rigid-body modes or repeated critically "
                         "damped modes cannot be integrated modally; ground them (K positive "
                         "definite) or change the damping")
    G = np.linalg.solve(V, np.linalg.solve(A, np.vstack([np.eye(n), Z])))
    return {"lambda": lam, "V": V, "G": G}


def _var(name, vr, causality, unit, description, value=None, variability=None):
    start = "none" if causality == "output" else "value"
    var = variability or ("fixed" if causality == "parameter" else "continuous")
    return fmu_xml.Variable(name, vr, causality, var, unit, start, description,
                            0.0 if value is None else float(value))


def interface(b: BladeSpec, F0: float, frequency: float, blade_index: float,
              phase: float) -> tuple[fmu_xml.Interface, dict]:
    """The blade's variable table and, per input, its force maps.

    Returns
    -------
    interface : fmu_xml.Interface
    maps : dict with, per work group of :data:`GROUPS`, ``(value, rate)`` (n, n_in): the
        generalized force of each input at the step start and its rate; ``outputs`` list
        of (dof, kind) per kinematic output
    """
    rows = []
    n = b.n
    parts = {g: ([], []) for g in GROUPS}
    zero = np.zeros(n)

    def add_input(name, unit, desc, value, groups):
        rows.append((name, unit, desc, value))
        for g in GROUPS:
            fv, fr = groups.get(g, (zero, zero))
            parts[g][0].append(fv)
            parts[g][1].append(fr)

    for point, dofs in b.points.items():
        f = np.asarray(b.f_points.get(point, (0.0, 0.0)), dtype=float)
        for k, (axis, d) in enumerate(zip(AXES, dofs)):
            e = np.zeros(n)
            e[d] = 1.0
            add_input(f"F_{point}_{axis}", "N", f"Force on the {point} platform point, "
                      f"{axis} ({b.dofs[d]})", f[k], {"interface": (e, zero)})
            add_input(f"F_{point}_{axis}_rate", "N/s", f"Rate of F_{point}_{axis} over the "
                      "step", 0.0, {"interface": (zero, e)})
    Kn = np.zeros((n, n)) if b.K_next is None else np.asarray(b.K_next, float)
    Cn = np.zeros((n, n)) if b.C_next is None else np.asarray(b.C_next, float)
    for side, Kc, Cc in (("next", Kn, Cn), ("prev", Kn.T, Cn.T)):
        blade = "j+1" if side == "next" else "j-1"
        for d in b.coupling_dofs():
            name = b.dofs[d]
            add_input(f"q_{side}_{name}", "m", f"Displacement {name} of blade {blade}",
                      b.q_neighbour[d], {"stiffness": (-Kc[:, d], zero)})
            add_input(f"v_{side}_{name}", "m/s", f"Velocity {name} of blade {blade}", 0.0,
                      {"stiffness": (zero, -Kc[:, d]), "damping": (-Cc[:, d], zero)})
    variables = [fmu_xml.Variable("time", 0, "independent", "continuous", "s", "none",
                                  "Simulation time")]
    for name, unit, desc, value in rows:
        variables.append(_var(name, len(variables), "input", unit, desc, value))
    outputs = []
    for d in b.output_dofs():
        for kind, unit in (("q", "m"), ("v", "m/s")):
            what = "Displacement" if kind == "q" else "Velocity"
            variables.append(_var(f"{kind}_{b.dofs[d]}", len(variables), "output", unit,
                                  f"{what} of DOF {b.dofs[d]}"))
            outputs.append((d, kind))
    for name, unit, desc in ENERGY_OUTPUTS:
        variables.append(_var(name, len(variables), "output", unit, desc))
    for name, unit, desc, value in (
            ("F0", "N", "Amplitude of the engine-order force on the forced DOF", F0),
            ("frequency", "Hz", "Frequency of the engine-order force", frequency),
            ("blade_index", "1", "Index j of this blade in the ring", blade_index),
            ("interblade_phase", "rad", "Phase step 2 pi EO / N_b between neighbours", phase)):
        variables.append(_var(name, len(variables), "parameter", unit, desc, value))
    names = [fmu_xml.c_name(v.name) for v in variables]
    if len(set(names)) != len(names):
        raise ValueError("blade DOF names collide once made C identifiers (letters, digits, _): "
                         "rename the DOFs")
    itf = fmu_xml.Interface("blade", "damper linear blade", tuple(variables),
                            fmu_xml.VALUE_START_RULES, "blade_vr.h", feedthrough=False,
                            directional=False, interpolates=False)
    maps = {g: (np.array(v).T, np.array(r).T) for g, (v, r) in parts.items()}
    maps["outputs"] = outputs
    return itf, maps


def _block(name: str, A) -> str:
    A = np.atleast_1d(np.asarray(A, dtype=complex)).ravel()
    return name + "\n" + "\n".join(f"{float(z.real)!r} {float(z.imag)!r}" for z in A) + "\n"


def resource_text(b: BladeSpec, itf: fmu_xml.Interface, maps: dict, modal: dict) -> str:
    """Text of ``resources/blade.txt`` (read by model_blade.c)."""
    n = b.n
    lam, V, G = modal["lambda"], modal["V"], modal["G"]
    m = lam.size
    Vq = V[:n]
    rows = np.array([V[d] if kind == "q" else V[n + d] for d, kind in maps["outputs"]])
    Lv = sum(maps[g][0] for g in GROUPS)
    Lr = sum(maps[g][1] for g in GROUPS)
    work = "".join(_block(f"work_{g}_value", maps[g][0].T @ Vq)
                   + _block(f"work_{g}_rate", maps[g][1].T @ Vq) for g in GROUPS)
    S = V.conj().T @ sla.block_diag(b.K, b.M) @ V
    eta0 = np.linalg.solve(V, np.concatenate([np.asarray(b.q0, float), np.zeros(n)]))
    n_in = len(itf.by_causality("input"))
    text = (f"damper-blade 1\nmodes {m}\ninputs {n_in}\noutputs {len(maps['outputs'])}\n"
            + _block("lambda", lam) + _block("eta0", eta0)
            + _block("value_map", G @ Lv) + _block("rate_map", G @ Lr)
            + _block("excitation", G[:, b.forced]) + _block("outputs", rows)
            + _block("forced", Vq[b.forced]) + work + _block("energy", S))
    return text


def build_blade_fmu(b: BladeSpec, out: str | os.PathLike, *, F0: float, frequency: float,
                    blade_index: float = 0.0, phase: float = 0.0, fmi_version: int = 2,
                    description: str = "", compiler: str | None = None) -> Path:
    """Write the blade FMU (atomically; nothing is written on a refused blade).

    Raises
    ------
    ValueError
        A blade the FMU cannot represent (:func:`check_spec`, :func:`modal_data`) or
        non-finite excitation parameters.
    """
    for label, v in (("F0", F0), ("frequency", frequency), ("blade_index", blade_index),
                     ("interblade_phase", phase)):
        if not np.isfinite(v):
            raise ValueError(f"blade FMU: {label} = {v} must be finite")
    if frequency < 0:
        raise ValueError(f"blade FMU: frequency = {frequency} must be >= 0")
    check_spec(b)
    modal = modal_data(b)
    itf, maps = interface(b, F0, frequency, blade_index, phase)
    doc = ("<html><body><h1>damper linear blade</h1><p>A linear reduced blade (M, K, C) "
           "integrated exactly between communication points by its complex modal "
           "decomposition, with a first-order hold of the inputs (value and rate) and the "
           "exact engine-order force F0 cos(2 pi frequency t + blade_index "
           "interblade_phase): any step size gives the exact solution of that input path. "
           "Outputs are states (no direct feedthrough).</p></body></html>\n")
    return fmu_build.package_fmu(out, fmi_version, "blade", itf,
                                 {"blade.txt": resource_text(b, itf, maps, modal)},
                                 description=description, documentation=doc,
                                 compiler=compiler)
