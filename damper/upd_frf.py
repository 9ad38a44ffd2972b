"""The UPD sector's forced response at one centrifugal load: ``damper upd frf`` and the scene's ``upd_frf``.

One computation for both callers: the sector model from the UPD config with the contacts the
options name (the TOML's Jenkins points, points computed from the ``[geometry]`` section, or
the damper's faces as contact surfaces), the curve over the band (fixed harmonics or raised
to an accuracy), its truncation estimate and the contacts' summary at the peak, returned as
the command's ``--json`` record. The caller checks the options first (the CLI's
``_check_frf``, the scene loader's ``[upd]`` checks) and prints or stores the record.

Options (an ``argparse.Namespace`` or any object with these attributes): ``config`` (path or
None: the bundled UPD-24), ``contacts`` ("toml", "geometry", "surface"), ``cf``, ``f0`` [N]
(None: the config's), ``damper`` ("nonlinear", "free", "stuck"), ``harmonics``, ``accuracy``
(None: fixed H), ``band`` ([lo, hi] Hz or None: the config's), ``points``, ``surface_nodes``,
``surface_model``, ``check_steady_state``, ``json`` (True: the geometry report is not printed),
``store`` (the cache of the condensed contacts; None or absent: the default).
The run's reports are set on it as the CLI's hooks do (``contact_report``, ``surface_report``,
``surface_run``).
"""
from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

from damper.upd_surface import SURFACE_MODELS

#: Contact-zone nodes per side of each face with surface contacts when not given.
SURFACE_NODES = 5

#: Surface model with surface contacts when not given: the condensed one, which reaches the
#: default CF (damper.upd_surface.SURFACE_MODELS).
SURFACE_MODEL = SURFACE_MODELS[0]


def options(**kw) -> SimpleNamespace:
    """The options of :func:`frf_record` with the CLI's defaults for those not given
    (a scene's ``[upd]`` table passes its keys)."""
    base = {"config": None, "contacts": "toml", "cf": None, "f0": None, "damper": "nonlinear",
            "harmonics": 7, "accuracy": None, "band": None, "points": 200, "surface_nodes": None,
            "surface_model": None, "check_steady_state": False, "json": True, "store": None}
    return SimpleNamespace(**(base | kw))


def upd_sector(opts):
    """The sector of ``opts.config`` with the contacts ``opts.contacts`` names (geometry: computed
    and kept in :func:`damper.cache.store_of`, the report in ``opts.contact_report``, printed unless ``opts.json``)."""
    from damper.cache import store_of
    from damper.upd_geometry import apply_to_args
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.sector import Sector

    return Sector(apply_to_args(opts, load_config(opts.config), store_of(opts)))


def frf_record(opts) -> dict:
    """The ``damper upd frf --json`` record of checked options ``opts`` (module docstring).

    Raises
    ------
    ValueError
        Options the model refuses (a geometry contact_core cannot hold, a surface too large).
    RuntimeError
        The solver failed (``SolverError``), or the damper left both faces.
    """
    sector = upd_sector(opts)
    band = opts.band or sector.cfg["load.band_hz"]
    omegas = 2 * np.pi * np.linspace(band[0], band[1], opts.points)
    if opts.damper == "nonlinear":
        out = _frf_nonlinear(sector, opts, omegas)
    else:
        out = _frf_linear(sector, opts, omegas)
        if opts.check_steady_state:
            out["steady_state"] = {"note": f"--damper {opts.damper} is linear: one steady state"}
    for key, attr in (("contacts_from_geometry", "contact_report"), ("contact_surfaces", "surface_report"),
                      ("surface_model", "surface_run")):
        if hasattr(opts, attr):
            out[key] = getattr(opts, attr)
    return out | response_warnings(out)


def surface_line(run: dict) -> str:
    """The printed line of ``upd frf --contacts surface``'s run record (its JSON ``surface_model``)."""
    st = run["start"]
    how = (f"first point by the path in CF {st['loads'][0]:.4g} -> {st['loads'][-1]:.4g} N "
           f"({len(st['loads'])} loads)" if len(st.get("loads", ())) > 1 else "first point from the stuck start")
    return (f"surface model {run['model']}, {run['nodes_per_side']} nodes per side ({run['nodes']} nodes): "
            f"{run['evaluations']} evaluations, {run['cpu_s']:.1f} s CPU ({run['time_s']:.1f} s wall), of which "
            f"the truncation check (a peak search at more harmonics) {run['truncation_check_cpu_s']:.1f} s CPU; {how}")


def response_warnings(out: dict) -> dict:
    """``band_end_warning`` (the refined largest amplitude lies at an end of the band: no peak
    inside it) and ``lift_off_warning`` (:func:`damper.upd_checks.rattle_warning` at the peak)
    of a ``upd frf`` result, each a line or None."""
    from damper.upd_checks import at_band_end, rattle_warning

    f, w = out["frequency_hz"], out["peak_frequency_hz"]
    band_end = None
    if at_band_end(w, f[0], f[-1]):   # the refined maximum (a coarse grid's largest point may be an end)
        band_end = (f"warning: the largest amplitude lies at the band's end {w:.6g} Hz, not at a peak "
                    f"inside the band {f[0]:g} ... {f[-1]:g} Hz: widen or move --band to find the resonance")
    rattle = None
    if out.get("lift_off"):
        hint = ("" if "contact_surfaces" in out else
                " (--check-steady-state compares the peak with a time integration)")
        rattle = rattle_warning(out["lift_off"], out["f0"], out["cf"], out["harmonics"], hint)
    return {"band_end_warning": band_end, "lift_off_warning": rattle}


def _frf_linear(sector, opts, omegas) -> dict:
    from harmonic_balance.bladed_disk.sector import linear_response, peak_of

    t0 = time.perf_counter()
    f0 = opts.f0 or sector.cfg.f0
    r = sector.response  # the blade's response DOF (u_a of UPD-24)
    U = linear_response(sector, omegas, opts.damper, f0)[:, r]
    w, a = peak_of(lambda om: abs(linear_response(sector, om, opts.damper, f0)[0, r]),
                   omegas[0], omegas[-1], len(omegas))
    return {"damper": opts.damper, "response_dof": sector.dof_names[r],
            "frequency_hz": (omegas / (2 * np.pi)).tolist(),
            "amplitude": np.abs(U).tolist(), "amplitude_max": np.abs(U).tolist(),
            "peak_frequency_hz": w / (2 * np.pi), "peak_amplitude": a,
            "time_s": time.perf_counter() - t0}


def _solve(sector, opts, omegas):
    """(hb, curve, truncation record) of the nonlinear sector: surfaces, fixed H or to an accuracy."""
    from damper import limits
    from harmonic_balance.bladed_disk.accuracy import peak_to_accuracy, truncation_error
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.solve import frf

    if opts.contacts == "surface":
        from damper.upd_surface import surface_curve

        hb, c, rec, opts.surface_run = surface_curve(sector, opts, omegas)
    elif opts.accuracy is None:
        hb = SectorHB(sector, opts.harmonics, cf=opts.cf, f0=opts.f0)
        c = frf(hb, omegas)
        rec = truncation_error(hb, c, limits.MAX_UPD_HARMONICS)
    else:
        t0, p0 = time.perf_counter(), time.process_time()
        hb, c, rec = peak_to_accuracy(sector, omegas, opts.accuracy, opts.harmonics,
                                      cf=opts.cf, f0=opts.f0)
        c.time_s = time.perf_counter() - t0
        c.extra["cpu_s"] = time.process_time() - p0   # the machine may be shared: CPU too
    return hb, c, rec


def _frf_nonlinear(sector, opts, omegas) -> dict:
    from damper.upd_surface import static_loads
    from harmonic_balance.accuracy import warning
    from harmonic_balance.bladed_disk.solve import energy_balance
    from harmonic_balance.bladed_disk.steady import annotate

    hb, c, rec = _solve(sector, opts, omegas)
    summ = _summary(hb, c, opts)
    out = {"damper": "nonlinear", "response_dof": sector.dof_names[sector.response],
           "cf": hb.cf, "f0": hb.f0, "harmonics": hb.H, "n_t": hb.basis.n_t,
           "frequency_hz": (c.omega / (2 * np.pi)).tolist(), "amplitude": c.amplitude.tolist(),
           "amplitude_max": c.amplitude_max.tolist(),
           "peak_frequency_hz": c.peak_omega / (2 * np.pi), "peak_amplitude": c.peak_amplitude,
           "contact_points": summ["names"], "normal_load_mean": summ["normal_load_mean"],
           "zone_edge_warning": summ.get("warning_zone_edge"),
           "normal_load_range": summ["normal_load_range"], "lift_off": summ["lift_off"],
           "static_normal_load": static_loads(hb),
           "energy_per_cycle_at_peak": energy_balance(hb, c.peak_x, c.peak_omega),
           "method": c.extra.get("method", ""), "peak_refined": c.extra.get("peak_refined"),
           "branch_points": c.extra.get("branch_points"), "evaluations": c.evaluations,
           "time_s": c.time_s, "truncation_error": rec,
           "truncation_warning": warning(rec)}
    a = rec.get("accuracy")
    if a and "H_peak" in a:   # the peak raised to the accuracy: its richest level is the result
        out |= {"peak_frequency_hz": a["peak_omega"] / (2 * np.pi), "peak_amplitude": a["peak_amplitude"],
                "harmonics_peak": a["H_peak"], "cpu_s": c.extra.get("cpu_s")}
    if "warning" in c.extra:  # a complete curve whose peak refinement failed: still exit 0
        out["warning"] = c.extra["warning"]
    out |= annotate(hb, c, opts.check_steady_state)
    out["time_s"] += out.get("steady_state", {}).get("time_s", 0.0)
    return out


def _summary(hb, c, opts) -> dict:
    """The contacts' summary at the curve's peak: per point, or per face with surfaces."""
    from damper import upd_surface

    if opts.contacts != "surface":
        return hb.contact_summary(c.peak_x)
    if opts.surface_model == "condensed":
        return upd_surface.condensed_summary(hb, c.peak_x, c.peak_omega)
    return upd_surface.face_summary(hb, hb.contact_summary(c.peak_x))


def plot_frf(out: dict, path) -> None:
    """First-harmonic and largest amplitude of the response DOF against frequency, written
    atomically (``damper upd frf --plot`` and the scene's ``upd_frf`` share it)."""
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from contact_core.fileio import save_png

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(out["frequency_hz"], np.array(out["amplitude"]) * 1e3, label="first harmonic")
    ax.plot(out["frequency_hz"], np.array(out["amplitude_max"]) * 1e3, "--", label="max |u_a(t)|")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("airfoil amplitude [mm]")
    ax.set_title(f"UPD sector, damper {out['damper']}")
    ax.legend()
    fig.tight_layout()
    save_png(fig, Path(path))
    plt.close(fig)
