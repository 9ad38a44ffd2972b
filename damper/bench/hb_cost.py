"""Cost of a forced-response curve against the number of harmonics: the hb stage's cost rows.

Cases: the 5-mass chain with three Jenkins links (:func:`harmonic_balance.bench_models.chain5`,
swept up, exact links, ``compute_frf``'s defaults) and the UPD-24 sector at CF 120 N,
F0 30 N (``damper upd frf --cf 120 --f0 30``: :class:`~harmonic_balance.bladed_disk.hb.SectorHB`
and :func:`~harmonic_balance.bladed_disk.solve.frf` on the 200-point grid of its band), each
at H in :data:`HARMONICS` (``quick``: :data:`QUICK_HARMONICS`).

A row per (case, H): the curve's points (continuation points), residual evaluations, the
process time of the whole curve (``time_s``: CPU seconds, peak refinement included; less
sensitive than wall time to the load of a shared machine), its time per point, the refined
peak (amplitude, frequency) and the process's peak memory so far. ``error`` is None: the
truncation error of each H is the accuracy rows' subject, not this table's. The curves run
in this process, one after the other, after one warm-up curve at the smallest H (imports,
the C library, caches).
"""
from __future__ import annotations

import time

import numpy as np

from .common import Row, self_peak_mb

#: Harmonics of the cost rows (the full run) and of a quick run, per case.
HARMONICS = {"chain5": (7, 15, 21, 31), "upd24": (7, 15, 21)}
QUICK_HARMONICS = {"chain5": (3, 7), "upd24": (3,)}
#: UPD-24 loads of the rows [N] (the command of the engine's goal).
UPD_CF, UPD_F0 = 120.0, 30.0
#: Frequency points of the UPD-24 grid (``damper upd frf``'s default).
UPD_POINTS = 200

HEAD = (f"{'case':22s} {'H':>3s} {'points':>6s} {'evals':>6s} {'cpu [s]':>8s} {'ms/point':>9s} "
        f"{'peak':>14s} {'at omega':>12s}")


def chain5_curve(H: int) -> dict:
    """One chain5 curve at H: points, evaluations, CPU seconds, peak (amplitude, omega)."""
    from harmonic_balance.bench_models import chain5
    from harmonic_balance.frf import compute_frf

    case = chain5()
    model = case.model()
    t0 = time.process_time()
    r = compute_frf(model, H, case.band)
    cpu = time.process_time() - t0
    return {"points": r.points, "evaluations": r.evaluations, "cpu_s": cpu,
            "peak_amplitude": float(r.peak_amplitude), "peak_omega": float(r.peak_omega)}


def upd24_curve(H: int, sector=None) -> dict:
    """One UPD-24 sector curve at H (CF 120 N, F0 30 N): as :func:`chain5_curve`."""
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.solve import frf

    sector = sector or Sector(load_config(None))
    band = sector.cfg["load.band_hz"]
    omegas = 2 * np.pi * np.linspace(band[0], band[1], UPD_POINTS)
    t0 = time.process_time()
    c = frf(SectorHB(sector, H, cf=UPD_CF, f0=UPD_F0), omegas)
    cpu = time.process_time() - t0
    return {"points": int(c.extra.get("branch_points") or len(c.omega)), "evaluations": c.evaluations,
            "cpu_s": cpu, "peak_amplitude": float(c.peak_amplitude), "peak_omega": float(c.peak_omega)}


CASES = {"chain5": ("chain5 up", chain5_curve), "upd24": ("UPD-24 CF 120 F0 30", upd24_curve)}


def run(quick: bool, log=print, harmonics: dict | None = None) -> list[Row]:
    """The cost rows (module docstring); ``harmonics`` overrides the H per case key."""
    hs = harmonics or (QUICK_HARMONICS if quick else HARMONICS)
    rows = []
    log(HEAD)
    for key, H_list in hs.items():
        name, curve = CASES[key]
        curve(min(H_list))  # warm-up: imports, the C library, caches
        for H in H_list:
            out = curve(H)
            per = out["cpu_s"] / max(out["points"], 1)
            rows.append(Row(f"cost {name}", H, None, out["cpu_s"], self_peak_mb(), False,
                            {"points": out["points"], "evaluations": out["evaluations"],
                             "time_per_point_s": per, "peak_amplitude": out["peak_amplitude"],
                             "peak_omega": out["peak_omega"], "clock": "process"}))
            log(f"{name:22s} {H:3d} {out['points']:6d} {out['evaluations']:6d} {out['cpu_s']:8.2f} "
                f"{1e3 * per:9.2f} {out['peak_amplitude']:14.8g} {out['peak_omega']:12.8g}")
    return rows
