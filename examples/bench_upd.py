"""Benchmark of the UPD-24 sector harmonic balance (table and plot; not a timed test).

Cases: one 200-point curve (H = 7); the optimal-load curve (20 loads, H = 7); the
peak against the ring time integration (TI) at CF/F0 = 2, 4, 20 for H = 1, 3, 5, 7, 9,
with the TI's step error (2x steps) and settling error.

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

BAND = (400.0, 500.0)


def curve_case(sector, H, points):
    hb = SectorHB(sector, H)
    c = frf(hb, 2 * np.pi * np.linspace(*BAND, points))
    return {"case": f"{points}-point curve H={H}", "time_s": c.time_s,
            "peak_hz": c.peak_omega / 2 / np.pi, "peak_amplitude": c.peak_amplitude,
            "evaluations": c.evaluations}


def hb_peak(sector, cf, H, points=40):
    hb = SectorHB(sector, H, cf=cf)
    t0 = time.perf_counter()
    c = frf(hb, 2 * np.pi * np.linspace(*BAND, points))
    return c, hb, time.perf_counter() - t0


def ti_case(sector, ratio, Hs, periods, step_check):
    """TI peak (parabola through 3 frequencies around the H = 7 peak) and HB peaks per H."""
    cf = ratio * sector.cfg.f0
    c7, hb7, _ = hb_peak(sector, cf, 7)
    w = c7.peak_omega * np.array([0.995, 1.0, 1.005])
    t0 = time.perf_counter()
    ti = march_ring(sector, w, cf=cf, max_periods=periods, tol=1e-7)
    t_ti = time.perf_counter() - t0
    a, b, c = np.polyfit(w, ti["amplitude"], 2)
    ti_peak = c - b * b / (4 * a)
    row = {"cf_over_f0": ratio, "ti_peak": ti_peak, "ti_time_s_3_freqs": t_ti,
           "ti_periods": ti["periods"], "ti_steps_per_period": ti["steps_per_period"],
           "ti_settle_change": float(np.max(ti["settle_error"])),
           "ti_blade_spread": float(np.ptp(ti["amplitude_blades"][1]) / ti["amplitude"][1]),
           "ti_phase_error_rad": float(np.abs(ti["phase_steps"][1] - sector.cfg.phi).max()),
           "lift_off_h7": hb7.contact_summary(c7.peak_x)["lift_off"]}
    if step_check:
        ti2 = march_ring(sector, w[1:2], cf=cf, max_periods=periods, tol=1e-7,
                         steps_per_period=2 * ti["steps_per_period"])
        row["ti_step_error"] = float(ti2["amplitude"][0] / ti["amplitude"][1] - 1)
    for H in Hs:
        c, _, t = hb_peak(sector, cf, H)
        row[f"H{H}"] = {"peak": c.peak_amplitude, "err_vs_ti": c.peak_amplitude / ti_peak - 1,
                        "time_s": t}
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/bench_upd")
    ap.add_argument("--quick", action="store_true", help="smoke version (seconds)")
    ap.add_argument("--periods", type=int, default=150, help="TI periods per load")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    sector = Sector(load_config())
    q = a.quick
    rows = {"curve": curve_case(sector, 3 if q else 7, 20 if q else 200)}
    print(rows["curve"], flush=True)
    opt = optimal_load(sector, (30, 3000), 4 if q else 20, 3 if q else 7, grid=15 if q else 40)
    rows["optimize"] = opt
    print({k: opt[k] for k in ("optimum_cf", "optimum_peak_amplitude", "time_s", "method")}, flush=True)
    Hs = (1, 3) if q else (1, 3, 5, 7, 9)
    rows["ti"] = []
    for r in (4,) if q else (2, 4, 20):
        rows["ti"].append(ti_case(sector, r, Hs, 3 if q else a.periods, not q))
        print(rows["ti"][-1], flush=True)
    (out / "bench_upd.json").write_text(json.dumps(rows, indent=1, default=float))
    _table(rows)
    _plot(rows, out)
    return rows


def _table(rows):
    print("\ncase | size | error | time [s]")
    c = rows["curve"]
    print(f"{c['case']} | {c['evaluations']} evaluations | - | {c['time_s']:.2f}")
    o = rows["optimize"]
    print(f"optimal-load curve | {len(o['cf'])} loads | - | {o['time_s']:.1f}")
    for r in rows["ti"]:
        for k, v in r.items():
            if k.startswith("H"):
                print(f"CF/F0={r['cf_over_f0']} {k} | peak {v['peak']:.5e} m | {v['err_vs_ti']:+.2%} "
                      f"vs TI | {v['time_s']:.2f}")
        print(f"CF/F0={r['cf_over_f0']} TI | {r['ti_periods']} periods x {r['ti_steps_per_period']} "
              f"steps | step {r.get('ti_step_error', float('nan')):+.1e}, settle "
              f"{r['ti_settle_change']:.1e} | {r['ti_time_s_3_freqs']:.1f} (3 freqs)")


def _plot(rows, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    o = rows["optimize"]
    ax[0].loglog(o["cf"], np.array(o["peak_amplitude"]) * 1e3, "o-")
    ax[0].loglog([o["optimum_cf"]], [o["optimum_peak_amplitude"] * 1e3], "r*", ms=12)
    ax[0].set_xlabel("CF [N]")
    ax[0].set_ylabel("peak [mm]")
    for r in rows["ti"]:
        Hs = [int(k[1:]) for k in r if k.startswith("H")]
        ax[1].semilogy(Hs, [abs(r[f"H{H}"]["err_vs_ti"]) for H in Hs], "o-",
                       label=f"CF/F0={r['cf_over_f0']}")
    ax[1].set_xlabel("H")
    ax[1].set_ylabel("|HB peak / TI peak - 1|")
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(out / "bench_upd.png", dpi=110)


if __name__ == "__main__":
    main()
