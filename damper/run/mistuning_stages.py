"""The mistuning stage: Monte Carlo of mistuning patterns on the UPD full ring.

The scene's ``[mistuning]`` table (``damper.mistuning.Study``; the model from ``[upd]``'s
``config``, default UPD-24). The samples run in this process, each stored in the cache
under its own key (``damper.mistuning``), so an interrupted run resumes and a study
that shares samples with ``damper upd mistuning`` reuses them.
"""
from __future__ import annotations

import tempfile
from pathlib import Path

from .backbone_stages import truncation_lines
from .contact_stages import collect_files
from .graph import Kind, Result, Stage


class Mistuning(Kind):
    """Per-blade peaks of the mistuned ring over samples, amplification statistics."""

    name = "mistuning"
    modules = ("harmonic_balance", "fmu_src", "damper.mistuning", "damper.mistuning_stats")

    def instances(self, data):
        if "mistuning" not in data:
            return []
        upd = data.get("upd") or {}
        params = {"mistuning": data["mistuning"], "config_sha256": upd.get("config_sha256")}
        return [Stage("mistuning", self, params, products=("mistuning",),
                      extra={"data": {"mistuning": data["mistuning"], "upd": upd}})]

    def compute(self, stage, inputs, ctx):
        from damper.mistuning import run_study, study_from_scene
        from damper.mistuning_plot import plot_study

        out = run_study(study_from_scene(stage.extra["data"]), ctx.store, serial=True,
                        echo=lambda text: None)
        with tempfile.TemporaryDirectory() as tmp:
            plot_study(out, Path(tmp))
            files = collect_files(Path(tmp))
        return Result(out, files=files)

    def outputs(self, stage, result):
        return {"mistuning": "result.json"}

    def lines(self, stage, result):
        o = result.data
        return [f"{len(o['samples'])} samples of {o['blades']} blades ({o['failed']} failed): amplification "
                f"max {o['max_amplification']:.4f}, median {o['quantiles']['0.5']:.4f} over the tuned peak "
                f"{o['tuned_peak']:.4e} m at {o['tuned_frequency_hz']:.2f} Hz, H = {o['harmonics']}"] + _ci_lines(o) + [
                    f"   {line}" for line in truncation_lines(o)] + (
                    [f"   {o['lift_off_warning']}"] if o.get("lift_off_warning") else [])

    def scalars(self, stage, result):
        o = result.data
        return {"max_amplification": o["max_amplification"], "mean_amplification": o["mean_amplification"],
                "q95_amplification": o["quantiles"]["0.95"], "tuned_peak_m": o["tuned_peak"],
                "harmonics_H": o["harmonics"],
                "tuned_truncation_error_rel": (o.get("truncation_error") or {}).get("peak_amplitude_rel"),
                "failed_samples": o["failed"]} | {f"q95_amplification_{k}": v for k, v in _q95(o).items()
                                                  if k in ("low", "high") and v is not None}


def _q95(o: dict) -> dict:
    return next(q for q in o["statistics"]["quantiles"] if q["q"] == 0.95)


def _ci_lines(o: dict) -> list:
    """The 0.95 quantile's interval and the --until-ci outcome."""
    q = _q95(o)
    est = "not estimated" if q["value"] is None else f"{q['value']:.4f}"
    line = (f"0.95 quantile {est}, 95 % interval " + (
        f"[{q['low']:.4f}, {q['high']:.4f}]" if q["half_width"] is not None else "not bounded by so few samples"))
    if "until_ci" in o:
        u = o["until_ci"]
        line += f"; until_ci {u['half_width_target']:g} " + ("reached" if u["reached"] else "not reached")
    return [line]
