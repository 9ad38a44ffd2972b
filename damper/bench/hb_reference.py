"""Dense references of the model-class benchmark: the first-harmonic peak of each model.

A reference is the same model traced at a higher H with small steps, once, and kept:
the benchmark reads it and never recomputes it.

How a reference is made (:func:`compute`):

* chains and the single-DOF oscillator (:mod:`harmonic_balance.bench_models`): every
  Jenkins link evaluated exactly (``FrictionLink.exact``: the loop's Fourier
  coefficients between the extrema of u, no AFT sampling error); first a trace at the
  case's H over the whole band (default steps) locates the highest first-harmonic peak,
  then a window of +-WINDOW_REL around it is traced at 2 H, 3 H (and 6 H while the peak
  still moves by more than H_CONVERGED) with the continuation's step capped at
  DS_MAX_REF (about 1e-4 of the frequency per step near the peak); the peak is the
  largest first-harmonic amplitude of the last trace, refined by a parabola through its
  two neighbours (:func:`curve_peak`). Its error estimate is the change from the
  previous H (and the parabola's change of the largest point, the interpolation). The same
  dense trace at the case's own H (``same_h``) separates the error of a traced curve
  (points, steps, AFT) from the truncation in H.
* UPD-24 (``damper upd frf`` defaults: H = 7, 200 points): the sector's own driver
  (``bladed_disk.solve.frf``: frequency grid, Brent's search on the first-harmonic
  amplitude) at H_ref = UPD_H_REF and n_t = UPD_SAMPLES_REF on a grid of UPD_POINTS_REF
  points over +-WINDOW_REL around the default run's peak. Its peak converges slowly in
  H (the damper lifts off: measured 5.2324, 5.1842, 5.1673, 5.1564, 5.1402e-4 m at
  H = 7, 11, 15, 21, 31), so the error estimate is the independent ring time
  integration (:func:`_upd_ti`; measured 5.1377e-4 m, 0.05 % from H = 31). ``same_h``:
  the same window at H = 7.

Where references live: the file :data:`REFERENCE_FILE` next to this module (committed;
regenerate with ``python -m damper.bench.hb_reference --write``), else the damper
cache (``damper.cache.Store``; computed on first use, with a log line). Each entry
carries the fingerprint of its model (:func:`fingerprint`), so a changed model
definition is a miss, never a stale reference.
"""
from __future__ import annotations

import argparse
import hashlib
import inspect
import json
import sys
import time
from pathlib import Path

import numpy as np

#: The committed references (case key -> entry).
REFERENCE_FILE = Path(__file__).with_name("hb_reference.json")
#: Half-width of the window traced densely around the peak, relative to its frequency.
WINDOW_REL = 0.03
#: Largest continuation step of the dense trace (compute_frf's ds_max): measured on the
#: 3-mass chain (F = 1, knl = 20, H = 21, 6 % window): 0.01, 0.003, 0.001 give steps of
#: 3e-4, 9e-5, 3e-5 rad/s at the peak and the same parabola peak to 1e-9.
DS_MAX_REF = 0.003
#: Harmonics of the dense traces, as multiples of the case's H: the next is traced while
#: the peak still changes by more than H_CONVERGED from the previous (measured on the
#: 3-mass chain at F = 1: knl = 200 peaks 0.013114, 0.012410, 0.012293 at H = 7, 14, 21).
H_FACTORS = (2, 3, 6)
H_CONVERGED = 1e-3
#: Point limit of a dense trace.
MAX_POINTS_REF = 20000
#: UPD-24's reference: harmonics, AFT samples and grid points over the window.
UPD_H_REF, UPD_H_MID = 31, 21
UPD_SAMPLES_REF = 1024
UPD_POINTS_REF = 241
#: Frequencies of UPD-24's time-integration check: the peak's and +- this fraction.
UPD_TI_REL = 2e-3
#: Version of the procedure above: part of every fingerprint (a new procedure is a miss).
METHOD = 2


def curve_peak(omega, a1) -> tuple[float, float, float]:
    """Largest first-harmonic amplitude of a traced curve, refined by a parabola.

    Through the largest point and its neighbours along the curve, when the three are
    strictly monotone in omega and the parabola is concave; its vertex is kept inside
    the neighbours' interval. The same rule serves every tool's curve and the dense
    references (so a row's error measures the traced points, not a peak finder).

    Parameters
    ----------
    omega, a1 : (n,) array_like
        Points in the order traced [rad/s] and first-harmonic amplitudes [m].

    Returns
    -------
    (amplitude [m], omega [rad/s], change against the largest point [-])
    """
    w, a = np.asarray(omega, float), np.asarray(a1, float)
    ok = np.isfinite(w) & np.isfinite(a)
    w, a = w[ok], a[ok]
    if a.size == 0:
        return float("nan"), float("nan"), float("nan")
    i = int(np.argmax(a))
    if 0 < i < a.size - 1:
        x = w[i - 1:i + 2] - w[i]
        y = a[i - 1:i + 2]
        if (x[0] < 0 < x[2]) or (x[0] > 0 > x[2]):
            c2, c1, c0 = np.polyfit(x, y, 2)
            if c2 < 0:
                xv = float(np.clip(-c1 / (2 * c2), min(x[0], x[2]), max(x[0], x[2])))
                av = float(c0 + c1 * xv + c2 * xv * xv)
                return av, float(w[i] + xv), abs(av / a[i] - 1.0)
    return float(a[i]), float(w[i]), 0.0


def fingerprint(key: str) -> str:
    """Hash of what a reference depends on: the model definition and :data:`METHOD`."""
    if key == "upd24":
        from harmonic_balance.bladed_disk.config import DEFAULT_CONFIG

        text = DEFAULT_CONFIG.read_text()
    else:
        spec = _case(key).spec()
        spec.pop("name")
        spec["band"] = sorted(spec["band"])     # the reference serves both directions
        text = json.dumps(spec, sort_keys=True)
    return hashlib.sha256(f"{METHOD}:{text}".encode()).hexdigest()[:16]


def _case(key: str):
    """The model of a reference key (a case name without its direction)."""
    from harmonic_balance.bench_models import by_name

    return by_name(key + " up") if key.startswith(("chain3", "chain5")) else by_name(key)


def reference_key(case_name: str) -> str:
    """Reference key of a case: its name without the sweep direction."""
    for tail in (" up", " down"):
        if case_name.endswith(tail):
            return case_name[: -len(tail)]
    return case_name


def _frf_kwargs(**kw) -> dict:
    """Keyword arguments that this version of compute_frf accepts (runs on any version)."""
    from harmonic_balance.frf import compute_frf

    names = inspect.signature(compute_frf).parameters
    return {k: v for k, v in kw.items() if k in names}


def _exact_model(case):
    """The case's model with every Jenkins link evaluated exactly, when the engine can."""
    model = case.model()
    try:
        from harmonic_balance.frf import exact_links
    except ImportError:
        return model, "sampled"
    return exact_links(model, every=True), "exact"


def _trace(model, H, band, ds_max=None, max_points=None) -> dict:
    """One curve of compute_frf (no peak refinement, no stability) and its curve peak."""
    from harmonic_balance.frf import compute_frf

    kw = {"refine": False, "stability": False}
    if ds_max is not None:
        kw.update(ds_max=ds_max, max_points=max_points)
    t0 = time.perf_counter()
    r = compute_frf(model, H, band, **_frf_kwargs(**kw))
    a, w, interp = curve_peak(r.omega, r.amplitude_h1)
    i = int(np.argmax(r.amplitude_h1))
    return {"H": H, "band": [float(b) for b in band], "amplitude": a, "omega": w,
            "interpolation": interp, "at_edge": i in (0, r.points - 1), "points": r.points,
            "n_t": int(r.n_t), "time_s": time.perf_counter() - t0, "status": r.status,
            "step_at_peak": float(np.median(np.abs(np.diff(r.omega[max(i - 2, 0):i + 3]))))}


def _window(w_p, lo, hi, scale=1.0):
    return max(lo, w_p * (1 - scale * WINDOW_REL)), min(hi, w_p * (1 + scale * WINDOW_REL))


def _dense(model, H, w_p, lo, hi, log) -> dict:
    """Dense trace at H over the window around w_p, widened while the peak sits on an
    inner edge of the window."""
    for scale in (1.0, 3.0, 9.0):
        win = _window(w_p, lo, hi, scale)
        d = _trace(model, H, win, DS_MAX_REF, MAX_POINTS_REF)
        log(f"  reference H = {H} over {win[0]:.5g}-{win[1]:.5g} rad/s: peak {d['amplitude']:.9g} at "
            f"{d['omega']:.7g} ({d['points']} points, {d['time_s']:.1f} s)")
        inner_edge = d["at_edge"] and not (np.isclose(d["omega"], lo) or np.isclose(d["omega"], hi))
        if not inner_edge:
            return d
        w_p = d["omega"]
    raise RuntimeError(f"the dense reference's peak stays on the window's edge near {w_p:.6g} rad/s")


def _chain_reference(key: str, log) -> dict:
    case = _case(key)
    model, aft = _exact_model(case)
    H = case.harmonics
    lo, hi = sorted(case.band)
    coarse = _trace(model, H, (lo, hi))
    log(f"  reference {key}: peak near {coarse['omega']:.6g} rad/s at H = {H} ({coarse['points']} points)")
    ref = _dense(model, H_FACTORS[0] * H, coarse["omega"], lo, hi, log)
    for f in H_FACTORS[1:]:
        mid, ref = ref, _dense(model, f * H, ref["omega"], lo, hi, log)
        if abs(ref["amplitude"] / mid["amplitude"] - 1.0) <= H_CONVERGED:
            break
    same = _dense(model, H, ref["omega"], lo, hi, log)
    return {"amplitude": ref["amplitude"], "omega": ref["omega"],
            "same_h": {"H": H, "amplitude": same["amplitude"], "omega": same["omega"]},
            "error_estimate": max(abs(ref["amplitude"] / mid["amplitude"] - 1.0), ref["interpolation"]),
            "how": f"compute_frf, {aft} links, H = {ref['H']}, ds_max = {DS_MAX_REF} over "
                   f"{ref['band'][0]:.6g}-{ref['band'][1]:.6g} rad/s ({ref['points']} points, "
                   f"{ref['step_at_peak']:.2g} rad/s apart at the peak), largest first harmonic "
                   f"refined by a parabola; error estimate: H = {mid['H']} and the parabola's change",
            "dense": ref, "mid": mid, "dense_same_h": same}


def _upd_curve(sector, H, n_t, omegas) -> dict:
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.solve import frf

    t0 = time.perf_counter()
    c = frf(SectorHB(sector, H, n_t=n_t), omegas)
    return {"H": H, "n_t": n_t, "amplitude": float(c.peak_amplitude), "omega": float(c.peak_omega),
            "points": len(omegas), "band": [float(omegas[0]), float(omegas[-1])],
            "time_s": time.perf_counter() - t0, "method": c.extra.get("method", "")}


def _upd_ti(sector, omega) -> dict:
    """Ring time integration at three frequencies +-UPD_TI_REL around ``omega``; the peak
    of the parabola through their first-harmonic amplitudes."""
    from harmonic_balance.bladed_disk.timeint import march_ring

    t0 = time.perf_counter()
    w = omega * np.array([1.0 - UPD_TI_REL, 1.0, 1.0 + UPD_TI_REL])
    ti = march_ring(sector, w, max_periods=3000, tol=1e-7)
    c2, c1, c0 = np.polyfit(w - omega, ti["amplitude"], 2)
    return {"amplitude": float(c0 - c1 * c1 / (4 * c2)), "omega": float(omega - c1 / (2 * c2)),
            "settle_error": float(np.max(ti["settle_error"])), "steps_per_period": int(ti["steps_per_period"]),
            "time_s": time.perf_counter() - t0}


def _upd_reference(log) -> dict:
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.sector import Sector

    sector = Sector(load_config(None))
    lo, hi = (2 * np.pi * f for f in sector.cfg["load.band_hz"])
    first = _upd_curve(sector, 7, 0, np.linspace(lo, hi, 200))
    omegas = np.linspace(*_window(first["omega"], lo, hi), UPD_POINTS_REF)
    ref, mid, same = (_upd_curve(sector, H, UPD_SAMPLES_REF, omegas) for H in (UPD_H_REF, UPD_H_MID, 7))
    for r in (ref, mid, same):
        log(f"  reference upd24 H = {r['H']}, n_t = {r['n_t']}: peak {r['amplitude']:.9g} at "
            f"{r['omega']:.7g} rad/s ({r['time_s']:.1f} s)")
    ti = _upd_ti(sector, ref["omega"])
    log(f"  reference upd24 ring time integration: peak {ti['amplitude']:.9g} at {ti['omega']:.7g} rad/s "
        f"({ti['time_s']:.1f} s)")
    return {"amplitude": ref["amplitude"], "omega": ref["omega"],
            "same_h": {"H": 7, "amplitude": same["amplitude"], "omega": same["omega"]},
            "error_estimate": abs(ref["amplitude"] / ti["amplitude"] - 1.0),
            "how": f"bladed_disk.solve.frf, H = {UPD_H_REF}, n_t = {UPD_SAMPLES_REF}, {UPD_POINTS_REF} points "
                   f"over {omegas[0]:.6g}-{omegas[-1]:.6g} rad/s, peak by Brent's search on the first "
                   "harmonic; error estimate: against the ring time integration (bladed_disk.timeint, "
                   f"parabola through +-{UPD_TI_REL:g} of the peak frequency); H = {UPD_H_MID} differs by "
                   f"{ref['amplitude'] / mid['amplitude'] - 1:+.1e} (the peak converges slowly and not "
                   "monotonically in H: the contacts lift off)",
            "dense": ref, "mid": mid, "dense_same_h": same, "time_integration": ti}


def compute(key: str, log=print) -> dict:
    """The dense reference of one model (module docstring), with how it was made."""
    t0 = time.perf_counter()
    out = _upd_reference(log) if key == "upd24" else _chain_reference(key, log)
    from .common import revision

    out.update(key=key, fingerprint=fingerprint(key), revision=revision(),
               date_utc=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
               time_s=time.perf_counter() - t0)
    return out


def _stored() -> dict:
    try:
        return json.loads(REFERENCE_FILE.read_text())
    except FileNotFoundError:
        return {}


def load(key: str, log=print, compute_missing: bool = True) -> dict | None:
    """The reference of ``key``: the committed file, else the cache, else computed and cached.

    Returns None when it is missing and ``compute_missing`` is False.
    """
    fp = fingerprint(key)
    entry = _stored().get(key)
    if entry and entry.get("fingerprint") == fp:
        return entry
    from damper.cache import Store, make_key

    store, ck = Store(), make_key("hb-bench-reference", key, fp)
    hit = store.get(ck)
    if hit is not None:
        return hit[1]
    if not compute_missing:
        return None
    log(f"  reference {key}: not stored, computing it once (minutes; kept in the damper cache)")
    entry = compute(key, log)
    store.put(ck, {}, entry)
    return entry


def keys() -> list[str]:
    """Every reference key: the models of harmonic_balance.bench_models and UPD-24."""
    from harmonic_balance.bench_models import all_cases

    return list(dict.fromkeys(reference_key(c.name) for c in all_cases())) + ["upd24"]


def main(argv=None) -> int:
    """Compute references and write them into :data:`REFERENCE_FILE` (maintainers)."""
    ap = argparse.ArgumentParser(description="dense references of the hb benchmark's model classes")
    ap.add_argument("keys", nargs="*", help=f"references to compute (default: all): {', '.join(keys())}")
    ap.add_argument("--write", action="store_true", help=f"write them into {REFERENCE_FILE.name}")
    args = ap.parse_args(argv)
    bad = [k for k in args.keys if k not in keys()]
    if bad:
        print(f"unknown reference(s) {bad}; known: {', '.join(keys())}", file=sys.stderr)
        return 2
    stored = _stored()
    for key in args.keys or keys():
        entry = compute(key, lambda s: print(s, file=sys.stderr, flush=True))
        print(json.dumps({k: entry[k] for k in ("key", "amplitude", "omega", "error_estimate", "time_s")}))
        if args.write:
            from contact_core.fileio import atomic_write

            stored[key] = entry
            atomic_write(REFERENCE_FILE, json.dumps(stored, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
