"""UPD-24 with contacts from geometry against the TOML's Jenkins contacts (table; not a test).
===========================================================================================

Per contact choice ("toml": the default Jenkins points, "geometry": contact_core's laws
of ``damper.upd_geometry`` at the config's CF):

1. the HB curve at the config's CF (H = 7, 200 points): peak, lift-off, mean loads;
2. the ring time integration (TI) at that CF at five frequencies around the HB peak, and
   the HB's relative difference there;
3. the TI peak against CF (2 Hz frequency grid per load, parabola through the largest
   three) and the optimal load from a parabola in log CF through the lowest three, the
   reference where the HB sweep does not converge (geometry contacts below ~90 N).

    OPENBLAS_NUM_THREADS=1 nice python examples/upd_geometry_compare.py [--quick] [--json F]

The full run takes ~20 min on a loaded 2-core machine (mostly TI); ``--quick`` (grid-7
contacts, one load, few periods) is the smoke version the tests run.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from damper.cache import Store
from damper.upd_geometry import with_geometry_contacts
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf
from harmonic_balance.bladed_disk.timeint import march_ring

#: TI load scans [N] and frequency bands [Hz] around each choice's peaks (measured).
SCANS = {"toml": ([100.0, 131.0, 165.0], (436.0, 462.0)),
         "geometry": ([60.0, 65.0, 70.0, 75.0], (444.0, 468.0))}


def sector_of(choice: str, cfg, store):
    """The sector with the choice's contacts (and the geometry report, or None)."""
    if choice == "toml":
        return Sector(cfg), None
    cfg2, report = with_geometry_contacts(cfg, None, store)
    return Sector(cfg2), report


def hb_row(sector, H: int, points: int, band) -> dict:
    hb = SectorHB(sector, H)
    c = frf(hb, 2 * np.pi * np.linspace(*band, points))
    s = hb.contact_summary(c.peak_x)
    return {"peak_hz": c.peak_omega / 2 / np.pi, "peak_amplitude": c.peak_amplitude,
            "lift_off": list(s["lift_off"]), "normal_load_mean": list(s["normal_load_mean"]),
            "time_s": c.time_s, "curve": c}


def ti_against_hb(sector, row: dict, periods: int) -> dict:
    """TI at five points of the HB curve's grid around its peak (+-10 Hz, +-3 Hz, peak)."""
    c = row["curve"]
    step = (c.omega[1] - c.omega[0]) / (2 * np.pi)
    i0 = int(np.argmax(c.amplitude))
    idx = np.clip(i0 + np.round(np.array([-10.0, -3.0, 0.0, 3.0, 10.0]) / step).astype(int),
                  0, c.omega.size - 1)
    t0 = time.perf_counter()
    ti = march_ring(sector, c.omega[idx], max_periods=periods, tol=1e-5)
    rel = c.amplitude[idx] / ti["amplitude"] - 1.0
    return {"freq_hz": (c.omega[idx] / (2 * np.pi)).tolist(), "ti": ti["amplitude"].tolist(),
            "hb_minus_ti": rel.tolist(), "settle": float(np.max(ti["settle_error"])),
            "time_s": time.perf_counter() - t0}


def ti_scan(sector, cfs, band, periods: int) -> dict:
    """TI peak per load (parabola through the largest three of a 2 Hz grid) and the optimum."""
    fr = np.arange(band[0], band[1] + 0.1, 2.0)
    peaks = []
    for cf in cfs:
        a = march_ring(sector, 2 * np.pi * fr, cf=cf, max_periods=periods, tol=1e-5)["amplitude"]
        i = min(max(int(np.argmax(a)), 1), a.size - 2)
        y0, y1, y2 = a[i - 1:i + 2]
        d = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
        peaks.append(float(y1 - 0.25 * (y0 - y2) * d))
    out = {"cf": list(cfs), "ti_peak": peaks}
    j = int(np.argmin(peaks))
    if 0 < j < len(peaks) - 1:
        c = np.polyfit(np.log(cfs[j - 1:j + 2]), peaks[j - 1:j + 2], 2)
        xm = -c[1] / (2 * c[0])
        out |= {"optimum_cf": float(np.exp(xm)), "optimum_peak": float(np.polyval(c, xm))}
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke: grid-7 contacts, one load, few periods")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--cache-dir", default=None, help="store of the contact results")
    ap.add_argument("--only", choices=tuple(SCANS), help="run one contact choice")
    args = ap.parse_args(argv)
    cfg, store = load_config(), Store(args.cache_dir)
    points, periods, band = (12, 4, (440.0, 500.0)) if args.quick else (200, 2000, (400.0, 500.0))
    if args.quick:
        cfg = cfg.with_values(geometry__grid=7, load__cf=300.0)
    out = {}
    for choice, (cfs, scan_band) in SCANS.items():
        if args.only and choice != args.only:
            continue
        sector, report = sector_of(choice, cfg, store)
        row = hb_row(sector, 3 if args.quick else 7, points, band)
        res = {k: v for k, v in row.items() if k != "curve"}
        res["ti_vs_hb"] = ti_against_hb(sector, row, periods)
        res["ti_scan"] = ti_scan(sector, cfs[:1] if args.quick else cfs, scan_band, periods)
        if report is not None:
            res["contacts"] = {k: {q: v[q] for q in ("k_n", "k_t", "slip_force", "time_s")}
                               for k, v in report["contacts"].items()}
        out[choice] = res
        print(f"{choice:8s} HB peak {res['peak_hz']:.2f} Hz {res['peak_amplitude'] * 1e3:.4f} mm, "
              f"lift-off {np.round(res['lift_off'], 3).tolist()}; HB - TI at 5 freqs "
              f"{np.round(100 * np.array(res['ti_vs_hb']['hb_minus_ti']), 2).tolist()} %")
        s = res["ti_scan"]
        print(f"{'':8s} TI peak vs CF: " + ", ".join(f"{c:g} N {p * 1e3:.4f} mm" for c, p in
                                                   zip(s["cf"], s["ti_peak"]))
              + (f"; optimum {s['optimum_cf']:.1f} N {s['optimum_peak'] * 1e3:.4f} mm"
                 if "optimum_cf" in s else ""), flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return out


if __name__ == "__main__":
    import sys

    from damper.script import run as run_script

    sys.exit(run_script(main))
