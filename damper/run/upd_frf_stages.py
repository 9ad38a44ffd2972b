"""The UPD forced-response stage: the sector's curve at one centrifugal load, as ``damper upd frf``.

The scene's ``[upd]`` table gives the model (``config``), the load (``cf``, ``f0``), the band and
its points (``band``, ``grid``), the harmonics (``harmonics``, ``accuracy``) and the contacts
(``contacts``, ``surface_nodes``, ``surface_model``); the loader has refused what the command
refuses. The computation is :func:`damper.upd_frf.frf_record`, the command's, so the stage's
result.json is the command's ``--json`` record.
"""
from __future__ import annotations

import tempfile
from pathlib import Path

from .backbone_stages import truncation_lines
from .contact_stages import collect_files
from .graph import Kind, Result, Stage

#: The [upd] keys the forced response reads (the model file enters by its hash, config_sha256).
KEYS = ("config_sha256", "cf", "f0", "band", "grid", "harmonics", "accuracy", "contacts",
        "surface_nodes", "surface_model")


class UPDFRF(Kind):
    """UPD sector: forced response of the EO excitation over a band at one CF, with point or
    surface contacts (``damper.upd_frf``)."""

    name = "upd_frf"
    modules = ("harmonic_balance", "fmu_src", "contact_core", "damper.upd_frf", "damper.upd_surface",
               "damper.upd_geometry", "damper.upd_checks")

    def instances(self, data):
        u = data.get("upd")
        if u is None:
            return []
        params = {k: u[k] for k in KEYS if k in u}
        return [Stage("upd_frf", self, params, products=("upd_frf",), extra={"config": u.get("config")})]

    def compute(self, stage, inputs, ctx):
        from damper.upd_frf import frf_record, options, plot_frf

        p = stage.params
        opts = options(config=stage.extra["config"], points=p["grid"], store=ctx.store,
                       **{k: p[k] for k in ("cf", "f0", "band", "harmonics", "accuracy", "contacts",
                                            "surface_nodes", "surface_model") if k in p})
        out = frf_record(opts)
        with tempfile.TemporaryDirectory() as tmp:
            plot_frf(out, Path(tmp) / "upd_frf.png")
            files = collect_files(Path(tmp))
        return Result(out, files=files)

    def outputs(self, stage, result):
        return {"upd_frf": "result.json"}

    def lines(self, stage, result):
        o = result.data
        what = "largest amplitude at the band's end" if o.get("band_end_warning") else "peak"
        at = f" at H = {o['harmonics_peak']}" if "harmonics_peak" in o else ""
        head = (f"{what} {o['peak_frequency_hz']:.4f} Hz, first-harmonic amplitude {o['peak_amplitude']:.6e} m"
                f"{at} (curve at H = {o.get('harmonics', '-')}, {o['time_s']:.2f} s)")
        from damper.upd_frf import surface_line

        notes = [o.get("warning") and f"warning: {o['warning']}"] + [
            o.get(k) for k in ("zone_edge_warning", "band_end_warning", "lift_off_warning")]
        if "surface_model" in o:
            notes.append(surface_line(o["surface_model"]))
        return [head] + [f"   {n}" for n in notes if n] + [f"   {line}" for line in truncation_lines(o)]

    def scalars(self, stage, result):
        o = result.data
        return {"peak_frequency_Hz": o["peak_frequency_hz"], "peak_amplitude_m": o["peak_amplitude"],
                "harmonics_H": o.get("harmonics_peak", o.get("harmonics")),
                "truncation_error_rel": (o.get("truncation_error") or {}).get("peak_amplitude_rel")}
