"""Benchmark of the mistuned full-ring harmonic balance (table; not a timed test).
===================================================================================

Rows:

* ``scaling``: one ring curve (41 points, H = 7, CF/F0 = 4, one std-0.02 pattern) of
  N_b = 4, 8, 24, 48 blades at the same interblade phase (EO = N_b / 4, so the tuned
  sector is the same) against the tuned sector's curve on the same grid: CPU time,
  evaluations, Newton iterations, one sparse LU of the ring Jacobian, its non-zeros; the
  same curve by the fast solver (``ring_fast``): CPU time, speed-up, evaluations, and its
  per-blade peaks and amplification against the full solver's.
* ``band``: UPD-24 samples (``--samples``, std 0.02, seed 1) on the study's default band
  (the tuned friction-damped peak up to the stuck ring's, with margins) by the fast
  solver and by the full solver on 41 and on 401 points: CPU time, evaluations (the
  fast solver's also its points, factorizations and residual-only evaluations), and
  the per-blade peaks' and amplification's largest differences against the 401-point
  full solver (the band's narrow resonance near the stuck peak needs that grid).
* ``factor``: the fast solver's factorization of the ring Jacobian, SuperLU (COLAMD)
  against the block elimination over the blades (``ring_lu.BlockRingFactor``, the
  default) with its numpy loop (``block_numpy``) and compiled (``block``), in turn on
  the same ``--samples`` patterns (std 0.02, seed 1) of the study's default band, N_b =
  ``--factor-blades`` (default 24; EO = N_b / 4): CPU time per sample, factorizations,
  the CPU time of one factorization of the sample's peak Jacobian and of one refined
  solve with it, and the largest differences of the per-blade peaks and the
  amplification against SuperLU's (``block_numpy_...`` those of the numpy loop).
* ``precond``: GMRES on the mistuned Jacobian preconditioned by the tuned ring's (the
  cyclic solution's) LU, iterations against the scatter, and the direct sparse LU's
  time: why the solver factors the mistuned Jacobian instead.
* ``throughput``: a Monte Carlo study (``damper.mistuning``, N_b = 24, std 0.02, the
  friction damper or ``--damper free|stuck``) on a Dask local cluster of 1 and 2 workers
  (``--workers``), fresh caches: wall time, samples per minute, the chunks' CPU time and
  the parallel efficiency CPU / (workers x wall), and with a serial run in the same list
  (``--workers 0 1 2``) the speed-up of each cluster over it (serial wall / cluster wall of
  the sample phase) and that over the workers; the traced memory peak of one sample
  (tracemalloc, a separate run). With ``--quick`` (and no ``--workers``) 2 samples run
  in this process (``workers = 0``, the serial executor): the quick mode starts no Dask
  cluster (the documentation build runs it).
* ``worst``: the worst pattern of the linear ring (damper free, std 0.02, factors within
  1 +- 0.06; ``damper upd mistuning --worst``'s search) against the largest amplification
  of ``--worst-samples`` uniform random patterns at the same std (a study, every blade's
  peak by the ring's own peak search), Whitehead's bound (1 + sqrt(N_b)) / 2, and, for
  N_b <= 6, scipy's differential evolution on the same peak (no gradients): whether it is
  above, below and within 1 %. N_b from ``--worst-blades`` (default 6 and 24; EO = N_b / 4,
  at least 1).
* ``worst_friction``: the worst pattern with the friction damper (``damper upd mistuning
  --worst``, std 0.02, H = 7, ``--worst-evaluations`` ring curves per start) on
  ``--worst-friction-blades`` (default 24): its amplification, each start's, and the ring's
  time integration at the worst blade's peak against the HB peak (and against the HB at
  H = 15 there).
* ``confidence``: the 0.95 quantile's 95 % interval from ``--confidence-samples`` damper-free
  samples (default 1000; UPD-24 or ``--confidence-blades``, std 0.02, seed 1) against the 0.95 quantile of an
  independent study four times as large (seed 2), in this process
  (``examples/mistuning_confidence.py``, which also plots it): whether it is inside.

Times are CPU (process_time) where one process works, wall time for the clusters: the
machine is shared, compare within one run only. ::

    OPENBLAS_NUM_THREADS=1 nice python examples/bench_mistuning.py --out out/bench_mistuning \\
        [--rows scaling band factor precond throughput worst worst_friction confidence] [--samples 8]
        [--quick] [--factor-blades 24 48]
        [--workers 1 2] [--damper free] [--worst-blades 6 24] [--worst-samples 1000]
        [--worst-friction-blades 24] [--worst-evaluations 25]
        [--confidence-samples 1000] [--confidence-blades 8]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from scipy.sparse.linalg import LinearOperator, gmres, splu

from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.mistuning import draw_factors
from harmonic_balance.bladed_disk.ring_fast import fast_ring_frf
from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
from harmonic_balance.bladed_disk.ring_solve import RingSolver, ring_frf
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf, start_point

BAND = (426.0, 471.0)   # around the tuned peak (448 Hz at CF = 120 N)
POINTS, H = 41, 7


def sector_of(nb: int) -> Sector:
    return Sector(load_config().with_values(disk__blades=nb, disk__engine_order=nb // 4))


def solve_ms(J, factor) -> float:
    """CPU time of one solve with ``factor``'s factors of J (a fixed right-hand side) [ms],
    the mean over >= 1 s of repeats."""
    factor.factor(J)
    b = np.random.default_rng(20261128).standard_normal(J.shape[0])
    t, k = time.process_time(), 0
    while time.process_time() - t < 1.0 or k == 0:
        factor.solve(b)
        k += 1
    return (time.process_time() - t) / k * 1e3


def lu_ms(J, factor=None) -> float:
    """CPU time of one sparse LU (COLAMD; or ``factor.factor``) [ms], the mean over >= 1 s
    of repeats."""
    t, k = time.process_time(), 0
    while time.process_time() - t < 1.0 or k == 0:
        splu(J, permc_spec="COLAMD") if factor is None else factor.factor(J)
        k += 1
    return (time.process_time() - t) / k * 1e3


def scaling_rows(blades) -> list:
    om = 2 * np.pi * np.linspace(*BAND, POINTS)
    rows = []
    for nb in blades:
        sector = sector_of(nb)
        tuned = SectorHB(sector, H)
        c0 = time.process_time()
        ct = frf(tuned, om)
        t_sector = time.process_time() - c0
        ring = MistunedRingHB(sector, draw_factors(nb, 0.02, 1, 0), H)
        c0 = time.process_time()
        c = ring_frf(ring, om, tuned, start_omega=ct.peak_omega)
        t_ring = time.process_time() - c0
        fast = MistunedRingHB(sector, ring.kappa, H)
        c0 = time.process_time()
        cf = fast_ring_frf(fast, (om[0], om[-1]), tuned, start_omega=ct.peak_omega)
        t_fast = time.process_time() - c0
        J = ring(c.peak_x, c.peak_omega)[1].tocsc()
        rows.append({"case": "ring curve", "blades": nb, "unknowns": ring.size, "jacobian_nnz": J.nnz,
                     "sector_cpu_s": t_sector, "ring_cpu_s": t_ring, "ratio_ring_sector": t_ring / t_sector,
                     "ring_cpu_per_blade_s": t_ring / nb, "fast_cpu_per_blade_s": t_fast / nb,
                     "evaluations": c.evaluations,
                     "newton_iterations": c.newton_iterations, "lu_ms": lu_ms(J),
                     "amplification": c.peak / ct.peak_amplitude, "truncated": c.extra["truncated"],
                     "fast_cpu_s": t_fast, "fast_speedup": t_ring / t_fast,
                     "fast_evaluations": cf.evaluations, "fast_points": cf.extra["points"],
                     "fast_amplification_rel_diff": cf.peak / c.peak - 1,
                     "fast_peak_per_blade_max_rel_diff": float(np.abs(cf.peak_per_blade / c.peak_per_blade
                                                                      - 1).max())})
        print(_fmt(rows[-1]), flush=True)
    return rows


def band_rows(samples: int) -> list:
    """Fast against full (41 and 401 points) on UPD-24's default study band."""
    from damper.mistuning import SampleModel, Study, tuned_reference

    study = Study(std=0.02, samples=samples, seed=1)
    ref = tuned_reference(study, study.load())
    model = SampleModel(study, ref["band_hz"], ref["tuned_frequency_hz"])
    lo, hi = model.om[0], model.om[-1]
    start = 2 * np.pi * ref["tuned_frequency_hz"]
    rows = []
    for i in range(samples):
        kappa = draw_factors(24, 0.02, 1, i)
        runs = {}
        for name, points in (("fast", 0), ("full41", 41), ("full401", 401)):
            ring = MistunedRingHB(model.sector, kappa, H, cf=study.cf, f0=study.f0)
            model.tuned = model.tuned or SectorHB(ring.sector, H, cf=ring.cf, f0=ring.f0,
                                                  mu=ring.mu, n_t=ring.basis.n_t)
            c0 = time.process_time()
            c = (fast_ring_frf(ring, (lo, hi), model.tuned, start_omega=start) if not points
                 else ring_frf(ring, np.linspace(lo, hi, points), model.tuned, start_omega=start))
            runs[name] = (time.process_time() - c0, c)
        ref_c = runs["full401"][1]
        row = {"case": "default band", "blades": 24, "pattern": i,
               "band_hz": [float(lo / 2 / np.pi), float(hi / 2 / np.pi)]}
        for name, (t, c) in runs.items():
            row |= {f"{name}_cpu_s": t, f"{name}_evaluations": c.evaluations}
            if name == "fast":   # of the evaluations, those of the residual alone
                row |= {"fast_points": c.extra["points"],
                        "fast_factorizations": c.extra["factorizations"],
                        "fast_residual_only": c.extra["landed"] + c.extra["missed"]}
            if name != "full401":
                row |= {f"{name}_peak_per_blade_max_rel_diff":
                        float(np.abs(c.peak_per_blade / ref_c.peak_per_blade - 1).max()),
                        f"{name}_amplification_rel_diff": c.peak / ref_c.peak - 1}
        rows.append(row)
        print(_fmt(row), flush=True)
    return rows


def factor_rows(samples: int, blades: int = 24) -> list:
    """The ``factor`` rows (module docstring): SuperLU and the block LU's two kernels in turn."""
    from damper.mistuning import SampleModel, Study, tuned_reference
    from harmonic_balance.bladed_disk import ring_lu

    study = Study(std=0.02, samples=samples, seed=1, blades=blades, engine_order=max(1, blades // 4))
    ref = tuned_reference(study, study.load())
    model = SampleModel(study, ref["band_hz"], ref["tuned_frequency_hz"])
    lo, hi, start = model.om[0], model.om[-1], 2 * np.pi * ref["tuned_frequency_hz"]
    rows, before = [], os.environ.get("DAMPER_SOLVER")
    try:
        for i in range(samples):
            kappa = draw_factors(blades, 0.02, 1, i)
            row = {"case": "ring factorization", "blades": blades, "pattern": i}
            curves = {}
            for name in ("superlu", "block_numpy", "block"):
                os.environ["DAMPER_SOLVER"] = name.split("_")[0]
                ring_lu.BLOCK_KERNEL = "numpy" if name == "block_numpy" else None
                ring = MistunedRingHB(model.sector, kappa, H, cf=study.cf, f0=study.f0)
                model.tuned = model.tuned or SectorHB(ring.sector, H, cf=ring.cf, f0=ring.f0,
                                                      mu=ring.mu, n_t=ring.basis.n_t)
                c0 = time.process_time()
                c = fast_ring_frf(ring, (lo, hi), model.tuned, start_omega=start)
                curves[name] = c
                J = ring(c.peak_x, c.peak_omega)[1]
                blocks = (blades, ring.sector.n_dof, ring.nb)
                row |= {f"{name}_cpu_s": time.process_time() - c0, f"{name}_evaluations": c.evaluations,
                        f"{name}_factorizations": c.extra["factorizations"],
                        f"{name}_factor_ms": lu_ms(J, ring_lu.make_factor(name.split("_")[0], blocks)),
                        f"{name}_solve_ms": solve_ms(J, ring_lu.make_factor(name.split("_")[0], blocks))}
            a = curves["superlu"]
            row |= {"speedup": row["superlu_cpu_s"] / row["block_cpu_s"],
                    "speedup_over_numpy": row["block_numpy_cpu_s"] / row["block_cpu_s"]}
            for name, pre in (("block_numpy", "block_numpy_"), ("block", "")):
                b = curves[name]
                rel = np.abs(b.peak_per_blade / a.peak_per_blade - 1)
                row |= {f"{pre}peak_per_blade_max_rel_diff": float(rel.max()),
                        f"{pre}amplification_rel_diff": b.peak / a.peak - 1}
            rows.append(row)
            print(_fmt(row), flush=True)
    finally:
        ring_lu.BLOCK_KERNEL = None
        if before is None:
            os.environ.pop("DAMPER_SOLVER", None)
        else:
            os.environ["DAMPER_SOLVER"] = before
    return rows


def precond_rows(stds, nb=24) -> list:
    sector = sector_of(nb)
    tuned_ring = MistunedRingHB(sector, np.ones(nb), H)
    solver_t = RingSolver(tuned_ring)
    rows = []
    for f in (440.0, 448.25, 460.0):
        w = 2 * np.pi * f
        Jt = tuned_ring(tuned_ring.from_sector(start_point(solver_t.tuned, w)), w)[1].tocsc()
        lut = splu(Jt, permc_spec="COLAMD")
        for std in stds:
            ring = MistunedRingHB(sector, draw_factors(nb, std, 1, 0), H)
            x = RingSolver(ring, solver_t.tuned).tuned_start(w)
            J = ring(x, w)[1].tocsc()
            b = np.random.default_rng(0).standard_normal(ring.size)
            residuals = []  # GMRES's preconditioned residual norms, one per inner iteration
            y, _ = gmres(J, b, M=LinearOperator(J.shape, lut.solve), rtol=1e-10, restart=200,
                         maxiter=1, callback=residuals.append, callback_type="pr_norm")
            rows.append({"case": "tuned preconditioner", "blades": nb, "frequency_hz": f, "std": std,
                         "gmres_iterations": len(residuals),
                         "gmres_residual": float(np.linalg.norm(J @ y - b) / np.linalg.norm(b)),
                         "lu_ms": lu_ms(J)})
            print(_fmt(rows[-1]), flush=True)
    return rows


def throughput_rows(samples: int, workers=(1, 2), damper: str = "nonlinear") -> list:
    """Monte Carlo rows; ``workers`` are Dask local-cluster sizes, 0 is this process
    (serial executor, no cluster). Each row: wall time, the chunks' CPU time and the
    parallel efficiency CPU / (workers x wall) of the study's sample phase."""
    from damper.cache import Store
    from damper.mistuning import Study, run_sample, run_study

    rows = []
    study = Study(std=0.02, samples=samples, seed=1, damper=damper)
    for n in workers:
        with tempfile.TemporaryDirectory() as tmp:
            load0 = os.getloadavg()[0]
            t0 = time.perf_counter()
            out = run_study(study, Store(tmp), workers=n or None, serial=n == 0, echo=lambda t: None)
            wall = time.perf_counter() - t0
        ok = [s for s in out["samples"] if s["error"] is None]
        e = out["efficiency"]
        rows.append({"case": "Monte Carlo", "blades": out["blades"], "damper": damper, "workers": n,
                     "samples": samples, "failed": out["failed"], "wall_s": wall,
                     "samples_per_min": 60 * samples / wall, "chunks": e["chunks"],
                     "chunk_size": e["chunk_size"], "sample_phase_wall_s": e["wall_s"],
                     "cpu_s": e["cpu_s"], "cpu_per_sample_s": e["cpu_s"] / samples,
                     "efficiency": e["efficiency"],
                     "sample_s_median": float(np.median([s["time_s"] for s in ok])),
                     "max_amplification": out["max_amplification"],
                     "load_avg_before": load0, "load_avg_after": os.getloadavg()[0]})
        serial = next((r for r in rows if r.get("workers") == 0), None)
        if serial is not None and n > 0:   # against the serial run of the same study
            rows[-1]["speedup_vs_serial"] = serial["sample_phase_wall_s"] / e["wall_s"]
            rows[-1]["efficiency_vs_serial"] = rows[-1]["speedup_vs_serial"] / n
        print(_fmt(rows[-1]), flush=True)
    # memory of one sample (tracemalloc traces numpy's buffers; a separate, untimed run)
    from damper.mistuning import fingerprint, sample_key, tuned_reference

    cfg = study.load()
    ref = tuned_reference(study, cfg)
    kappa = draw_factors(cfg.blades, 0.02, 1, 0)
    with tempfile.TemporaryDirectory() as tmp:
        task = {"study": study.__dict__, "index": 0, "kappa": kappa.tolist(), "band_hz": ref["band_hz"],
                "tuned_frequency_hz": ref["tuned_frequency_hz"], "folder": tmp, "max_bytes": 2**30,
                "key": sample_key(study, fingerprint(cfg), ref["band_hz"], kappa)}
        tracemalloc.start()
        run_sample(task)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    rows.append({"case": "memory per sample", "blades": cfg.blades, "traced_peak_mib": peak / 2**20})
    print(_fmt(rows[-1]), flush=True)
    return rows


def worst_rows(blades, samples: int) -> list:
    """The ``worst`` rows (module docstring)."""
    from scipy.optimize import differential_evolution

    from damper.cache import Store
    from damper.mistuning import Study, run_study
    from damper.mistuning_worst import _linear_search
    from harmonic_balance.bladed_disk.mistuning import whitehead_bound

    std, b, rows = 0.02, 0.06, []
    for nb in blades:
        eo = max(1, nb // 4)
        study = Study(blades=nb, engine_order=eo, std=std, damper="free", seed=1)
        c0 = time.process_time()
        r, peak, (_, a_t), _ = _linear_search(study, b, 32)
        t_worst = time.process_time() - c0
        c0 = time.process_time()
        with tempfile.TemporaryDirectory() as tmp:
            mc = run_study(Study(blades=nb, engine_order=eo, std=std, damper="free", seed=3, samples=samples,
                                 distribution="uniform"), Store(tmp), serial=True, echo=lambda t: None)
        t_mc = time.process_time() - c0
        row = {"case": "worst pattern, linear", "blades": nb, "damper": "free", "std": std, "bound": b,
               "amplification": r["peak"] / a_t, "worst_cpu_s": t_worst, "evaluations": r["evaluations"],
               "random_samples": samples - mc["failed"], "random_max": mc["max_amplification"],
               "random_cpu_s": t_mc, "whitehead_bound": whitehead_bound(nb)}
        row["above_random"] = row["amplification"] > row["random_max"]
        row["below_whitehead"] = row["amplification"] < row["whitehead_bound"]
        if nb <= 6:
            c0 = time.process_time()
            de = differential_evolution(lambda k, p=peak: -p.peak(k)[0], [(1 - b, 1 + b)] * nb,
                                        seed=20261127, tol=1e-7, popsize=10, polish=True)
            row |= {"de_amplification": -de.fun / a_t, "de_cpu_s": time.process_time() - c0,
                    "de_evaluations": int(de.nfev)}
            row["rel_diff_de"] = row["amplification"] / row["de_amplification"] - 1
            row["within_1pct_of_de"] = abs(row["rel_diff_de"]) <= 0.01
        rows.append(row)
        print(_fmt(row), flush=True)
    return rows


def worst_friction_rows(blades, evaluations: int) -> list:
    """The ``worst_friction`` rows (module docstring)."""
    from damper.mistuning import Study
    from damper.mistuning_worst import run_worst_friction

    rows = []
    for nb in blades:
        c0 = time.process_time()
        out = run_worst_friction(Study(blades=nb, engine_order=max(1, nb // 4), std=0.02),
                                 max_evaluations=evaluations)
        c = out["timeint_check"]
        rows.append({"case": "worst pattern, friction", "blades": nb, "std": 0.02, "bound": out["bound"],
                     "harmonics": out["harmonics"], "amplification": out["amplification"],
                     "frequency_hz": out["frequency_hz"], "worst_blade": out["worst_blade"],
                     "starts": {s["label"]: s["amplification"] for s in out["starts"]},
                     "converged": out["converged"], "message": out["message"],
                     "evaluations": out["evaluations"], "failures": len(out["failures"]),
                     "timeint_rel_diff": c["rel_diff"], "timeint_within_1pct": c["within_1_percent"],
                     "timeint_rel_diff_h15": c["rel_diff_check"], "timeint_periods": c["periods"],
                     "whitehead_bound": out["whitehead_bound"], "factors": out["factors"],
                     "cpu_s": time.process_time() - c0, "wall_s": out["time_s"]})
        print(_fmt(rows[-1]), flush=True)
    return rows


def confidence_rows(n: int, blades: int | None) -> list:
    """The ``confidence`` row (``examples/mistuning_confidence.py`` on a fresh cache)."""
    import importlib.util

    from damper.cache import Store

    spec = importlib.util.spec_from_file_location("mistuning_confidence",
                                                  Path(__file__).with_name("mistuning_confidence.py"))
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    with tempfile.TemporaryDirectory() as tmp:
        row = conf.confidence_row(n, "free", Store(tmp), blades)[0]
    for line in conf.row_lines(row):
        print(line, flush=True)
    return [row]


def _fmt(row: dict) -> str:
    return "  ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items())


def main(argv=None) -> int:
    from damper.script import out_folder

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=out_folder, default=Path("out/bench_mistuning"))
    p.add_argument("--rows", nargs="+", default=["scaling", "precond", "throughput"],
                   choices=("scaling", "band", "factor", "precond", "throughput", "worst", "worst_friction",
                            "confidence"))
    p.add_argument("--samples", type=int, default=8, help="Monte Carlo samples per cluster size")
    p.add_argument("--workers", type=int, nargs="+",
                   help="Dask local-cluster sizes of the throughput rows (0: this process; "
                   "default 1 2, --quick 0)")
    p.add_argument("--damper", choices=("nonlinear", "free", "stuck"), default="nonlinear",
                   help="the throughput rows' damper (free/stuck: the cheap linear limits)")
    p.add_argument("--quick", action="store_true",
                   help="N_b = 4, 8 only; one scatter; 2 samples in this process (no Dask cluster)")
    p.add_argument("--factor-blades", type=int, nargs="+", default=[24],
                   help="N_b of the factor rows (EO = N_b / 4)")
    p.add_argument("--worst-blades", type=int, nargs="+", default=[6, 24],
                   help="N_b of the worst rows (differential evolution for N_b <= 6)")
    p.add_argument("--worst-samples", type=int, default=1000,
                   help="random patterns the worst rows compare with")
    p.add_argument("--worst-friction-blades", type=int, nargs="+", default=[24],
                   help="N_b of the worst_friction rows")
    p.add_argument("--worst-evaluations", type=int, default=25,
                   help="ring curves per start of the worst_friction rows")
    p.add_argument("--confidence-samples", type=int, default=1000,
                   help="samples of the confidence row's first study (>= 72; the second: 4x)")
    p.add_argument("--confidence-blades", type=int,
                   help="N_b of the confidence row (EO = N_b / 4; default UPD-24's 24)")
    a = p.parse_args(argv)
    if a.confidence_samples < 72:
        p.error("--confidence-samples must be >= 72 (the 0.95 quantile's interval needs them)")
    if a.samples < 1:
        p.error("--samples must be >= 1")
    rows = []
    if "scaling" in a.rows:
        rows += scaling_rows((4, 8) if a.quick else (4, 8, 24, 48))
    if "band" in a.rows:
        rows += band_rows(a.samples)
    if "factor" in a.rows:
        for nb in ([4] if a.quick else a.factor_blades):
            rows += factor_rows(1 if a.quick else a.samples, nb)
    if "precond" in a.rows:
        rows += precond_rows((0.02,) if a.quick else (0.002, 0.005, 0.02), nb=8 if a.quick else 24)
    if "throughput" in a.rows:
        workers = a.workers or ((0,) if a.quick else (1, 2))
        rows += throughput_rows(a.samples if a.workers or not a.quick else 2, workers, a.damper)
    if "worst" in a.rows:
        rows += worst_rows([4] if a.quick else a.worst_blades, 20 if a.quick else a.worst_samples)
    if "worst_friction" in a.rows:
        rows += worst_friction_rows([4] if a.quick else a.worst_friction_blades,
                                    2 if a.quick else a.worst_evaluations)
    if "confidence" in a.rows:
        rows += confidence_rows(80 if a.quick else a.confidence_samples,
                                8 if a.quick else a.confidence_blades)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "bench_mistuning.json").write_text(json.dumps(rows, indent=1, default=str) + "\n")
    print(f"table in {a.out / 'bench_mistuning.json'}")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
