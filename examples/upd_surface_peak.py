"""UPD-24 with contact surfaces: the HB peak, its node convergence, the ring time integration and the point model.
===============================================================================================================

Per centrifugal load CF:

* the peak of the default point model (three Jenkins points of the TOML,
  :class:`harmonic_balance.bladed_disk.hb.SectorHB`, its curve over the configuration's
  band refined by :func:`harmonic_balance.bladed_disk.solve.frf`);
* the peak of the sector with the damper's faces as contact surfaces
  (:class:`harmonic_balance.bladed_disk.surface_hb.SurfaceSectorHB`, ``--nodes`` per side,
  one harmonic count): the first-harmonic amplitude of u_a maximised over the frequency
  by the library's search (:func:`harmonic_balance.bladed_disk.surface_peak.surface_peak`:
  an interval uphill, then Brent's search), each frequency a Newton solve started on
  the tangent of the nearest one solved, the search started at the point
  model's peak (or ``--guess``); with the condensed model, whose unknowns are the
  sector's for every node count, each node count's first solve starts from the
  previous one's peak solution (the CF path where that fails);
* with ``--ti``, at the surface peak of the finest node count: the ring of the same
  sectors and surfaces marched in time
  (:func:`harmonic_balance.bladed_disk.ring_surface.march_ring_surface`) until its first
  harmonic settles, started on the harmonic balance's periodic state (the sliders
  stepped through its loop) instead of at rest, which settles in tens of periods
  instead of hundreds; the march's equations do not know the start, so the state it
  settles to is its own (a start from rest remains ``--ti-rest``).

Writes one JSON (``--json``) with the revision, and prints a table. Full study::

    python examples/upd_surface_peak.py --cf 120 --nodes 5,7,10 --harmonics 3 --ti --json out/surface_peak_120.json

``--quick`` runs the path at H 1, 5 nodes, the surface model solved at the point model's
peak frequency only (no peak search), one march period after the start's two (a smoke
run, not a comparison).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from damper.bench.common import revision
from damper.cache import Store
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk import load_path, solve
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.ring_surface import march_ring_surface
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.surface_hb import DASHPOTS, CondensedSurfaceSectorHB, SurfaceSectorHB
from harmonic_balance.bladed_disk.surface_peak import PEAK_XTOL
from harmonic_balance.bladed_disk.surface_peak import surface_peak as library_peak
from harmonic_balance.newton import NewtonError

#: Loads of the path from ``--start-cf`` to the CF (:func:`cf_path`): steps of ~10 % at
#: 300 -> 120 N, where the condensed model's Newton takes 5-15 evaluations a step.
CF_STEPS = 8
#: Print every frequency solved (``--verbose``).
VERBOSE = False


def point_peak(sector: Sector, H: int, cf: float, points: int) -> dict:
    """The default point model's refined peak over the configuration's band."""
    p0 = time.process_time()
    hb = SectorHB(sector, H, cf=cf)
    band = sector.cfg["load.band_hz"]
    c = solve.frf(hb, 2 * np.pi * np.linspace(band[0], band[1], points))
    return {"peak_hz": c.peak_omega / (2 * np.pi), "peak_amplitude_h1": c.peak_amplitude,
            "cpu_s": time.process_time() - p0}


def cf_path(make, omega: float, cf: float, start_cf: float, steps: int = CF_STEPS):
    """A first solution at ``cf`` [N] reached from the stuck start at ``start_cf`` by
    Newton at ``steps`` loads between them (log-spaced), each warm-started from the last
    (:func:`harmonic_balance.bladed_disk.load_path.cf_path`, the CLI's path): where the
    stuck start does not converge (low CF: much of the faces slips). ``make(cf)``: the
    model at that load."""
    def report(c, hb, x):
        if VERBOSE:
            print(f"    CF {c:.1f} N at {omega / 2 / np.pi:.3f} Hz: {hb.amplitude_h1(x):.6e} m", flush=True)
    return load_path.cf_path(make, omega, cf, start_cf, steps, max_iter=80, report=report)[0]


def surface_peak(hb, f_guess: float, xtol: float = PEAK_XTOL, first=None) -> dict:
    """The library's peak search (:func:`harmonic_balance.bladed_disk.surface_peak.surface_peak`),
    every frequency printed with ``--verbose``."""
    def report(f, a):
        if VERBOSE:
            print(f"    {f:.4f} Hz: {a:.6e} m", flush=True)
    return library_peak(hb, f_guess, xtol, first, report)


def surface_point(hb, f: float, first=None) -> dict:
    """The surface model solved at the one frequency f [Hz] (``--quick``: the path of
    :func:`surface_peak` without its search, which takes ~10 frequencies of ~200
    evaluations each); the same record, its one point as the "peak"."""
    p0 = time.process_time()
    w = 2 * np.pi * f
    x = (first or (lambda w: solve.start_point(hb, w)))(w)
    a = float(hb.amplitude_h1(x))
    return {"peak_hz": float(f), "peak_amplitude_h1": a, "x": x, "points": [(float(f), a)],
            "cpu_s": time.process_time() - p0}


def ring_check(shb: SurfaceSectorHB, x, basis, f: float, tol: float, periods: int, rest: bool) -> dict:
    """The ring of ``shb``'s sectors marched at frequency f [Hz], started on the HB state x
    (harmonics on ``basis``; sector DOFs, with or without the nodes) and, with ``rest``, from rest."""
    out = {}
    for name, start in (("from_hb_state", x),) + ((("from_rest", None),) if rest else ()):
        p0 = time.process_time()
        try:
            r = march_ring_surface(shb, [2 * np.pi * f], max_periods=periods, tol=tol, start=start,
                                   start_basis=basis)
        except RuntimeError as err:   # a step's node solve failed: recorded, not hidden
            out[name] = {"failed": str(err), "cpu_s": time.process_time() - p0}
            continue
        out[name] = {"amplitude_h1": float(r["amplitude"][0]), "periods": int(r["periods"][0]),
                     "converged": bool(r["converged"][0]), "steps_per_period": int(r["steps_per_period"]),
                     "time_steps": int(r["time_steps"]), "cpu_s": time.process_time() - p0,
                     "ring_dofs": int(r["ring_dofs"])}
    return out


def _factory(sector, surfaces, H: int, args):
    """``model(cf)``, the surface model of ``args.model`` at that load, and the list of every
    model it built (the CF path's too: their evaluations are the run's)."""
    built = []

    def model(c):
        if args.model == "condensed":
            built.append(CondensedSurfaceSectorHB(sector, surfaces, H, cf=c))
        else:
            built.append(SurfaceSectorHB(sector, surfaces, H, cf=c, dashpots=args.dashpots))
        return built[-1]
    return model, built


def _first(model, hb, cf: float, args, x_prev):
    """``first(omega)`` of the node count's search: Newton from the previous node count's peak
    solution where the unknowns are the same (the condensed model's: the sector's DOFs, for
    any node count), else, or where that fails, the CF path (``--start-cf``) or the stuck
    start (None: the search's default)."""
    def fallback(w):
        if args.start_cf is None:
            return solve.start_point(hb, w)
        return cf_path(model, w, cf, args.start_cf, args.cf_steps)

    if x_prev is None or x_prev.shape != (hb.size,):
        return None if args.start_cf is None else fallback

    def first(w):
        try:
            return solve.solve_point(hb, w, x_prev, max_iter=80)
        except NewtonError:
            return fallback(w)
    return first


def run_cf(cfg, sector, cf: float, nodes: list, H: int, args) -> dict:
    """One CF: the point peak, the surface peak per node count, the ring check."""
    rec = {"cf": cf, "model": args.model, "dashpots": args.dashpots,
           "point": point_peak(sector, H, cf, args.points), "surface": []}
    print(f"CF {cf:g} N: point model peak {rec['point']['peak_hz']:.3f} Hz, "
          f"|u_a,1| {rec['point']['peak_amplitude_h1']:.6e} m", flush=True)
    f_guess = rec["point"]["peak_hz"] if args.guess is None else args.guess
    x_prev = None
    for n in nodes:
        surfaces = build_surfaces(cfg, n, cf, Store().prepare())
        model, built = _factory(sector, surfaces, H, args)
        hb = model(cf)
        first = _first(model, hb, cf, args, x_prev)
        if args.quick or args.at is not None:
            pk = surface_point(hb, f_guess if args.at is None else args.at, first)
        else:
            pk = surface_peak(hb, f_guess, args.xtol, first)
        pk["evaluations"] = sum(m.evaluations for m in built)   # hb's and the CF path's models
        f_guess, x_prev = pk["peak_hz"], pk["x"]
        row = {k: v for k, v in pk.items() if k != "x"} | {
            "nodes_per_side": n, "nodes": [s.n for s in surfaces.values()], "unknowns": hb.size,
            "searched": not (args.quick or args.at is not None)}
        if args.save_x:
            np.save(f"{args.save_x}_cf{cf:g}_n{n}_H{H}.npy", pk["x"])
        print(f"  {n:>2} nodes per side: peak {pk['peak_hz']:.4f} Hz, |u_a,1| "
              f"{pk['peak_amplitude_h1']:.6e} m (HB; the ring follows)", flush=True)
        if args.ti and n == nodes[-1]:
            # the ring has the model's dashpots: the condensed model's act on the faces' inputs
            ring_hb = SurfaceSectorHB(sector, surfaces, 1, cf=cf, dashpots=args.dashpots)
            row["ring"] = ring_check(ring_hb, pk["x"], hb.basis,
                                     pk["peak_hz"], args.ti_tol, args.ti_periods, args.ti_rest)
        rec["surface"].append(row)
        print(f"  {n:>2} nodes per side: peak {pk['peak_hz']:.3f} Hz, |u_a,1| "
              f"{pk['peak_amplitude_h1']:.6e} m, {pk['evaluations']} evaluations, "
              f"{pk['cpu_s']:.0f} s CPU", flush=True)
        for name, r in row.get("ring", {}).items():
            if "failed" in r:
                print(f"     ring {name}: FAILED ({r['failed']})", flush=True)
                continue
            print(f"     ring {name}: |u_a,1| {r['amplitude_h1']:.6e} m "
                  f"({r['amplitude_h1'] / pk['peak_amplitude_h1'] - 1:+.3%} of the HB), "
                  f"{r['periods']} periods ({'settled' if r['converged'] else 'NOT settled'}), "
                  f"{r['cpu_s']:.0f} s CPU", flush=True)
    s = rec["surface"]
    if len(s) > 1:
        rec["last_refinement_change"] = s[-1]["peak_amplitude_h1"] / s[-2]["peak_amplitude_h1"] - 1
    if args.at is not None:   # a fixed frequency is no peak: nothing to hold the point peak against
        print(f"  point model against the surface: not compared (the surface solved at {args.at:g} Hz "
              "only, not at its peak)", flush=True)
        return rec
    rec["point_error"] = rec["point"]["peak_amplitude_h1"] / s[-1]["peak_amplitude_h1"] - 1
    rec["point_frequency_error"] = rec["point"]["peak_hz"] / s[-1]["peak_hz"] - 1
    print(f"  point model against the {nodes[-1]}-node surface: amplitude "
          f"{rec['point_error']:+.2%}, frequency {rec['point_frequency_error']:+.3%}", flush=True)
    return rec


def table(paths) -> str:
    """Markdown rows (the study page's table) from JSON files of this script; amplitudes are
    the first harmonic of u_a at the peak."""
    rows = ["| CF [N] | model, H | nodes per side | surface peak [Hz] | surface amplitude [m] | change from "
            "the previous node count | point model: peak [Hz], amplitude [m], error | ring TI from the HB "
            "state: amplitude [m], TI - HB, periods | revision |",
            "|---|---|---|---|---|---|---|---|---|"]
    for path in paths:
        rec = json.loads(Path(path).read_text())
        for case in rec["cases"]:
            prev = None
            for s in case["surface"]:
                change = f"{s['peak_amplitude_h1'] / prev - 1:+.2%}" if prev else "-"
                prev = s["peak_amplitude_h1"]
                pt = case["point"]
                error = (f"{pt['peak_amplitude_h1'] / s['peak_amplitude_h1'] - 1:+.1%}"
                         if case.get("point_error") is not None else "-")
                point = f"{pt['peak_hz']:.2f}, {pt['peak_amplitude_h1']:.4e}, {error}"
                r = s.get("ring", {}).get("from_hb_state")
                if not r:
                    ring = "-"
                elif "failed" in r:
                    ring = "step failed"
                else:
                    ring = (f"{r['amplitude_h1']:.4e}, {r['amplitude_h1'] / s['peak_amplitude_h1'] - 1:+.2%}, "
                            f"{r['periods']}{'' if r['converged'] else ' (not settled)'}")
                model = case.get("model", "nodes")
                if model == "nodes" and case.get("dashpots") == "inputs":
                    model += " (dashpots on the inputs)"
                at = "" if s.get("searched", True) else " (fixed)"
                rows.append(f"| {case['cf']:g} | {model}, {rec['harmonics']} | "
                            f"{s['nodes_per_side']} | {s['peak_hz']:.2f}{at} | {s['peak_amplitude_h1']:.4e} | "
                            f"{change} | {point} | {ring} | {rec['revision']} |")
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cf", default="120", help="centrifugal loads [N], comma-separated")
    ap.add_argument("--nodes", default="5", help="surface nodes per side, comma-separated (increasing)")
    ap.add_argument("--harmonics", type=int, default=3, help="harmonic count H")
    ap.add_argument("--points", type=int, default=21, help="frequencies of the point model's curve")
    ap.add_argument("--xtol", type=float, default=PEAK_XTOL, help="relative frequency tolerance of the peak")
    ap.add_argument("--model", choices=("nodes", "condensed"), default="nodes",
                    help="surface HB: node DOFs as unknowns (SurfaceSectorHB) or condensed onto the "
                    "faces' rigid inputs (CondensedSurfaceSectorHB)")
    ap.add_argument("--dashpots", choices=DASHPOTS, default=None,
                    help="where the bodies' damping acts (SurfaceSectorHB): on their deformation (the "
                    "node-DOF model's default) or on the faces' rigid inputs (the condensed model's, "
                    "its only choice); the ring time integration takes the same")
    ap.add_argument("--at", type=float, metavar="HZ", help="solve the surface model at this one "
                    "frequency [Hz] instead of searching its peak (a comparison at a fixed frequency)")
    ap.add_argument("--guess", type=float, metavar="HZ", help="start the first node count's peak search "
                    "here [Hz] instead of at the point model's peak")
    ap.add_argument("--start-cf", type=float, help="reach the first solution from the stuck start at this "
                    "CF [N] (cf_path) instead of at the CF itself")
    ap.add_argument("--cf-steps", type=int, default=CF_STEPS, help="log-spaced loads of the path from "
                    "--start-cf (each a Newton solve; ~24 from 300 to 40 N)")
    ap.add_argument("--ti", action="store_true", help="ring time integration at the finest surface peak")
    ap.add_argument("--ti-rest", action="store_true", help="also march the ring from rest (slow)")
    ap.add_argument("--ti-tol", type=float, default=1e-5, help="steady-state tolerance of the march")
    ap.add_argument("--ti-periods", type=int, default=400, help="most periods marched")
    ap.add_argument("--json", metavar="FILE", help="write the results here")
    ap.add_argument("--save-x", metavar="PREFIX", help="save each HB peak's solution to PREFIX_cf.._n.._H...npy")
    ap.add_argument("--verbose", action="store_true", help="print every frequency solved")
    ap.add_argument("--quick", action="store_true", help="H 1, 5 nodes, one frequency, 1 march period: a smoke run")
    ap.add_argument("--table", nargs="+", metavar="JSON", help="print the study table of these "
                    "JSON files of this script and stop")
    args = ap.parse_args(argv)
    if args.dashpots is None:
        args.dashpots = "inputs" if args.model == "condensed" else "bodies"
    if args.model == "condensed" and args.dashpots != "inputs":
        ap.error("the condensed model's dashpots act on the faces' rigid inputs: --dashpots inputs")
    if not 1 <= args.cf_steps <= 1000:
        ap.error(f"--cf-steps must be 1 ... 1000, not {args.cf_steps}")
    if args.guess is not None and not args.guess > 0:
        ap.error(f"--guess must be a positive frequency [Hz], not {args.guess:g}")
    if args.at is not None and not args.at > 0:
        ap.error(f"--at must be a positive frequency [Hz], not {args.at:g}")
    if args.table:
        print(table(args.table))
        return 0
    if args.quick:
        args.harmonics, args.nodes, args.points = 1, "5", 5
        args.ti_periods, args.ti_rest = 1, False
    global VERBOSE
    VERBOSE = args.verbose
    cfs = [float(v) for v in args.cf.split(",")]
    nodes = [int(v) for v in args.nodes.split(",")]
    cfg = load_config(None)
    sector = Sector(cfg)
    t0 = time.perf_counter()
    out = {"revision": revision() or "unknown", "harmonics": args.harmonics, "command": " ".join(sys.argv),
           "cases": [run_cf(cfg, sector, cf, nodes, args.harmonics, args) for cf in cfs]}
    out["time_s"] = time.perf_counter() - t0
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
