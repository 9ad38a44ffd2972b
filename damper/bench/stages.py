"""The benchmark stages: accuracy against cost of each stage, one list of rows each.

Every stage runs the ``damper`` CLI (or the FMU child of the stress run) in
child processes, so a cold run is cold and the memory is the child's own. The
error of each row is against an independent reference:

* contact: Hertz (contact radius and peak pressure, the larger relative error);
* tangential: Cattaneo-Mindlin's virgin curve (largest |T - T_M| / mu N);
* element: Masing's loop energy 8 int_0^a g - 4 a g(a) of the exact Mindlin curve,
  against the loop of an n-point curve (``damper loop``);
* fmu: the same Masing energy of the FMU's own piecewise-linear curve, against
  the energy the FMU dissipates per cycle at P communication steps a cycle;
* hb: time integration (``harmonic_balance.timeint.march``, 1024 steps a period,
  tol 1e-10) of the single-DOF Jenkins model at one frequency near resonance,
  against the harmonic-balance amplitude there, over H and over AFT samples; the
  cost of a whole curve against H (:mod:`.hb_cost`: the 5-mass chain and UPD-24, CPU
  time per curve and per point, the refined peak; no error); the truncation-error
  estimate against the true error per model and H or accuracy target
  (:mod:`.hb_accuracy`: ``error`` the true error against a high-H re-solve of the peak,
  ``estimate`` the engine's own, ``time_s`` wall); the converged harmonic balance against
  the time integration from rest per model (:mod:`.hb_steady`: ``error`` |HB / TI - 1| of
  the first-harmonic peak, ``states_differ`` when the two are different steady states);
  then whole curves of
  the model classes (:mod:`.hb_classes`: single-DOF soft and stiff,
  3- and 5-mass friction chains, UPD-24, with pyHarm and NLvib when given), their
  first-harmonic peak against a dense reference (:mod:`.hb_reference`);
* surface: UPD-24 with contact surfaces, the CPU time of one residual evaluation per
  node count and per H (:mod:`.surface_cost`; no error: the cost side).

``time_s`` is the command's wall time, interpreter start and imports included
(hb: the solver's own time, which the CLI reports; the cost rows: process time). Rows carry ``default: True``
where the setting is the tool's default. A stage is a function ``(quick, work, log) ->
list[Row]`` in STAGES.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from contact_core import tangential_reference as tr

from .common import Row, run_child

R, N0, MU = 0.01, 200.0, 0.5
SPHERE = ["--body", "sphere", "--radius", str(R), "--force", str(N0)]
TIMEOUT_S = 1800.0
SDOF = {"mass": 1.0, "stiffness": 1.0, "damping": 0.01, "contact-stiffness": 1.0, "slip-force": 0.05,
        "force": 0.05}
#: Frequency of the harmonic-balance comparison: in the friction-softened resonance [rad/s].
W_REF = 1.1
#: Mindlin curve of the element and FMU stages: gross slip at U_SLIP, amplitude A (partial slip).
U_SLIP, A = 2.5e-6, 1.5e-6


def _cli_json(argv, log, timeout=TIMEOUT_S, env=None):
    r = run_child(argv, timeout, env=env)
    if r.code != 0:
        log(f"  failed (exit {r.code}): damper {' '.join(map(str, argv))}: {r.stderr.strip()[-300:]}")
        return None, r
    return r.json(), r


def contact(quick: bool, work: Path, log=print) -> list[Row]:
    """Normal contact of the sphere: grid against Hertz error, cold and cached (default: real, grid 21)."""
    cases = [("halfspace", 5), ("halfspace", 9)] if quick else \
        [("halfspace", g) for g in (11, 21, 41)] + [("real", g) for g in (11, 21, 31)]  # real 41: stage "solvers"
    rows = []
    for model, grid in cases:
        cache = work / f"cache_{model}_{grid}"
        for cached in (False, True):
            out, r = _cli_json(["normal", *SPHERE, "--model", model, "--grid", str(grid), "--cache-dir", str(cache),
                                "--json"], log)
            if out is None:
                continue
            h = out["hertz"]
            err = max(abs(h["error_size"]), abs(h["error_p0"]))
            rows.append(Row(f"sphere {model}", grid, err, r.time_s, r.memory_mb, cached,
                            {"default": (model, grid) == ("real", 21), "solver": out["meta"].get("solver")}))
            log(f"  contact {model:9s} {grid:3d} {'cached' if cached else 'cold':6s} err {err:.2e} "
                f"{r.time_s:6.1f} s {r.memory_mb:6.0f} MB")
    return rows


#: Steel on steel G* [Pa] and the Hertz radius [m] that put Mindlin's gross slip at U_SLIP.
GS = tr.shear_modulus_star(2e11, 0.3, 2e11, 0.3)
A_HERTZ = 3.0 * MU * N0 / (16.0 * GS * U_SLIP)


def _mindlin(u, u_slip, muN):
    """Mindlin's virgin curve with gross slip at u_slip (contact_core's law, G* a chosen to match)."""
    a = 3.0 * muN / (16.0 * GS * u_slip)  # u_s = 3 mu N / (16 G* a)
    return tr.mindlin_force(u, muN / MU, MU, a, GS)


def tangential(quick: bool, work: Path, log=print) -> list[Row]:
    """Virgin curve of the sphere: grid against Mindlin error; BEM, and FE real bodies cold and cached
    (default: real, grid 21)."""
    cases = [("bem", 7), ("bem", 11)] if quick else [("bem", g) for g in (11, 21, 41, 61)] + \
        [("real", g) for g in (11, 21)]
    rows = []
    for model, grid in cases:
        cache = work / f"cache_{model}_{grid}"
        for cached in (False, True) if model != "bem" else (False,):  # the BEM has no cache
            out, r = _cli_json(["tangential", *SPHERE, "--mu", str(MU), "--model", model, "--grid", str(grid),
                                "--cache-dir", str(cache), "--json"], log)
            if out is None:
                continue
            muN = out["mu"] * out["normal_force"]
            u, T = np.asarray(out["u"]), np.asarray(out["T"])
            err = float(np.max(np.abs(T - _mindlin(u, out["mindlin"]["u_slip"], muN))) / muN)
            rows.append(Row(f"sphere {model}", grid, err, r.time_s, r.memory_mb, cached,
                            {"default": (model, grid) == ("real", 21), "curve_points": len(u)}))
            log(f"  tangential {model:4s} {grid:3d} {'cached' if cached else 'cold':6s} err {err:.2e} "
                f"{r.time_s:6.1f} s, {len(u)} curve points")
    return rows


def _curve_file(path: Path, n: int) -> Path:
    u = np.linspace(0.0, U_SLIP, n)
    T = _mindlin(u, U_SLIP, MU * N0)
    path.write_text(json.dumps({"schema": "damper-virgin-curve/1", "u": u.tolist(), "T": T.tolist(), "N": N0,
                                "mu": MU, "k_t": 1.5 * MU * N0 / U_SLIP, "load_case": "CNF"}))
    return path


def _masing_exact(a: float) -> float:
    """Loop energy of the exact Mindlin curve at displacement amplitude a: Mindlin-Deresiewicz's
    energy at the force amplitude T(a) [J] (= Masing's 8 int_0^a g du - 4 a g(a))."""
    return float(tr.mindlin_deresiewicz_energy(float(_mindlin(a, U_SLIP, MU * N0)), N0, MU, A_HERTZ, GS))


def element(quick: bool, work: Path, log=print) -> list[Row]:
    """Iwan element: slider count against the loop-energy error (default: the 256-sample loop)."""
    sizes = (3, 9, 33) if quick else (2, 3, 5, 9, 17, 33, 65, 129, 257)
    ref = _masing_exact(A)
    rows = []
    for n in sizes:
        curve = _curve_file(work / f"mindlin{n}.json", n)
        out, r = _cli_json(["loop", "--curve", str(curve), "--amplitude", str(A), "--json"], log)
        if out is None:
            continue
        err = abs(out["energy_per_cycle"] / ref - 1.0)
        rows.append(Row("Mindlin curve", out["n_sliders"], err, r.time_s, r.memory_mb, False,
                        {"curve_points": n}))
        log(f"  element {out['n_sliders']:4d} sliders err {err:.2e} {r.time_s:6.1f} s")
    return rows


def fmu(quick: bool, work: Path, log=print) -> list[Row]:
    """FMU: communication steps a cycle against the dissipated-energy error (no default: the importer's choice)."""
    per_cycle = (4, 6, 64) if quick else (4, 5, 6, 8, 10, 16, 64, 256, 1024)
    n = 10
    curve = _curve_file(work / "fmu_curve.json", n)
    u = np.linspace(0.0, U_SLIP, n)
    g = _mindlin(u, U_SLIP, MU * N0)
    grid = np.union1d(u[u < A], [A])
    gi = np.interp(grid, u, g)
    ref = 8.0 * np.sum(0.5 * (gi[1:] + gi[:-1]) * np.diff(grid)) - 4.0 * A * gi[-1]  # exact (piecewise linear)
    code = "from damper.stress.fmu_child import main; import sys; sys.exit(main())"
    rows = []
    for P in per_cycle:
        cycles = 6
        r = run_child([curve, "2", 1.0 / P, P * cycles, "sine", A, work / "fmu", P], TIMEOUT_S, python_code=code)
        if r.code != 0:
            log(f"  fmu P={P} failed: {r.stderr.strip()[-300:]}")
            continue
        Wc = r.json()["W_cycles"]
        W = (Wc[-1] - Wc[1]) / (len(Wc) - 2)  # steady cycles only (the first holds the virgin loading)
        err = abs(W / ref - 1.0)
        rows.append(Row("FMI 2, sine 1 Hz", P, err, r.time_s, r.memory_mb, False, {"step_s": 1.0 / P}))
        log(f"  fmu {P:5d} steps/cycle err {err:.2e} {r.time_s:6.1f} s")
    return rows


def _sdof_argv(**over) -> list[str]:
    argv = ["frf", "--model", "sdof"]
    for k, v in dict(SDOF, **over).items():
        argv += [f"--{k}", f"{v:g}"]
    return argv


def _ti_reference(log) -> float:
    """Steady amplitude of the single-DOF Jenkins model at W_REF by time integration [m]."""
    from harmonic_balance.model import sdof_model
    from harmonic_balance.timeint import march

    model = sdof_model(**{k.replace("-", "_"): v for k, v in SDOF.items()})
    amp = march(model, W_REF, steps_per_period=1024, tol=1e-10).amplitude
    log(f"  hb reference: time integration at {W_REF} rad/s: {amp:.8e} m")
    return float(amp)


def hb(quick: bool, work: Path, log=print, models=None) -> list[Row]:
    """Harmonic balance: harmonics and AFT samples against the error vs time integration (default H 1, auto),
    the cost of a curve against H (:mod:`.hb_cost`), the accuracy rows (:mod:`.hb_accuracy`), HB against
    time integration per model (:mod:`.hb_steady`), then the
    model classes with their peers (:mod:`.hb_classes`; ``models``: its ModelOptions)."""
    from . import hb_accuracy, hb_classes, hb_cost, hb_steady

    rows = _hb_settings(quick, log)
    log("  hb cost against H (CPU time of a whole curve):")
    rows += hb_cost.run(quick, lambda s: log("  " + s))
    log("  hb accuracy (truncation-error estimate against the true error):")
    rows += hb_accuracy.bench_rows(quick, lambda s: log("  " + s))
    log("  hb against time integration (which steady state):")
    rows += hb_steady.bench_rows(quick, lambda s: log("  " + s))
    log("  hb model classes (peak error against dense references):")
    log("  " + hb_classes.HEAD)
    return rows + hb_classes.run(quick, work, lambda s: log("  " + s), models)


def _hb_settings(quick: bool, log) -> list[Row]:
    """The H and AFT-sample rows against time integration on the single-DOF model."""
    ref = _ti_reference(log)
    band = ["--omega", f"{W_REF * 0.999:g}", f"{W_REF * 1.001:g}"]
    rows = []
    hs = (1, 3, 7) if quick else (1, 3, 5, 7, 11, 15, 21)
    samples = (32, 64) if quick else (16, 32, 64, 128, 256)
    settings = [("harmonics", H, ["--harmonics", str(H)]) for H in hs] + \
               [("samples (H 7)", s, ["--harmonics", "7", "--samples", str(s)]) for s in samples]
    for what, size, extra in settings:
        out, r = _cli_json([*_sdof_argv(), *extra, *band, "--json"], log)
        if out is None:
            continue
        amp = float(np.interp(W_REF, out["omega"], out["amplitude"]))
        err = abs(amp / ref - 1.0)
        rows.append(Row(what, size, err, float(out["time_s"]), r.memory_mb, False,
                        {"default": what == "harmonics" and size == 1, "wall_s": r.time_s}))
        log(f"  hb {what:13s} {size:4d} err {err:.2e} {out['time_s']:6.2f} s")
    return rows


def surface(quick: bool, work: Path, log=print) -> list[Row]:
    """UPD-24 with contact surfaces: the cost of one evaluation per node count and per H, the
    condensed and the node-DOF models (:mod:`.surface_cost`)."""
    from . import surface_cost

    return surface_cost.run(quick, lambda s: log("  " + s))


#: Stage name -> function (quick, work, log) -> rows.
STAGES = {"contact": contact, "tangential": tangential, "element": element, "fmu": fmu, "hb": hb,
          "surface": surface}
