"""UPD-24 as a system of FMUs in libcosim against harmonic balance and the ring time integration.
==============================================================================================

For each centrifugal load (F0 = 30 N): the HB curve (H = 7, the `damper upd frf`
solver) gives the peak; the ring archive of `damper system` is co-simulated
(`damper cosim`, default step) at the HB peak frequency, at +-0.5 % around it (the
co-simulated peak: parabola through the three) and at two frequencies off the peak
(+-2 %); the ring time integration (`harmonic_balance/bladed_disk/timeint.py`, the
same ODE marched by central differences) at the same frequencies is the reference of
the ODE both solve. Prints the comparison table and the cost rows (wall time per
period and to the answer), writes ``upd_cosim.json`` and, at the CF = 120 N peak,
``upd_cosim_period.png`` (co-simulated steady state against the HB periodic solution
over one period). Wall times: the machine is shared, compare within one run. ::

    OPENBLAS_NUM_THREADS=1 nice python examples/upd_cosim.py --out out/upd_cosim [--cf 60 120 600]
    python examples/upd_cosim.py --quick --out out/upd_cosim_quick   # smoke: CF 120, 3 periods
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from damper.cosim import run as cosim
from damper.ring_system import build_ring
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf, solve_point, start_point
from harmonic_balance.bladed_disk.timeint import march_ring
from harmonic_balance.newton import NewtonError

F0 = 30.0
#: Frequencies relative to the HB peak: the peak, the parabola's neighbours, off the peak.
FACTORS = (1.0, 0.995, 1.005, 0.98, 1.02)


def hb_case(sector, cf, H=7, points=40, freqs=None):
    """HB curve (band of the config) and HB solutions at the FACTORS frequencies of its
    peak (or at ``freqs`` [Hz])."""
    hb = SectorHB(sector, H, cf=cf, f0=F0)
    band = sector.cfg["load.band_hz"]
    t0 = time.perf_counter()
    c = frf(hb, 2 * np.pi * np.linspace(band[0], band[1], points))
    t_curve = time.perf_counter() - t0
    fpk = c.peak_omega / (2 * np.pi)
    amps, sols = [], []
    for k, fac in enumerate(FACTORS):
        w = 2 * np.pi * (fpk * fac if freqs is None else freqs[k])
        i = int(np.argmin(np.abs(c.omega - w)))  # start from the nearest curve point
        if fac == 1.0 and freqs is None:
            x = c.peak_x
        else:
            try:
                x = solve_point(hb, w, c.x[i])
            except NewtonError:  # far from the nearest curve point: the sweep's own start
                x = start_point(hb, w)
        amps.append(hb.amplitude_h1(x))
        sols.append(x)
    return {"hb": hb, "peak_hz": fpk, "peak": c.peak_amplitude, "amplitude": amps,
            "x_peak": sols[0], "curve_s": t_curve, "curve_points": len(c.omega)}


def ti_case(sector, cf, freqs, periods):
    t0 = time.perf_counter()
    r = march_ring(sector, 2 * np.pi * np.asarray(freqs), cf=cf, f0=F0, max_periods=periods,
                   tol=1e-6)
    wall = time.perf_counter() - t0
    return {"amplitude": r["amplitude"].tolist(), "periods": r["periods"],
            "steps_per_period": r["steps_per_period"], "wall_s": wall,
            "wall_per_period_s": wall / r["periods"], "settle": np.max(r["settle_error"]).item()}


def parabola_peak(f, a) -> float:
    p = np.polyfit(f, a, 2)
    return float(np.polyval(p, -p[1] / (2 * p[0])))


def load_case(cfg, cf, out, periods, quick, h_ref):
    sector = Sector(cfg)
    h = hb_case(sector, cf)
    freqs = [h["peak_hz"] * fac for fac in FACTORS]
    ref = hb_case(sector, cf, h_ref, freqs=freqs) if h_ref else None
    ssp = out / f"ring_cf{cf:g}.ssp"
    t0 = time.perf_counter()
    info = build_ring(cfg, cf, F0, ssp)
    build_s = time.perf_counter() - t0
    runs = [cosim(ssp, f, periods, keep_last=(k == 0)) for k, f in enumerate(freqs)]
    ti = ti_case(sector, cf, freqs, 3 if quick else 400)
    amp = [r["amplitude"] for r in runs]
    row = {"cf": cf, "hb_peak_hz": h["peak_hz"], "hb_peak": h["peak"], "frequency_hz": freqs,
           "hb": h["amplitude"], "cosim": amp, "ti": ti["amplitude"],
           "cosim_vs_hb": [a / b - 1 for a, b in zip(amp, h["amplitude"])],
           "cosim_vs_ti": [a / b - 1 for a, b in zip(amp, ti["amplitude"])],
           "cosim_peak": parabola_peak(freqs[:3], amp[:3]),
           "ti_peak": parabola_peak(freqs[:3], ti["amplitude"][:3]),
           "cosim_periods": [r["periods"] for r in runs], "settled": [r["settled"] for r in runs],
           "energy_residual": [r["energy"]["relative_residual"] for r in runs],
           "blade_spread": [max(r["amplitude_blades"]) / min(r["amplitude_blades"]) - 1 for r in runs],
           "phase_error": [float(np.max(np.abs(np.array(r["phase_steps"]) - r["interblade_phase"])))
                           for r in runs],
           "step": runs[0]["step"], "steps_per_period": runs[0]["steps_per_period"],
           "step_limit": info["step_limit"], "build_s": build_s,
           "cosim_wall_s": [r["wall_time_s"] for r in runs],
           "cosim_wall_per_period_s": float(np.mean([r["wall_time_per_period_s"] for r in runs])),
           "ti_run": ti, "hb_curve_s": h["curve_s"], "hb_curve_points": h["curve_points"]}
    if ref is not None:  # the HB at a higher H: its truncation error at H = 7
        row |= {"h_ref": h_ref, "hb_ref": ref["amplitude"], "hb_ref_peak": ref["peak"],
                "cosim_vs_hb_ref": [a / b - 1 for a, b in zip(amp, ref["amplitude"])]}
    row["cosim_peak_vs_hb"] = row["cosim_peak"] / h["peak"] - 1
    row["cosim_peak_vs_ti"] = row["cosim_peak"] / row["ti_peak"] - 1
    return row, h, runs[0]


def plot_period(h, run, path):
    """Co-simulated u_a(t) over its last period against the HB periodic solution."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    hb, t, x = h["hb"], np.asarray(run["last_t"]), np.asarray(run["last_response"])
    w = 2 * np.pi * run["frequency_hz"]
    th = np.mod(w * t, 2 * np.pi)
    u_hb = hb.basis.evaluate(hb.response(h["x_peak"]), th)
    order = np.argsort(th)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(th[order], x[order] * 1e3, label=f"co-simulation (libcosim, {len(t)} steps)")
    ax.plot(th[order], u_hb[order] * 1e3, "--", label=f"harmonic balance (H = {hb.H})")
    ax.set_xlabel("phase of the excitation [rad]")
    ax.set_ylabel(f"{run['response_dof']} of blade 0 [mm]")
    ax.set_title(f"UPD-24 ring, CF {run['cf']:g} N, F0 {run['f0']:g} N, {run['frequency_hz']:.2f} Hz")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def print_table(rows):
    print("\nCF [N] | f [Hz] (x HB peak) | HB H=7 [mm] | co-sim [mm] | vs HB | ring TI [mm] | co-sim vs TI "
          "| periods | energy residual")
    for r in rows:
        for k, f in enumerate(r["frequency_hz"]):
            ref = (f" | HB H={r['h_ref']}: {r['hb_ref'][k] * 1e3:.5f} ({r['cosim_vs_hb_ref'][k]:+.2%})"
                   if "h_ref" in r else "")
            print(f"{r['cf']:g} | {f:.3f} ({FACTORS[k]:g}) | {r['hb'][k] * 1e3:.5f} | "
                  f"{r['cosim'][k] * 1e3:.5f} | {r['cosim_vs_hb'][k]:+.2%} | {r['ti'][k] * 1e3:.5f} | "
                  f"{r['cosim_vs_ti'][k]:+.3%} | {r['cosim_periods'][k]} | {r['energy_residual'][k]:+.1e}"
                  + ref)
        print(f"{r['cf']:g} | peak (parabola) | {r['hb_peak'] * 1e3:.5f} | {r['cosim_peak'] * 1e3:.5f} | "
              f"{r['cosim_peak_vs_hb']:+.2%} | {r['ti_peak'] * 1e3:.5f} | {r['cosim_peak_vs_ti']:+.3%} | | ")
    print("\ncase | size | time (wall, shared machine)")
    for r in rows:
        print(f"CF {r['cf']:g} co-sim | {r['steps_per_period']} steps/period x {sum(r['cosim_periods'])} "
              f"periods (5 freqs) | {r['cosim_wall_per_period_s']:.3f} s/period, "
              f"{sum(r['cosim_wall_s']):.0f} s total (+ build {r['build_s']:.1f} s)")
        t = r["ti_run"]
        print(f"CF {r['cf']:g} ring TI | {t['steps_per_period']} steps/period x {t['periods']} periods "
              f"(5 freqs batched) | {t['wall_per_period_s']:.3f} s/period, {t['wall_s']:.0f} s total")
        print(f"CF {r['cf']:g} HB H=7 | {r['hb_curve_points']}-point curve + peak | {r['hb_curve_s']:.1f} s")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/upd_cosim")
    ap.add_argument("--cf", type=float, nargs="+", default=[60.0, 120.0, 600.0])
    ap.add_argument("--periods", type=int, default=400, help="most co-simulated periods per point")
    ap.add_argument("--quick", action="store_true", help="smoke: CF 120 N, 3 periods")
    ap.add_argument("--hb-ref", type=int, default=0, metavar="H",
                    help="also the HB at this H at the same frequencies (its truncation at H = 7)")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_config()
    cfs = [120.0] if a.quick else a.cf
    rows = []
    for cf in cfs:
        row, h, run0 = load_case(cfg, cf, out, 3 if a.quick else a.periods, a.quick, a.hb_ref)
        rows.append(row)
        print(json.dumps({k: v for k, v in row.items() if k != "ti_run"}, default=float), flush=True)
        if cf == 120.0:
            plot_period(h, run0, out / "upd_cosim_period.png")
    (out / "upd_cosim.json").write_text(json.dumps(rows, indent=1, default=float))
    print_table(rows)
    return rows


if __name__ == "__main__":
    import sys

    from damper.script import run as run_script

    sys.exit(run_script(main))
