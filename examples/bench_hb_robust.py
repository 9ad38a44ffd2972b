"""Robustness benchmark of the HB solver: convergence map and cost vs contact stiffness.
================================================================================================

Run:  .venv/bin/python examples/bench_hb_robust.py [--smoke | --full] [--harmonics 1,3]
          [--log map.csv] [--no-cost | --cost-only] [--den-hartog | --den-hartog-hb]

Model: single-DOF Jenkins oscillator m = k = 1 (``harmonic_balance.bench_models.sdof``),
forcing P = 1 cos(omega t), sweep 0.5 -> 2 rad/s (start below resonance), 1 -> 2 (start
at resonance) and 2 -> 0.5 (start above, sweeping down), no tuning (library defaults).

Table 1 (convergence map): contact stiffness ratio kt/k, slip force fs/P, damping c,
harmonics H and the three starts; per (H, kt/k) the number of curves converged over
the whole range (complete AND without restart gaps), and every failure with where it
stopped. Default grid: kt/k in {1e-3, 1, 30, 1e3, 1e4, 1e6}, fs/P in {1e-3, 0.5, 10},
c in {1e-4, 0.04, 0.5}, H in {1, 7, 21}; ``--full`` the whole grid (kt/k
1e-3..1e6 by decades, fs/P 1e-3..10, c 1e-4..0.5, H = 1, 3, 7, 21, 51: 3750 curves,
many hours; ``--harmonics`` picks a subset of H, ``--log`` keeps one CSV line per
curve).

Table 2 (cost vs stiffness): the reference case (``harmonic_balance.bench_models.sdof``,
c = 0.04, fs = 0.5, H = 15, 0.5 -> 2 rad/s, no peak refinement; ``damper bench --stage
hb`` runs it at 1, 1e4 and 1e6 k with the command's defaults): points, Newton iterations
and residual evaluations per point, the cost of one residual evaluation and time per
point against kt/k (goal: no worse than 2x the soft-contact cost at 1e6). To compare
revisions, run this table (``--cost-only``) from a worktree of each, back to back.

Table 3 (``--den-hartog``): HB (H = 21) and time integration of the same elastic
model against Den Hartog's rigid-Coulomb steady state at 1e3 and 1e5 k, 0.5-2 rad/s.
Table 4 (``--den-hartog-hb``): the HB alone against Den Hartog at 1e5 and 1e6 k, H = 21
and 51 (how the error falls with H where the elastic model is near the rigid one).

Wall times depend on the machine's load; nothing here gates CI. The last full run's
numbers: README.md at revision c58d443, section "Harmonic balance on stiff contacts".
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import itertools  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from harmonic_balance import bench_models as bm  # noqa: E402
from harmonic_balance.denhartog import den_hartog  # noqa: E402
from harmonic_balance.frf import TOL_REL, FRFError, FRFProblem, compute_frf, exact_links, stiff_samples  # noqa: E402
from harmonic_balance.start import homotopy_start  # noqa: E402
from harmonic_balance.timeint import steady_curve  # noqa: E402

STARTS = {"below": (0.5, 2.0), "at": (1.0, 2.0), "above": (2.0, 0.5)}
GRID = dict(kt=(1e-3, 1.0, 30.0, 1e3, 1e4, 1e6), fs=(1e-3, 0.5, 10.0), c=(1e-4, 0.04, 0.5),
            H=(1, 7, 21))
FULL = dict(kt=tuple(10.0**e for e in range(-3, 7)), fs=(1e-3, 1e-2, 0.1, 1.0, 10.0),
            c=(1e-4, 1e-3, 1e-2, 0.1, 0.5), H=(1, 3, 7, 21, 51))
SMOKE = dict(kt=(1.0, 30.0), fs=(0.5,), c=(0.04,), H=(3,))
#: Point limit per curve (a curve that needs more counts as failed).
MAX_POINTS = 3000


def one_curve(kt, fs, c, H, start, details=False, eval_point=False):
    """(converged, points, iterations, seconds, message) of one curve; with ``details``
    also (residual evaluations, AFT samples, gaps), with ``eval_point`` then the curve's
    problem and middle point (problem, x, omega) for :func:`_eval_ms`. Converged:
    complete with no gap."""
    t0 = time.perf_counter()
    try:
        case = bm.sdof(kt, damping=c, slip_force=fs, harmonics=H, band=STARTS[start])
        r = compute_frf(case.model(), case.harmonics, case.band, refine=False,
                        stability=False, max_points=MAX_POINTS)
        # a curve with restart gaps has stretches without points: not converged over the
        # whole range
        ok = not r.extra.get("gaps")
        msg = "" if ok else r.status[:160]
    except FRFError as err:
        r, ok, msg = err.result, False, str(err)[:160]
    out = (ok, r.points, r.newton_iterations, time.perf_counter() - t0, msg)
    if not details:
        return out
    out += (r.evaluations, r.n_t, len(r.extra.get("gaps", ())))
    i = r.points // 2
    return out + ((r.problem, r.solutions[i], r.omega[i]),) if eval_point else out


def _eval_ms(points, rounds=7, n=30):
    """Cost of one residual evaluation [ms] at each (problem, x, omega): the minimum over
    ``rounds`` batches of ``n``, the points interleaved in every round so that the
    machine's load weighs on all alike."""
    best = [float("inf")] * len(points)
    for _ in range(rounds):
        for k, (prob, x, w) in enumerate(points):
            t0 = time.perf_counter()
            for _ in range(n):
                prob(x, w)
            best[k] = min(best[k], (time.perf_counter() - t0) / n)
    return [1e3 * b for b in best]


def convergence_map(grid, log=None):
    """Every curve of ``grid``, H by H (cheapest first), one row per (H, kt/k).

    ``log``: open text file that gets one CSV line per curve as it finishes (a long
    run stopped early keeps its rows).
    """
    print("\nTable 1: convergence map (curves completed over the whole range)")
    print(f"{'H':>3} {'kt/k':>8} {'done':>6} {'total':>6} {'s/curve':>8}")
    rows, fails = [], []
    for H, kt in itertools.product(grid["H"], grid["kt"]):
        n_ok = n = 0
        t_all = 0.0
        for fs, c, start in itertools.product(grid["fs"], grid["c"], STARTS):
            ok, pts, it, t, msg, nev, n_t, gaps = one_curve(kt, fs, c, H, start, details=True)
            rows.append((kt, fs, c, H, start, ok, pts, it, t))
            if log is not None:
                log.write(f"{H},{kt:g},{fs:g},{c:g},{start},{int(ok)},{pts},{it},{t:.3f},"
                          f"{nev},{n_t},{gaps},\"{msg}\"\n")
                log.flush()
            n += 1
            n_ok += ok
            t_all += t
            if not ok:
                fails.append((kt, fs, c, H, start, msg))
        print(f"{H:>3} {kt:>8.0e} {n_ok:>6} {n:>6} {t_all / n:>8.2f}", flush=True)
    print(f"failures ({len(fails)}):")
    for kt, fs, c, H, start, msg in fails:
        print(f"  kt/k={kt:.0e} fs/P={fs:g} c={c:g} H={H} start={start}: {msg}")
    return rows, fails


def cost_table(kts, H=15):
    print(f"\nTable 2: reference case (c = 0.04, fs = 0.5, H = {H}, 0.5 -> 2 rad/s) vs stiffness")
    curves = [one_curve(kt, 0.5, 0.04, H, "below", True, True) for kt in kts]
    ms = _eval_ms([cv[-1] for cv in curves])
    print("(ms/eval: one residual evaluation, best of 7 x 30 interleaved over the rows; "
          "est/pt = eval/pt x ms/eval, less load-dependent than the wall ms/pt)")
    print(f"{'kt/k':>8} {'ok':>3} {'n_t':>5} {'points':>6} {'gaps':>4} {'iter/pt':>7} "
          f"{'eval/pt':>7} {'ms/eval':>7} {'est/pt':>7} {'ms/pt':>7} {'time_s':>7}")
    out = []
    for kt, (ok, pts, it, t, msg, nev, n_t, gaps, _), me in zip(kts, curves, ms):
        out.append((kt, ok, pts, it, t, nev, me))
        n = max(pts, 1)
        print(f"{kt:>8.0e} {'yes' if ok else 'no':>3} {n_t:>5} {pts:>6} {gaps:>4} {it / n:>7.2f} "
              f"{nev / n:>7.2f} {me:>7.3f} {me * nev / n:>7.2f} {1e3 * t / n:>7.2f} {t:>7.2f}"
              + ("" if ok else f"  {msg[:70]}"), flush=True)
    return out


def rerun_failed(files, log=None):
    """Re-run the failed curves (ok = 0) of ``--log`` CSV files; one CSV line each."""
    import csv

    rows = [r for f in files for r in csv.DictReader(open(f)) if r["ok"] == "0"]
    out = open(log, "w") if log else None
    head = "H,kt,fs,c,start,ok,points,iterations,seconds,evaluations,n_t,gaps,message"
    print(head)
    if out is not None:
        out.write(head + "\n")
    res = []
    for r in rows:
        H, kt, fs, c, st = int(r["H"]), float(r["kt"]), float(r["fs"]), float(r["c"]), r["start"]
        ok, pts, it, t, msg, nev, n_t, gaps = one_curve(kt, fs, c, H, st, details=True)
        line = f"{H},{kt:g},{fs:g},{c:g},{st},{int(ok)},{pts},{it},{t:.3f},{nev},{n_t},{gaps},\"{msg}\""
        print(line, flush=True)
        if out is not None:
            out.write(line + "\n")
            out.flush()
        res.append((kt, fs, c, H, st, ok))
    return res


def den_hartog_table(kts=(1e3, 1e5), omegas=(0.5, 0.75, 1.0, 1.5, 2.0), H=21):
    """Table 3: HB (H) and time integration of the same elastic Jenkins model against
    Den Hartog's rigid-Coulomb steady state (c = 0.04, fs = 0.5, P = 1)."""
    print(f"\nTable 3: Jenkins (c = 0.04, fs = 0.5 P) vs Den Hartog's rigid Coulomb, HB at H = {H}")
    print(f"{'kt/k':>8} {'omega':>6} {'DH':>9} {'HB':>9} {'TI':>9} {'HB/TI-1':>9} {'HB/DH-1':>9} "
          f"{'TI/DH-1':>9} {'TI_step':>8}")
    out = []
    for kt in kts:
        m = exact_links(bm.sdof(kt).model())   # as compute_frf
        prob = FRFProblem(m, H, stiff_samples(m, H))
        ti, _, err, _ = steady_curve(m, np.array(omegas), 512)
        for w, a_ti, e in zip(omegas, ti, err):
            x, _ = homotopy_start(prob, w, TOL_REL * prob.reference(w))
            a_hb, a_dh = prob.amplitude(x, w), den_hartog(1.0, 0.04, 1.0, 0.5, 1.0, w).amplitude
            out.append((kt, w, a_dh, a_hb, a_ti, e))
            print(f"{kt:>8.0e} {w:>6.2f} {a_dh:>9.6f} {a_hb:>9.6f} {a_ti:>9.6f} {a_hb / a_ti - 1:>+9.1e} "
                  f"{a_hb / a_dh - 1:>+9.1e} {a_ti / a_dh - 1:>+9.1e} {e:>8.1e}", flush=True)
    return out


def hb_vs_den_hartog(kts=(1e5, 1e6), Hs=(21, 51), omegas=(0.5, 0.75, 1.0, 1.5, 2.0)):
    """Table 4: the HB alone (no time integration, which at 1e6 k needs 1e-3 of the stuck
    period per step) against Den Hartog, by stiffness and H: HB/DH - 1 per omega."""
    print("\nTable 4: HB / Den Hartog - 1 (c = 0.04, fs = 0.5 P) by stiffness and H")
    print(f"{'kt/k':>8} {'H':>3} {'n_t':>5} " + " ".join(f"{w:>9.2f}" for w in omegas))
    out = []
    for kt in kts:
        m = exact_links(bm.sdof(kt).model())   # as compute_frf
        for H in Hs:
            prob = FRFProblem(m, H, stiff_samples(m, H))
            errs = []
            for w in omegas:
                x, _ = homotopy_start(prob, w, TOL_REL * prob.reference(w))
                errs.append(prob.amplitude(x, w) / den_hartog(1.0, 0.04, 1.0, 0.5, 1.0, w).amplitude - 1)
            out.append((kt, H, errs))
            print(f"{kt:>8.0e} {H:>3} {prob.basis.n_t:>5} " + " ".join(f"{e:>+9.1e}" for e in errs),
                  flush=True)
    return out


def main(argv=None):
    from damper.script import numbers

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="tiny grid (the test)")
    ap.add_argument("--full", action="store_true", help="the whole grid (hours)")
    ap.add_argument("--harmonics", type=numbers(int, 1), help="comma-separated subset of the grid's H (e.g. 1,3)")
    ap.add_argument("--stiffness", type=numbers(float),
                    help="comma-separated subset of the grid's kt/k (e.g. 1e5,1e6): "
                    "split a long map over processes or finish a partial one")
    ap.add_argument("--log", help="CSV file: one line per curve as it finishes")
    ap.add_argument("--no-cost", action="store_true", help="skip table 2")
    ap.add_argument("--cost-only", action="store_true", help="skip table 1")
    ap.add_argument("--rerun-failed", nargs="+", metavar="CSV",
                    help="re-run the failed curves of --log files (e.g. after a solver change)")
    ap.add_argument("--den-hartog", action="store_true",
                    help="only table 3 (HB and time integration vs Den Hartog, minutes)")
    ap.add_argument("--den-hartog-hb", action="store_true",
                    help="only table 4 (HB alone vs Den Hartog at 1e5, 1e6 k, H = 21, 51)")
    args = ap.parse_args(argv)
    if args.den_hartog_hb:
        return {"hb_vs_den_hartog": hb_vs_den_hartog()}
    if args.den_hartog:
        return {"den_hartog": den_hartog_table()}
    if args.rerun_failed:
        return {"rerun": rerun_failed(args.rerun_failed, args.log)}
    grid = dict(SMOKE if args.smoke else FULL if args.full else GRID)
    if args.harmonics:
        grid["H"] = tuple(args.harmonics)
    if args.stiffness:
        grid["kt"] = tuple(args.stiffness)
    log = open(args.log, "w") if args.log else None
    if log is not None:
        log.write("H,kt,fs,c,start,ok,points,iterations,seconds,evaluations,n_t,gaps,message\n")
    rows, fails = ([], []) if args.cost_only else convergence_map(grid, log)
    if args.no_cost:
        return {"map": rows, "failures": fails, "cost": []}
    kts = (1.0, 30.0) if args.smoke else (1.0, 10.0, 30.0, 100.0, 1e3, 1e4, 1e5, 1e6)
    cost = cost_table(kts, H=3 if args.smoke else 15)
    return {"map": rows, "failures": fails, "cost": cost}


if __name__ == "__main__":
    import sys

    from damper.script import run as run_script

    sys.exit(run_script(main))
