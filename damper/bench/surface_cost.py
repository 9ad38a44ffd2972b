"""Cost of the UPD-24 sector with contact surfaces per node count and per harmonic: the hb stage's surface rows.

The damper's two faces as contact surfaces (:func:`damper.upd_surface.build_surfaces`,
``--contacts surface``) in the two harmonic-balance models:

* ``condensed``: :class:`~harmonic_balance.bladed_disk.surface_hb.CondensedSurfaceSectorHB`,
  the surfaces condensed onto their rigid inputs, the nodes marched in time inside each
  evaluation (unknowns: the sector's alone);
* ``nodes``: :class:`~harmonic_balance.bladed_disk.surface_hb.SurfaceSectorHB`, every
  node's DOFs unknowns of the harmonic balance (dense Jacobian).

A row per (model, nodes per side, H) (case ``cost surface MODEL H h``, size the nodes
per side): one residual evaluation with its Jacobian and one
without, at the stuck start (:meth:`stuck_guess`) at :data:`CF` and :data:`FREQUENCY_HZ`
(the method page's measuring point), each the median of :data:`REPEATS` (quick: one) in this process
after a first call (the condensed model keeps its block factors across evaluations: the
first call pays for them); the unknowns, the surface nodes, the CPU time per node and per
harmonic coefficient (2H + 1) and the process's peak memory so far. ``error`` is None:
these rows are the cost side (the accuracy of the surface model is the study page's
subject, against the ring time integration). ``time_s`` is process time.
"""
from __future__ import annotations

import time

import numpy as np

from .common import Row, self_peak_mb

#: (model, nodes per side, H) of the full run and of a quick run.
CASES = [("condensed", n, H) for n in (5, 10, 20) for H in (3, 7)] + \
    [("condensed", 5, 1), ("condensed", 5, 5)] + \
    [("nodes", 5, H) for H in (1, 3, 7)] + [("nodes", 10, 3)]
QUICK_CASES = [("condensed", 5, 1), ("nodes", 5, 1)]
#: The measuring point: centrifugal load [N] and frequency [Hz] (near the stuck
#: resonance; docs/method/contact_surface.md's tables use the same).
CF, FREQUENCY_HZ = 300.0, 440.0
#: Timed calls per measurement (median), after one untimed call; a quick run times one.
REPEATS = 3

HEAD = (f"{'model':10s} {'nodes':>5s} {'H':>3s} {'unknowns':>8s} {'surface nodes':>13s} "
        f"{'eval+J [s]':>10s} {'eval [s]':>9s} {'ms/node':>8s} {'ms/coef':>8s} {'MB':>7s}")


def _median_cpu(fun, repeats: int) -> float:
    fun()
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        fun()
        times.append(time.process_time() - t0)
    return float(np.median(times))


def measure(model: str, nodes: int, H: int, sector=None, store=None, repeats: int = REPEATS) -> dict:
    """One case: unknowns, surface nodes, CPU seconds of an evaluation with and without
    the Jacobian (medians)."""
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB, SurfaceSectorHB

    from ..upd_surface import build_surfaces

    sector = sector or Sector(load_config(None))
    surfaces = build_surfaces(sector.cfg, nodes, CF, store)
    cls = CondensedSurfaceSectorHB if model == "condensed" else SurfaceSectorHB
    hb = cls(sector, surfaces, H, cf=CF)
    w = 2 * np.pi * FREQUENCY_HZ
    x = hb.stuck_guess(w)
    return {"unknowns": int(hb.size), "surface_nodes": int(sum(s.n for s in surfaces.values())),
            "eval_jac_s": _median_cpu(lambda: hb(x, w), repeats),
            "eval_s": _median_cpu(lambda: hb.value(x, w), repeats)}


def run(quick: bool, log=print, cases=None) -> list[Row]:
    """The surface cost rows (module docstring); ``cases`` overrides the (model, nodes, H) list."""
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.sector import Sector

    from ..cache import Store

    sector, store = Sector(load_config(None)), Store().prepare()
    rows = []
    log(HEAD)
    for model, nodes, H in cases or (QUICK_CASES if quick else CASES):
        out = measure(model, nodes, H, sector, store, 1 if quick else REPEATS)
        per_node = out["eval_jac_s"] / out["surface_nodes"]
        per_coef = out["eval_jac_s"] / (2 * H + 1)
        mem = self_peak_mb()
        rows.append(Row(f"cost surface {model} H {H}", nodes, None, out["eval_jac_s"], mem, False,
                        out | {"harmonics": H, "time_per_node_s": per_node,
                               "time_per_coefficient_s": per_coef, "clock": "process"}))
        log(f"{model:10s} {nodes:5d} {H:3d} {out['unknowns']:8d} {out['surface_nodes']:13d} "
            f"{out['eval_jac_s']:10.3f} {out['eval_s']:9.3f} {1e3 * per_node:8.2f} "
            f"{1e3 * per_coef:8.2f} {mem:7.0f}")
    return rows


#: Columns of the surface rows' tables: (heading, key, format).
COLUMNS = (("case", "case", "s"), ("nodes per side", "size", "d"), ("H", "harmonics", "d"),
           ("unknowns", "unknowns", "d"), ("surface nodes", "surface_nodes", "d"),
           ("evaluation with J [s]", "eval_jac_s", ".3f"), ("without J [s]", "eval_s", ".3f"),
           ("per node [ms]", "time_per_node_s", ".2f"), ("per coefficient [ms]", "time_per_coefficient_s", ".1f"),
           ("memory [MB]", "memory_mb", ".0f"))
CAPTION = ("contact surfaces: CPU time of one residual evaluation of the UPD-24 sector with its Jacobian "
           f"and without, at the stuck start (CF {CF:g} N, {FREQUENCY_HZ:g} Hz), per node of the two faces "
           "and per harmonic coefficient (2 H + 1); memory: the process's peak so far, rows in run order")


def is_row(r: dict) -> bool:
    """Whether a bench row is one of this module's."""
    return r.get("case", "").startswith("cost surface ")


def cells(r: dict) -> list[str]:
    """The formatted cells of one row (per-node and per-coefficient times in ms)."""
    out = []
    for _, k, f in COLUMNS:
        v = r.get(k)
        if v is None:
            out.append("-")
            continue
        out.append(format(1e3 * v if k.startswith("time_per") else v, f))
    return out


def markdown(rows: list[dict]) -> list[str]:
    """Markdown table lines of the surface rows."""
    return ["| " + " | ".join(h for h, _, _ in COLUMNS) + " |", "|" + "---|" * len(COLUMNS),
            *("| " + " | ".join(cells(r)) + " |" for r in rows)]
