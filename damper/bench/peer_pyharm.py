"""One benchmark curve by pyHarm, run by pyHarm's own interpreter (imports nothing of damper).

Usage: ``PYTHON peer_pyharm.py CASE.json OUT.json``

CASE.json: a benchmark case (``harmonic_balance.bench_models.BenchCase.spec``: M, K, C,
force, links [a, b, k, f_s], response_dof, harmonics, band) plus the peer's settings
``nti`` (AFT samples), ``ds0``, ``ds_max``, ``corrector`` and ``x0`` ("stuck": pyHarm's
own start, the linear solution with the Jenkins links stuck; "free": the linear solution
without them, given as the starting point).

How pyHarm poses it: one substructure of n nodes with one DOF each (M, K, C), a
``CosinusForcing`` connector per loaded DOF, a ``Jenkins`` connector per link (to the
ground, or to another node of the same substructure through ``INTERNAL``) with
mu N0 = f_s, N0 = 1, and an "frf" analysis over the band (``sign_ds`` -1 sweeps down)
with the scipy root solver and the given corrector.

OUT.json: omega and a1 (first-harmonic amplitude of the response DOF) of every accepted
point in the order traced, points, evaluations (calls of the system's residual),
solve_s (wall) and cpu_s of the build and continuation, and an error message if it raised.
"""
import json
import sys
import time

import numpy as np


def idata(spec: dict) -> dict:
    """pyHarm's input dictionary of a case (module docstring)."""
    M, K, C = (np.asarray(spec[k], float) for k in ("M", "K", "C"))
    subs = {"chain": {"type": "substructure", "ndofs": 1, "matrix": {"M": M, "K": K, "C": C}}}
    conn = {}
    for dof, amp in enumerate(spec["force"]):
        if amp != 0.0:
            conn[f"force{dof}"] = {"type": "CosinusForcing", "connect": {"chain": [dof]}, "dirs": [0],
                                   "amp": float(amp)}
    for i, (a, b, k, fs) in enumerate(spec["links"]):
        connect = {"chain": [a]} if b is None else {"chain": [a], "INTERNAL": [b]}
        conn[f"jenkins{i}"] = {"type": "Jenkins", "connect": connect, "dirs": [0], "mu": float(fs),
                               "N0": 1.0, "k": float(k)}
    w0, w1 = spec["band"]
    frf = {"study": "frf", "puls_inf": min(w0, w1), "puls_sup": max(w0, w1), "sign_ds": 1 if w1 > w0 else -1,
           "ds0": spec["ds0"], "ds_min": spec["ds0"] * 1e-4, "ds_max": spec["ds_max"],
           "corrector": spec["corrector"], "solver": "scipyroot", "verbose": False, "stopper": "bounds"}
    return {"system": {"type": "Base", "nh": int(spec["harmonics"]), "nti": int(spec["nti"])},
            "substructures": subs, "connectors": conn, "analysis": {"FRF": frf}}


def free_start(m, spec: dict) -> np.ndarray:
    """Starting point: the first harmonic of the linear response without the links."""
    M, K, C = (np.asarray(spec[k], float) for k in ("M", "K", "C"))
    w = spec["band"][0]
    X = np.linalg.solve(K - w * w * M + 1j * w * C, np.asarray(spec["force"], float))
    x0 = np.zeros(len(m.system.expl_dofs))
    for idx, r in m.system.expl_dofs.iterrows():
        if int(r["harm"]) == 1:
            x0[idx] = X[int(r["node_num"])].real if r["cs"] == "c" else -X[int(r["node_num"])].imag
    return x0


def first_harmonic(m, sols, node: int) -> tuple[list, list]:
    """Frequencies and first-harmonic amplitudes of ``node`` over the accepted points."""
    edf = m.system.expl_dofs
    sel = edf[(edf["node_num"] == node) & (edf["harm"] == 1)]
    ic = sel[sel["cs"] == "c"].index[0]
    i_s = sel[sel["cs"] == "s"].index[0]
    return [float(s.x[-1]) for s in sols], [float(np.hypot(s.x[ic], s.x[i_s])) for s in sols]


def run(spec: dict) -> dict:
    from pyHarm.Maestro import Maestro

    out = {"omega": [], "a1": [], "points": 0, "evaluations": None, "error": None}
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        m = Maestro(idata(spec))
        calls = [0]
        residual = m.system.Residual

        def counted(*a, **kw):
            calls[0] += 1
            return residual(*a, **kw)

        m.system.Residual = counted
        if spec["x0"] == "free":
            m.operate(free_start(m, spec))
        else:
            m.operate()
        sols = [s for s in m.nls["FRF"].SolList if s.flag_accepted]
        out["omega"], out["a1"] = first_harmonic(m, sols, int(spec["response_dof"]))
        out["points"], out["evaluations"] = len(sols), calls[0]
    except Exception as err:  # any failure of the peer is a result of the benchmark
        out["error"] = f"{type(err).__name__}: {err}"[:300]
    out["solve_s"], out["cpu_s"] = time.perf_counter() - t0, time.process_time() - c0
    return out


if __name__ == "__main__":
    case = json.loads(open(sys.argv[1]).read())
    with open(sys.argv[2], "w") as f:
        json.dump(run(case), f)
