"""Benchmark of the UPD-24 sector harmonic balance (table and plot; not a timed test).

Cases: one 200-point curve (H = 7); the optimal-load curve (20 loads); the peak
against the ring time integration at CF/F0 = 2, 4, 20 for H = 1, 3, 5, 7, 9, with the
time integration's step error (2x steps) and settling error.

    OPENBLAS_NUM_THREADS=1 nice python examples/bench_upd.py --out out/bench_upd [--quick]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.optimize import optimal_load
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf
from harmonic_balance.bladed_disk.timeint import march_ring


def curve_case(sector):
    hb = SectorHB(sector, 7)
    c = frf(hb, 2 * np.pi * np.linspace(400, 500, 200))
    return {"case": "200-point curve H=7", "time_s": c.time_s, "peak_hz": c.peak_omega / 2 / np.pi,
            "peak_amplitude": c.peak_amplitude, "evaluations": c.evaluations}


def ti_case(sector, ratio, Hs, periods, fine):
    """Peak of the ring time integration near the H = 7 peak, and HB peaks per H."""
    f0 = sector.cfg.f0
    hb7 = SectorHB(sector, 7, cf=ratio * f0)
    c7 = frf(hb7, 2 * np.pi * np.linspace(400, 500, 60))
    w = c7.peak_omega * np.linspace(0.99, 1.01, 5)
    t0 = time.perf_counter()
    ti = march_ring(sector, w, cf=ratio * f0, max_periods=periods, tol=1e-6)
    t_ti = time.perf_counter() - t0
    # parabola through the three largest TI points -> TI peak
    k = int(np.clip(np.argmax(ti["amplitude"]), 1, len(w) - 2))
    a, b, c = np.polyfit(w[k - 1:k + 2], ti["amplitude"][k - 1:k + 2], 2)
    ti_peak = c - b * b / (4 * a)
    row = {"cf_over_f0": ratio, "ti_peak": ti_peak, "ti_time_s": t_ti, "ti_periods": ti["periods"],
           "ti_steps_per_period": ti["steps_per_period"],
           "ti_settle_error": float(np.max(ti["settle_error"])),
           "ti_phase_steps_rad": ti["phase_steps"][k].tolist(),
           "lift_off_h7": SectorHB(sector, 7, cf=ratio * f0).contact_summary(c7.peak_x)["lift_off"]}
    if fine:
        ti2 = march_ring(sector, w[k:k + 1], cf=ratio * f0, max_periods=periods, tol=1e-6,
                         steps_per_period=2 * ti["steps_per_period"])
        row["ti_step_error"] = float(abs(ti2["amplitude"][0] / ti["amplitude"][k] - 1))
    for H in Hs:
        hb = SectorHB(sector, H, cf=ratio * f0)
        t0 = time.perf_counter()
        c = frf(hb, 2 * np.pi * np.linspace(400, 500, 60))
        row[f"H{H}_peak"] = c.peak_amplitude
        row[f"H{H}_err"] = c.peak_amplitude / ti_peak - 1
        row[f"H{H}_time_s"] = time.perf_counter() - t0
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/bench_upd")
    ap.add_argument("--quick", action="store_true", help="smoke version (few periods, 5 loads)")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    sector = Sector(load_config())
    rows = {"curve": curve_case(sector)}
    print(rows["curve"], flush=True)
    opt = optimal_load(sector, (30, 3000), 5 if a.quick else 20, 7, grid=40)
    rows["optimize"] = {k: opt[k] for k in ("optimum_cf", "optimum_peak_amplitude", "time_s", "method")}
    print(rows["optimize"], flush=True)
    Hs = (1, 3) if a.quick else (1, 3, 5, 7, 9)
    rows["ti"] = [ti_case(sector, r, Hs, 20 if a.quick else 1500, not a.quick)
                  for r in ((4,) if a.quick else (2, 4, 20))]
    for r in rows["ti"]:
        print(r, flush=True)
    (out / "bench_upd.json").write_text(json.dumps(rows, indent=1, default=float))
    _plot(rows, opt, out)


def _plot(rows, opt, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].loglog(opt["cf"], np.array(opt["peak_amplitude"]) * 1e3, "o-")
    ax[0].set_xlabel("CF [N]")
    ax[0].set_ylabel("peak [mm]")
    for r in rows["ti"]:
        Hs = sorted(int(k[1:-5]) for k in r if k.endswith("_peak") and k.startswith("H"))
        ax[1].semilogy(Hs, [abs(r[f"H{H}_err"]) for H in Hs], "o-", label=f"CF/F0={r['cf_over_f0']}")
    ax[1].set_xlabel("H")
    ax[1].set_ylabel("|HB peak / TI peak - 1|")
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(out / "bench_upd.png", dpi=110)


if __name__ == "__main__":
    main()
