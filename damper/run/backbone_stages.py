"""The backbone stage: nonlinear mode of the structure with the friction element (EPMC).

The structure is the scene's ``[structure]`` (the 2-DOF blade-damper model or a matrices
file; its excitation is ignored, a nonlinear mode is a free motion); the element is either
the scene's ``[element]`` (built from its contact's virgin curve, so the plan runs the
contact stages) or a Jenkins element given in ``[backbone]`` (no contact or FE stage).
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from .contact_stages import collect_files
from .element_stages import curve_of
from .graph import Kind, Result, Stage
from .response_stages import matrices_model, two_dof_model

#: Continuation points at most per backbone (``compute_backbone``'s default).
MAX_POINTS = 2000


class Backbone(Kind):
    """Backbone (frequency and damping ratio vs modal amplitude) by ``harmonic_balance.epmc``."""

    name = "backbone"
    modules = ("harmonic_balance", "fmu_src", "contact_core.curve")

    def instances(self, data):
        bb, s = data.get("backbone"), data.get("structure")
        if not (bb and s) or (bb["element"] == "contact" and "element" not in data):
            return []
        deps = (f"tangential:{data['element']['contact']}",) if bb["element"] == "contact" else ()
        structure = {k: v for k, v in s.items() if k != "matrices"}     # the file enters by its hash
        return [Stage("backbone", self, {"structure": structure, "backbone": bb}, deps=deps,
                      products=("backbone",), extra={"matrices": s.get("matrices")})]

    def compute(self, stage, inputs, ctx):
        from damper import limits
        from fmu_src.element import IwanElement
        from harmonic_balance.epmc import EPMCError, compute_backbone
        from harmonic_balance.epmc_accuracy import backbone_to_accuracy, truncation_error, warning

        p, bb = stage.params, stage.params["backbone"]
        if bb["element"] == "contact":
            element = IwanElement.from_virgin_curve(curve_of(inputs[stage.deps[0]]))
        else:
            element = IwanElement.jenkins(bb["contact_stiffness"], bb["slip_force"])
        # a Model needs an excitation; EPMC ignores it (a nonlinear mode is a free motion)
        if p["structure"]["model"] == "two_dof":
            model = two_dof_model(p["structure"], 1.0, element)
        else:
            model = matrices_model(stage.extra["matrices"], p["structure"]["element_dofs"], 1.0, element)
        try:
            if bb.get("accuracy") is None:
                result = compute_backbone(model, str(bb["harmonics"]), bb["amplitude"], n_t=bb["samples"],
                                          mode=bb["mode"], max_points=MAX_POINTS)
                rec = truncation_error(model, str(bb["harmonics"]), result, bb["samples"], bb["mode"],
                                       limits.MAX_HARMONICS)
            else:
                result, rec = backbone_to_accuracy(model, str(bb["harmonics"]), bb["amplitude"],
                                                   bb["accuracy"], bb["samples"], bb["mode"],
                                                   limits.MAX_HARMONICS)
        except EPMCError as err:
            raise RuntimeError(f"{err} ({err.result.a.size} points kept)") from None
        summary = result.summary() | {"harmonics": rec["H_used"]}
        summary["truncation_error"], summary["truncation_warning"] = rec, warning(rec)
        with tempfile.TemporaryDirectory() as tmp:
            plot_backbone(summary, Path(tmp) / "backbone.png")
            files = collect_files(Path(tmp))
        return Result(summary, files=files)

    def outputs(self, stage, result):
        return {"backbone": "result.json"}

    def lines(self, stage, result):
        from harmonic_balance.epmc_accuracy import summary_lines

        s = result.data
        w, d = np.asarray(s["omega"]), np.asarray(s["damping_ratio"])
        i = int(np.nanargmax(d)) if d.size else 0
        return [f"{s['points']} points, {s['newton_iterations']} Newton iterations, status: {s['status']}",
                f"   frequency {w[0] / (2 * np.pi):.1f} Hz (stuck) -> {w[-1] / (2 * np.pi):.1f} Hz; "
                f"largest damping ratio {d[i]:.4g} at modal amplitude {s['modal_amplitude'][i]:.4g}"] + [
                    f"   {line}" for line in summary_lines(s.get("truncation_error"))]

    def scalars(self, stage, result):
        s = result.data
        d = np.asarray(s["damping_ratio"], dtype=float)
        rec = s.get("truncation_error") or {}
        return {"stuck_frequency_Hz": s["omega"][0] / (2 * np.pi), "end_frequency_Hz": s["omega"][-1] / (2 * np.pi),
                "max_damping_ratio": float(np.nanmax(d)), "points": s["points"],
                "harmonics_H": rec.get("H_used"), "truncation_error_omega_rel": rec.get("omega_rel"),
                "truncation_error_damping_rel": rec.get("damping_ratio_rel")}


def plot_backbone(s: dict, path: Path) -> None:
    """Frequency and damping ratio against the modal amplitude (log scale), one figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a = np.asarray(s["modal_amplitude"])
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
    ax1.semilogx(a, np.asarray(s["omega"]) / (2 * np.pi))
    ax1.set_ylabel("frequency [Hz]")
    ax2.semilogx(a, s["damping_ratio"])
    ax2.set_ylabel("damping ratio [-]")
    ax2.set_xlabel("modal amplitude [m sqrt(kg)]")
    ax1.set_title("backbone (EPMC)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


class OptimalLoad(Kind):
    """UPD bladed-disk sector: peak response against CF and the optimal load
    (``harmonic_balance.bladed_disk.optimize.optimal_load``; with contacts = "surface"
    ``damper.upd_surface.optimize_record``); no contact or FE stage."""

    name = "optimal_load"
    modules = ("harmonic_balance", "fmu_src", "damper.upd_frf", "damper.upd_geometry", "damper.upd_surface")

    def instances(self, data):
        u = data.get("upd")
        if u is None:
            return []
        keys = ("cf_range", "points", "harmonics", "grid", "accuracy", "contacts", "config_sha256",
                "surface_nodes", "surface_model")
        params = {k: u[k] for k in keys if k in u}    # its own keys; the file enters by its hash
        return [Stage("optimal_load", self, params, products=("optimal_load",),
                      extra={"config": u.get("config")})]

    def compute(self, stage, inputs, ctx):
        import time

        from damper import limits
        from damper.upd_frf import options, upd_sector
        from harmonic_balance.accuracy import warning
        from harmonic_balance.bladed_disk.accuracy import optimal_load_to_accuracy, optimum_truncation
        from harmonic_balance.bladed_disk.optimize import optimal_load

        p = stage.params
        opts = options(config=stage.extra["config"], contacts=p.get("contacts", "toml"), store=ctx.store,
                       cf_range=p["cf_range"], points=p["points"], harmonics=p["harmonics"],
                       surface_nodes=p.get("surface_nodes"))
        sector = upd_sector(opts)
        if opts.contacts == "surface":   # the walk of the condensed surface model (damper upd optimize's)
            from damper.upd_surface import optimize_record

            out = optimize_record(sector, opts, note=ctx.note)   # its estimate, then a line per load
        elif p.get("accuracy") is None:
            out = optimal_load(sector, p["cf_range"], p["points"], p["harmonics"], grid=p["grid"])
            out["truncation_error"] = optimum_truncation(sector, out, p["grid"], limits.MAX_UPD_HARMONICS)
        else:
            t0 = time.perf_counter()
            out = optimal_load_to_accuracy(sector, p["cf_range"], p["accuracy"], p["points"], p["harmonics"],
                                           p["grid"], limit=limits.MAX_UPD_HARMONICS)
            out["time_s"] = time.perf_counter() - t0   # both sweeps and the curves that chose H
        out["truncation_warning"] = warning(out["truncation_error"])
        with tempfile.TemporaryDirectory() as tmp:
            plot_optimal_load(out, Path(tmp) / "optimal_load.png")
            files = collect_files(Path(tmp))
        return Result(out, files=files)

    def outputs(self, stage, result):
        return {"optimal_load": "result.json"}

    def lines(self, stage, result):
        o = result.data
        out = [f"optimum CF {o['optimum_cf']:.4g} N, peak {o['optimum_peak_amplitude']:.5e} m "
               f"({o['method']}, H = {o['harmonics']}, {o['time_s']:.1f} s)"]
        if "surface_model" in o:
            from damper.upd_surface import optimize_line

            out.append(f"   {optimize_line(o['surface_model'])}")
        if "warning" in o:   # a surface walk that stopped above the range's low end (as upd optimize prints it)
            out.append(f"   warning: {o['warning']}")
        return out + [f"   {line}" for line in truncation_lines(o)]

    def scalars(self, stage, result):
        o = result.data
        return {"optimum_cf_N": o["optimum_cf"], "optimum_peak_amplitude_m": o["optimum_peak_amplitude"],
                "harmonics_H": o["harmonics"],
                "truncation_error_rel": (o.get("truncation_error") or {}).get("peak_amplitude_rel")}


def truncation_lines(out: dict) -> list[str]:
    """The truncation-error lines of a UPD result with a sector record (the optimum's, or
    the tuned peak of a mistuning study): estimate, accuracy run, warning; frequencies in Hz."""
    from harmonic_balance.frf_accuracy import summary_lines

    rec = out.get("truncation_error")
    if not rec:
        return []
    return summary_lines({"truncation_error": rec, "accuracy": rec.get("accuracy"),
                          "truncation_warning": out.get("truncation_warning")}, hz=True)


def plot_optimal_load(o: dict, path: Path) -> None:
    """Peak amplitude against CF (log-log) with the optimum marked, written atomically
    (the scene stage and ``damper upd optimize --plot`` share it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from contact_core.fileio import save_png

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(o["cf"], np.array(o["peak_amplitude"]) * 1e3, "o-")
    ax.loglog([o["optimum_cf"]], [o["optimum_peak_amplitude"] * 1e3], "r*", ms=12)
    ax.set_xlabel("centrifugal load CF [N]")
    ax.set_ylabel("peak amplitude [mm]")
    ax.set_title("optimal-load curve (UPD sector)")
    fig.tight_layout()
    save_png(fig, Path(path))
    plt.close(fig)
