"""Cylinder laws (thesis 2.2.6, 2.3.2.1): delta = C F^a L^-b D^c for the eight cylinders of Table II.

Normal approach: delta_n(F), the approach of the distant faces at normal force F.
Tangential approach: delta_t(T), the tangential displacement of the distant
faces at tangential force T on the virgin curve, in the thesis's CND case (the
normal approach held at ``APPROACH_CND`` = 5 um, section 2.3.2, so the normal
force differs between cylinders) at T = ``T_SHARES`` of mu N.
Both laws are fitted by scipy's trust-region-reflective least squares (the
thesis used MATLAB's lsqcurvefit, the same algorithm) on relative residuals
(delta spans two decades). SI units: delta [m], F [N], L and D [m].

Body-compression share (section 2.2.5): the cylinder's own compression outside
the contact, u_1o / delta at ~3 b (``body1_share_far``), for the cylinders of
Table I (= Table II's 1-4), and the share at the centre (``body1_share``).
"""
from __future__ import annotations

import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import optimize

#: Worker processes are spawned, not forked: a fork of a process whose BLAS or
#: other libraries already run threads can deadlock on a lock held at the fork
#: (seen: the study test hung inside the full test session).
SPAWN = multiprocessing.get_context("spawn")

#: Thesis Table II: (D, L) [m] of cylinders 1-8.
TABLE_II = ((5e-3, 1.2e-3), (2.5e-3, 1.2e-3), (5e-3, 2.4e-3), (2.5e-3, 2.4e-3),
            (5e-3, 4.8e-3), (5e-3, 9.6e-3), (10e-3, 9.6e-3), (10e-3, 19.2e-3))
#: Thesis eq. 2.11, 2.14 (delta [um], F [N], L, D [um]) and Table III's literature exponents.
THESIS = {"normal": {"C_um": 10.21, "a": 0.917, "b": 0.928, "c": 0.099},
          "tangential": {"C_um": 14.337, "a": 1.010, "b": 1.052, "c": 0.144}}
LITERATURE = {"Brandlein": {"a": 0.925, "b": 0.850, "c": 0.0},
              "Palmgren": {"a": 0.900, "b": 0.800, "c": 0.0}}
#: Normal forces [N] (thesis Fig. 21: up to ~600 N) and the normal approach of
#: the tangential study's CND case (thesis 2.3.2: dz = 5 um).
FORCES = (50.0, 100.0, 200.0, 400.0, 600.0)
APPROACH_CND = 5e-6
MU = 0.5
#: The CND normal force is not known before the solve; the zone is sized for
#: ZONE_SAFETY times the thesis's eq. 2.11 estimate of it (a zone too small is
#: detected: contact on the zone edge raises).
ZONE_SAFETY = 1.5
#: Tangential forces as shares of mu N (the part of the curve before gross slip).
T_SHARES = (0.1, 0.2, 0.3, 0.4, 0.5)
#: The zone of each cylinder is sized from the Hertz contact of its largest
#: force (``load_hint``), not from a design pressure: a 3000 MPa zone is ten
#: contact widths wide on the long cylinders, whose coarse grids then put the
#: whole contact between two node rows. This floor only keeps p_design valid.
P_DESIGN_FLOOR = 1e6
#: Full and quick settings: cylinders (indices into TABLE_II), the three grids
#: of the convergence study (zone spacing halves: 6, 12, 24 cells), forces.
FULL = {"cylinders": tuple(range(8)), "grids": (7, 13, 25), "forces": FORCES}
QUICK = {"cylinders": (0, 1, 2), "grids": (5, 9, 17), "forces": (100.0, 200.0, 400.0)}


def thesis_si(law: str) -> dict:
    """The thesis's law in SI units: C for delta [m] with L, D [m]."""
    t = THESIS[law]
    return {"C": t["C_um"] * 1e-6 * 1e6 ** (t["c"] - t["b"]), "a": t["a"], "b": t["b"], "c": t["c"]}


def thesis_force(delta: float, D: float, L: float) -> float:
    """The normal force [N] giving approach ``delta`` [m] by the thesis's eq. 2.11."""
    t = thesis_si("normal")
    return (delta / (t["C"] * L ** (-t["b"]) * D ** t["c"])) ** (1.0 / t["a"])


def _check_zone(r: dict, D: float, L: float, what: str) -> None:
    if r["zone_edge_in_contact"]:
        raise RuntimeError(f"cylinder D {D:g} m, L {L:g} m at {what}: the contact reaches the "
                           f"edge of the potential zone")


def run_one(D: float, L: float, grid: int, forces, cache_dir) -> dict:
    """Normal approaches, compression shares and tangential approaches of one cylinder."""
    from contact_core import normal, report, tangential_curve
    from contact_core.condense import condense
    from contact_core.spec import ContactSpec
    from contact_core.tangential import TangentialProblem

    t0 = time.perf_counter()
    hint = max(max(forces), ZONE_SAFETY * thesis_force(APPROACH_CND, D, L))
    spec = ContactSpec(body="cylinder", radius=D / 2, length=L, grid=grid, p_design=P_DESIGN_FLOOR,
                       load_hint=hint)
    cc = condense(spec, directions=("z", "x"), cache=cache_dir)
    out = {"D": D, "L": L, "grid": grid, "spacing": cc.meta.get("spacing"), "force": [], "approach": [],
           "body1_share": [], "body1_share_far": [], "cache_hit": cc.meta["cache"]["hit"]}
    for F in forces:
        sol = normal.solve_force(cc, F)
        r = report.summarize(cc, sol, spec.kind)
        _check_zone(r, D, L, f"{F:g} N")
        out["force"].append(F)
        out["approach"].append(r["approach"])
        out["body1_share"].append(r["body1_share"])
        out["body1_share_far"].append(r.get("body1_share_far"))
    sol = normal.solve_displacement(cc, APPROACH_CND)
    _check_zone(report.summarize(cc, sol, spec.kind), D, L, f"approach {APPROACH_CND:g} m")
    prob = TangentialProblem(cc, sol.f, MU)
    out["normal_force_cnd"] = prob.N
    out["tangential_force"] = [s * MU * prob.N for s in T_SHARES]
    out["tangential_approach"] = [tangential_curve.virgin_point(prob, T=T).delta
                                  for T in out["tangential_force"]]
    out["k_t"] = prob.k_t
    out["time_s"] = time.perf_counter() - t0
    return out


def run_sphere(D: float, grid: int, forces, cache_dir) -> dict:
    """Body-1 shares of a sphere of diameter D (the thesis's term of comparison, Fig. 17)."""
    from contact_core import normal, report
    from contact_core.condense import condense
    from contact_core.spec import ContactSpec

    spec = ContactSpec(body="sphere", radius=D / 2, grid=grid, p_design=P_DESIGN_FLOOR, load_hint=max(forces))
    cc = condense(spec, cache=cache_dir)
    out = {"body": "sphere", "D": D, "force": list(forces), "body1_share": [], "body1_share_far": [],
           "cache_hit": cc.meta["cache"]["hit"]}
    for F in forces:
        r = report.summarize(cc, normal.solve_force(cc, F), spec.kind)
        out["body1_share"].append(r["body1_share"])
        out["body1_share_far"].append(r.get("body1_share_far"))
    return out


def fit_law(F, L, D, delta) -> dict:
    """Least-squares fit of delta = C F^a L^-b D^c (trust-region reflective, relative residuals)."""
    F, L, D, delta = (np.asarray(v, float) for v in (F, L, D, delta))

    def model(p):  # p = (log C, a, b, c): log C keeps C positive and well scaled
        return np.exp(p[0]) * F ** p[1] * L ** (-p[2]) * D ** p[3]

    p0 = np.array([math.log(np.median(delta / (F * D**0 / L))), 1.0, 1.0, 0.0])
    res = optimize.least_squares(lambda p: model(p) / delta - 1.0, p0, method="trf", x_scale="jac")
    rel = model(res.x) / delta - 1.0
    return {"C": float(np.exp(res.x[0])), "a": float(res.x[1]), "b": float(res.x[2]),
            "c": float(res.x[3]), "rms_residual": float(np.sqrt(np.mean(rel**2))),
            "max_residual": float(np.abs(rel).max()), "points": int(delta.size)}


def _fits(models) -> dict:
    """Both laws fitted to one grid's models."""
    out = {}
    for law, fkey, dkey in (("normal", "force", "approach"),
                            ("tangential", "tangential_force", "tangential_approach")):
        cols = [(f, m["L"], m["D"], d) for m in models for f, d in zip(m[fkey], m[dkey])]
        out[law] = fit_law(*zip(*cols))
    return out


def run(quick: bool = False, cache_dir=None, workers: int = 2) -> dict:
    """The whole study on three grids; ``workers`` processes share the condensation cache.

    The printed law of each kind is fitted on the finest grid; ``convergence``
    holds, for every exponent, log C and each model's largest-force approaches,
    the three grid values and their Richardson estimate.
    """
    cfg = QUICK if quick else FULL
    t0 = time.perf_counter()
    jobs = [(TABLE_II[i][0], TABLE_II[i][1], g, cfg["forces"], cache_dir)
            for g in cfg["grids"] for i in cfg["cylinders"]]
    if workers > 1:
        with ProcessPoolExecutor(workers, mp_context=SPAWN) as pool:
            runs = list(pool.map(run_one, *zip(*jobs)))
    else:
        runs = [run_one(*job) for job in jobs]
    n = len(cfg["cylinders"])
    per_grid = [runs[k * n:(k + 1) * n] for k in range(len(cfg["grids"]))]
    for models in per_grid:
        for i, m in zip(cfg["cylinders"], models):
            m["cylinder"] = i + 1
    fits = [_fits(models) for models in per_grid]
    models = per_grid[-1]
    out = {"quick": quick, "grids": list(cfg["grids"]), "models": models}
    for law in ("normal", "tangential"):
        out[law] = fits[-1][law] | {"thesis": thesis_si(law)}
    out["convergence"] = _convergence(per_grid, fits)
    out["literature"] = LITERATURE
    out["compression"] = [{"cylinder": m["cylinder"], "D": m["D"], "L": m["L"], "force": m["force"],
                           "body1_share": m["body1_share"], "body1_share_far": m["body1_share_far"]}
                          for m in models if m["cylinder"] <= 4]
    sphere = run_sphere(TABLE_II[0][0], cfg["grids"][-1], cfg["forces"], cache_dir)
    out["compression_sphere"] = sphere
    out["wall_time_s"] = time.perf_counter() - t0
    out["cache_hits"] = sum(m["cache_hit"] for m in runs) + sphere["cache_hit"]
    return out


def _convergence(per_grid, fits) -> dict:
    """Richardson estimates (``convergence.richardson``) over the three grids."""
    from .convergence import richardson

    h = [1.0 / (models[0]["grid"] - 1) for models in per_grid]  # zone cells: the spacing halves
    out = {}
    for law in ("normal", "tangential"):
        for key in ("a", "b", "c"):
            vals = [f[law][key] for f in fits]
            out[f"{law}_{key}"] = {"grids": vals} | richardson(vals, h)
        vals = [math.log(f[law]["C"]) for f in fits]
        out[f"{law}_logC"] = {"grids": vals} | richardson(vals, h)
    for k, m in enumerate(per_grid[-1]):
        for key in ("approach", "tangential_approach"):
            vals = [models[k][key][-1] for models in per_grid]
            hk = [models[k]["spacing"] for models in per_grid]
            out[f"cylinder{m['cylinder']}_{key}"] = {"grids": vals} | richardson(vals, hk)
    return out


def table(result: dict) -> str:
    """Text table of the exponents beside the thesis's Tables III and V, with convergence."""
    conv = result["convergence"]
    lines = [f"grids {result['grids']} (nodes per side); law fitted on the finest; "
             f"Richardson estimate [observed order] below each",
             f"{'law':11s} {'':10s} {'C (SI)':>11s} {'a (F)':>7s} {'b (L)':>7s} {'c (D)':>7s}  residual rms/max"]
    for law in ("normal", "tangential"):
        r, t = result[law], result[law]["thesis"]
        lines.append(f"{law:11s} {'ours':10s} {r['C']:11.4g} {r['a']:7.3f} {r['b']:7.3f} {r['c']:7.3f}"
                     f"  {100 * r['rms_residual']:.2f} % / {100 * r['max_residual']:.2f} %")
        rich = [conv[f"{law}_{k}"] for k in ("logC", "a", "b", "c")]
        lines.append(f"{'':11s} {'Richardson':10s} {math.exp(rich[0]['value']):11.4g} "
                     + " ".join(f"{c['value']:7.3f}" for c in rich[1:]) + "  order "
                     + ", ".join("-" if c["order"] is None else f"{c['order']:.1f}" for c in rich[1:]))
        lines.append(f"{'':11s} {'thesis':10s} {t['C']:11.4g} {t['a']:7.3f} {t['b']:7.3f} {t['c']:7.3f}")
        if law == "normal":
            for name, lit in result["literature"].items():
                lines.append(f"{'':11s} {name:10s} {'':11s} {lit['a']:7.3f} {lit['b']:7.3f} {lit['c']:7.3f}")
    lines.append("largest-force approaches [um], finest grid -> Richardson (error of finest):")
    for m in result["models"]:
        cn, ct = (conv[f"cylinder{m['cylinder']}_{k}"] for k in ("approach", "tangential_approach"))
        lines.append(f"  cylinder {m['cylinder']} D {m['D'] * 1e3:g} mm L {m['L'] * 1e3:g} mm: normal "
                     f"{m['approach'][-1] * 1e6:.4f} -> {cn['value'] * 1e6:.4f} ({100 * cn['error_finest']:.2f} %), "
                     f"tangential {m['tangential_approach'][-1] * 1e6:.4f} -> {ct['value'] * 1e6:.4f} "
                     f"({100 * ct['error_finest']:.2f} %)")
    return "\n".join(lines)
