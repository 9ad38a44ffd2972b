"""Cylinder laws (thesis 2.2.6, 2.3.2.1): delta = C F^a L^-b D^c for the eight cylinders of Table II.

Normal approach: delta_n(F), the approach of the distant faces at normal force F.
Tangential approach: delta_t(T), the tangential displacement of the distant
faces at tangential force T on the virgin curve, at the constant normal force
``N_TANGENTIAL`` (the thesis's CNF case, 120 N) and T up to ``T_MAX_SHARE`` mu N.
Both laws are fitted by scipy's trust-region-reflective least squares (the
thesis used MATLAB's lsqcurvefit, the same algorithm) on relative residuals
(delta spans two decades). SI units: delta [m], F [N], L and D [m].

Body-compression share (section 2.2.5): the cylinder's own compression outside
the contact, u_1o / delta at ~3 b (``body1_share_far``), for the cylinders of
Table I (= Table II's 1-4), and the share at the centre (``body1_share``).
"""
from __future__ import annotations

import math
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import optimize

#: Thesis Table II: (D, L) [m] of cylinders 1-8.
TABLE_II = ((5e-3, 1.2e-3), (2.5e-3, 1.2e-3), (5e-3, 2.4e-3), (2.5e-3, 2.4e-3),
            (5e-3, 4.8e-3), (5e-3, 9.6e-3), (10e-3, 9.6e-3), (10e-3, 19.2e-3))
#: Thesis eq. 2.11, 2.14 (delta [um], F [N], L, D [um]) and Table III's literature exponents.
THESIS = {"normal": {"C_um": 10.21, "a": 0.917, "b": 0.928, "c": 0.099},
          "tangential": {"C_um": 14.337, "a": 1.010, "b": 1.052, "c": 0.144}}
LITERATURE = {"Brandlein": {"a": 0.925, "b": 0.850, "c": 0.0},
              "Palmgren": {"a": 0.900, "b": 0.800, "c": 0.0}}
#: Normal forces [N] (thesis Fig. 21: up to ~600 N) and the CNF normal force of
#: the tangential study (thesis 2.3.2: NF = 120 N).
FORCES = (50.0, 100.0, 200.0, 400.0, 600.0)
N_TANGENTIAL = 120.0
MU = 0.5
#: Tangential forces as shares of mu N (the part of the curve before gross slip).
T_SHARES = (0.1, 0.2, 0.3, 0.4, 0.5)
#: Zone sized for this peak pressure so that one condensed model holds every force.
P_DESIGN = 3000e6
#: Full and quick settings: cylinders (indices into TABLE_II), grid, forces.
FULL = {"cylinders": tuple(range(8)), "grid": 15, "forces": FORCES}
QUICK = {"cylinders": (0, 1, 2, 3), "grid": 7, "forces": (100.0, 200.0, 400.0)}


def thesis_si(law: str) -> dict:
    """The thesis's law in SI units: C for delta [m] with L, D [m]."""
    t = THESIS[law]
    return {"C": t["C_um"] * 1e-6 * 1e6 ** (t["c"] - t["b"]), "a": t["a"], "b": t["b"], "c": t["c"]}


def run_one(D: float, L: float, grid: int, forces, cache_dir) -> dict:
    """Normal approaches, compression shares and tangential approaches of one cylinder."""
    from contact_core import normal, report, tangential_curve
    from contact_core.condense import condense
    from contact_core.spec import ContactSpec
    from contact_core.tangential import TangentialProblem

    t0 = time.perf_counter()
    spec = ContactSpec(body="cylinder", radius=D / 2, length=L, grid=grid, p_design=P_DESIGN)
    cc = condense(spec, directions=("z", "x"), cache=cache_dir)
    out = {"D": D, "L": L, "force": [], "approach": [], "body1_share": [], "body1_share_far": [],
           "cache_hit": cc.meta["cache"]["hit"]}
    for F in forces:
        sol = normal.solve_force(cc, F)
        r = report.summarize(cc, sol, spec.kind)
        out["force"].append(F)
        out["approach"].append(r["approach"])
        out["body1_share"].append(r["body1_share"])
        out["body1_share_far"].append(r.get("body1_share_far"))
    sol = normal.solve_force(cc, N_TANGENTIAL)
    prob = TangentialProblem(cc, sol.f, MU)
    out["tangential_force"] = [s * MU * prob.N for s in T_SHARES]
    out["tangential_approach"] = [tangential_curve.virgin_point(prob, T=T).delta
                                  for T in out["tangential_force"]]
    out["k_t"] = prob.k_t
    out["time_s"] = time.perf_counter() - t0
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


def run(quick: bool = False, cache_dir=None, workers: int = 2) -> dict:
    """The whole study; ``workers`` processes share the condensation cache folder."""
    cfg = QUICK if quick else FULL
    t0 = time.perf_counter()
    jobs = [(TABLE_II[i][0], TABLE_II[i][1], cfg["grid"], cfg["forces"], cache_dir)
            for i in cfg["cylinders"]]
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            models = list(pool.map(run_one, *zip(*jobs)))
    else:
        models = [run_one(*job) for job in jobs]
    for i, m in zip(cfg["cylinders"], models):
        m["cylinder"] = i + 1
    out = {"quick": quick, "grid": cfg["grid"], "models": models}
    for law, fkey, dkey in (("normal", "force", "approach"),
                            ("tangential", "tangential_force", "tangential_approach")):
        cols = [(f, m["L"], m["D"], d) for m in models for f, d in zip(m[fkey], m[dkey])]
        out[law] = fit_law(*zip(*cols)) | {"thesis": thesis_si(law)}
    out["literature"] = LITERATURE
    out["compression"] = [{"cylinder": m["cylinder"], "D": m["D"], "L": m["L"], "force": m["force"],
                           "body1_share": m["body1_share"], "body1_share_far": m["body1_share_far"]}
                          for m in models if m["cylinder"] <= 4]
    out["wall_time_s"] = time.perf_counter() - t0
    return out


def table(result: dict) -> str:
    """Text table of the exponents beside the thesis's Tables III and V."""
    lines = [f"{'law':11s} {'':10s} {'C (SI)':>11s} {'a (F)':>7s} {'b (L)':>7s} {'c (D)':>7s}  residual rms/max"]
    for law in ("normal", "tangential"):
        r, t = result[law], result[law]["thesis"]
        lines.append(f"{law:11s} {'ours':10s} {r['C']:11.4g} {r['a']:7.3f} {r['b']:7.3f} {r['c']:7.3f}"
                     f"  {100 * r['rms_residual']:.2f} % / {100 * r['max_residual']:.2f} %")
        lines.append(f"{'':11s} {'thesis':10s} {t['C']:11.4g} {t['a']:7.3f} {t['b']:7.3f} {t['c']:7.3f}")
        if law == "normal":
            for name, lit in result["literature"].items():
                lines.append(f"{'':11s} {name:10s} {'':11s} {lit['a']:7.3f} {lit['b']:7.3f} {lit['c']:7.3f}")
    return "\n".join(lines)
