"""From a contact specification to a virgin curve: condense, normal solve, tangential solve.

Load cases (thesis section 2.3.2):

* CNF, constant normal force N: the normal problem is solved in force control
  and its nodal forces are held while the tangential load grows.
* CND, constant normal displacement: the normal problem is solved at the given
  approach and the approach is held. As in the thesis (Appendix A.2.1), normal
  and tangential problems are decoupled (exact for like materials), so holding
  the approach holds the nodal normal forces too: the CND curve equals the CNF
  curve at the normal force the approach produces. What differs between the
  cases is which quantity is prescribed (and so N and mu N, compare thesis
  Fig. 29 with Fig. 33).

Models: ``"real"`` and ``"halfspace"`` are the FE bodies of
``contact_core.condense``; ``"bem"`` is the half-space influence-coefficient
model of ``contact_core.halfspace_bem`` on the same zone and grid.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from contact_core import halfspace_bem, normal
from contact_core.curve import VirginCurve
from contact_core.spec import ContactSpec
from contact_core.tangential import TangentialProblem
from contact_core.tangential_curve import CURVE_TOL, TangentialPath, to_virgin_curve, virgin_curve

MODELS = ("real", "halfspace", "bem")
#: Fewer full-model contact nodes than this cannot carry a stick/slip pattern:
#: refused (ValueError) rather than returned as a number.
MIN_CONTACT_NODES = 4
#: Fewer grid nodes across the contact than this: the curve is returned with
#: a warning (k_t is then typically several per cent off; 3 nodes per side
#: gave +8 % on the sphere, and below ROUGH_NODES_ACROSS tens of per cent: the bem
#: model at grid 3, 2.5 nodes across, +31 %).
WARN_NODES_ACROSS = 7
ROUGH_NODES_ACROSS = 3


@dataclass(frozen=True)
class TangentialRun:
    """Everything computed for one virgin curve.

    Attributes
    ----------
    spec : ContactSpec
    model : str
    load_case : {"CNF", "CND"}
    contact : CondensedContact
    normal : NormalSolution
    problem : TangentialProblem
    virgin : TangentialPath
    curve : VirginCurve
    k_n : float
        Normal contact stiffness dN/d(approach) at the normal state [N/m].
    timings : dict
        Seconds per stage.
    warnings : list of str
        Doubts about the result (a contact resolved by few nodes).
    """

    spec: ContactSpec
    model: str
    load_case: str
    contact: object
    normal: object
    problem: TangentialProblem
    virgin: TangentialPath
    curve: VirginCurve
    k_n: float
    timings: dict
    warnings: list


def build_contact(spec: ContactSpec, model: str = "real", cache=None, progress=None):
    """Condensed normal and tangential compliance of ``spec`` with ``model`` (``progress``:
    see ``contact_core.condense.condense``; the BEM model does not report)."""
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
    if model == "bem":
        return halfspace_bem.condense(replace(spec, model="halfspace"), ("z", "x"))
    from contact_core import condense

    return condense.condense(replace(spec, model=model), directions=("z", "x"), cache=cache,
                             progress=progress)


def solve_normal(contact, force: float | None = None, approach: float | None = None,
                 eccentricity: float | None = None):
    """Normal state for CNF (``force`` [N]; flat face: and ``eccentricity`` [m]) or CND
    (``approach`` [m]); returns (solution, load case)."""
    if (force is None) == (approach is None):
        raise ValueError("give exactly one of a normal force (CNF) or an approach (CND)")
    if eccentricity is not None and (force is None or contact.rigid.shape[1] < 2):
        raise ValueError("an eccentricity needs a normal force on a flat face")
    if force is not None:
        return normal.solve_force(contact, float(force), eccentricity), "CNF"
    approach = float(approach)
    if not (np.isfinite(approach) and approach > 0):
        raise ValueError(f"approach must be positive and finite, got {approach!r}")
    sol = normal.solve_displacement(contact, approach)
    if not np.any(sol.f > 0):
        raise ValueError(f"approach {approach:.3g} m closes no gap: no contact")
    return sol, "CND"


def run(spec: ContactSpec, mu: float, *, force: float | None = None, approach: float | None = None,
        eccentricity: float | None = None, model: str = "real", cache=None, tol: float = CURVE_TOL,
        command: str | None = None, progress=None) -> TangentialRun:
    """Condense, solve the normal problem, and compute the virgin curve to gross slip.

    Parameters
    ----------
    spec : ContactSpec
        Bodies, materials, grid.
    mu : float
        Friction coefficient (> 0).
    force, approach : float
        Exactly one: normal force [N] (CNF) or approach [m] (CND).
    eccentricity : float, optional
        Flat face in CNF: x position of the normal resultant [m].
    model : {"real", "halfspace", "bem"}
    cache : see ``contact_core.condense.condense``
    tol : float
        Step control of the curve (``contact_core.tangential_curve.CURVE_TOL``).
    command : str, optional
        Command line for the file's provenance.
    progress : callable(done, total, label), optional
        Called per FE step of the condensation and per load step of the march
        (``tangential_curve.march``); None: no calls.
    """
    mu = _check_mu(mu)
    t0 = time.perf_counter()
    contact = build_contact(spec, model, cache, progress)
    t1 = time.perf_counter()
    nsol, load_case = solve_normal(contact, force, approach, eccentricity)
    k_n = float(normal.tangent(contact, nsol.active)[0, 0])
    t2 = time.perf_counter()
    problem = TangentialProblem(contact, nsol.f, mu)
    warnings = check_resolution(contact, nsol.f)
    path = virgin_curve(problem, tol, progress)
    t3 = time.perf_counter()
    curve = to_virgin_curve(path, problem, load_case=load_case, k_n=k_n,
                            geometry=_geometry(spec, model), materials=_materials(spec),
                            grid=_grid_info(spec, contact, problem), command=command)
    timings = {"condense": t1 - t0, "normal": t2 - t1, "tangential": t3 - t2,
               "condense_stages": contact.meta.get("timings", {})}
    return TangentialRun(spec, model, load_case, contact, nsol, problem, path, curve, k_n, timings,
                         warnings)


def check_resolution(contact, f_n) -> list:
    """Refuse a contact on too few nodes; warn when it spans few nodes across.

    Counts full-model nodes (``grid.copies``, symmetry images) in contact; the
    nodes across are those of a disc of that many nodes, sqrt(4 n / pi).
    """
    grid = contact.grid
    copies = grid.copies if grid.copies is not None else np.ones(grid.n)
    n_full = int(np.sum(np.asarray(copies)[np.asarray(f_n) > 0]))
    hint = "refine --grid or lower --p-design (the potential zone is sized for that peak pressure)"
    if n_full < MIN_CONTACT_NODES:
        raise ValueError(f"the contact covers only {n_full} grid node(s): too few for a "
                         f"tangential stick/slip solution; {hint}")
    across = float(np.sqrt(4.0 * n_full / np.pi))
    if across < WARN_NODES_ACROSS:
        return [f"the contact spans only ~{across:.1f} grid nodes across ({n_full} nodes): "
                f"k_t and the curve may be {'tens of' if across < ROUGH_NODES_ACROSS else 'several'} per cent "
                f"off; {hint}"]
    return []


def _check_mu(mu) -> float:
    mu = float(mu)
    if not np.isfinite(mu) or mu <= 0:
        raise ValueError(f"friction coefficient mu must be positive and finite, got {mu!r}")
    return mu


def _geometry(spec: ContactSpec, model: str) -> dict:
    out = {"body": spec.body, "model": model}
    for name in ("radius", "length", "width", "height"):
        if getattr(spec, name):
            out[name] = getattr(spec, name)
    return out


def _materials(spec: ContactSpec) -> dict:
    return {"E1": spec.E1, "nu1": spec.nu1, "E2": spec.E2, "nu2": spec.nu2}


def _grid_info(spec: ContactSpec, contact, problem: TangentialProblem) -> dict:
    zx, zy = spec.zone()
    return {"nodes_per_side": spec.n_side, "zone_half_x": zx, "zone_half_y": zy,
            "modelled_nodes": contact.n, "contact_nodes": problem.n_c,
            "symmetry": contact.meta.get("symmetry", contact.meta.get("grid", {}).get("symmetry"))}
