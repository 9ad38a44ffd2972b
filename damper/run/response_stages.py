"""Forced-response stages: harmonic balance of the structure with the friction element.

One stage per excitation level, so adding a level computes only that curve and a
changed structural damping recomputes the forced responses and nothing upstream.
The blade-damper model joins as another structure ``model`` here.
"""
from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from .contact_stages import collect_files
from .element_stages import curve_of
from .graph import Kind, Result, Stage

#: Continuation points at most per curve (the frf command's default).
MAX_POINTS = 2000


def two_dof_model(s: dict, force: float, element):
    """The bundled 2-DOF blade-damper model with the friction element on the platform DOF.

    Tip mass m_tip on k_blade to the platform m_platform, which sits on k_disk to the
    ground and on the damper (the element, to the ground). Rayleigh damping C = beta K
    with beta = 2 zeta / omega_1 gives the damping ratio zeta at the first free mode
    (element removed). A cosine force of amplitude ``force`` [N] drives the tip (DOF 0,
    the response DOF).
    """
    from harmonic_balance.aft import FrictionLink
    from harmonic_balance.linear import LinearModel
    from harmonic_balance.model import Model

    M = np.diag([s["m_tip"], s["m_platform"]])
    K = np.array([[s["k_blade"], -s["k_blade"]], [-s["k_blade"], s["k_blade"] + s["k_disk"]]])
    omega1 = math.sqrt(min(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    beta = 2.0 * s["zeta"] / omega1
    lin = LinearModel(M=M, C=beta * K, K=K)
    forcing = {1: force * np.array([1.0, 0.0], dtype=complex)}
    return Model(lin, [FrictionLink(element, 1, None, "element0")], forcing, 0)


def matrices_model(path: str, dofs: list, scale: float, element):
    """A matrices file's structure (``harmonic_balance.model`` format) with the element on
    ``dofs`` ([a]: to the ground, [a, b]: between two DOFs) and the file's excitation times
    ``scale``."""
    from harmonic_balance.aft import FrictionLink
    from harmonic_balance.model import Model, load_matrices

    lin, forcing, resp = load_matrices(path)
    forcing = {h: scale * np.asarray(f, dtype=complex) for h, f in forcing.items()}
    b = dofs[1] if len(dofs) == 2 else None
    return Model(lin, [FrictionLink(element, dofs[0], b, "element0")], forcing, resp)


class FRF(Kind):
    """Forced-response curve by multi-harmonic balance and arc-length continuation."""

    name = "frf"
    modules = ("harmonic_balance", "fmu_src", "contact_core.curve")

    def instances(self, data):
        el, s, ex, sw = (data.get(k) for k in ("element", "structure", "excitation", "sweep"))
        if not (el and s and ex and sw):
            return []
        label = "frf:{:g}N" if s["model"] == "two_dof" else "frf:x{:g}"
        structure = {k: v for k, v in s.items() if k != "matrices"}     # the file enters by its hash
        return [Stage(label.format(F), self, {"structure": structure, "force": F, "sweep": sw},
                      deps=(f"tangential:{el['contact']}",), products=("frf",),
                      extra={"matrices": s.get("matrices")}) for F in ex["forces"]]

    def compute(self, stage, inputs, ctx):
        from damper import limits
        from fmu_src.element import IwanElement
        from harmonic_balance.frf import FRFError, check_peak_traced, compute_frf
        from harmonic_balance.plots import plot_frf

        p = stage.params
        element = IwanElement.from_virgin_curve(curve_of(inputs[stage.deps[0]]))
        if p["structure"]["model"] == "two_dof":
            model = two_dof_model(p["structure"], p["force"], element)
        else:
            model = matrices_model(stage.extra["matrices"], p["structure"]["element_dofs"], p["force"], element)
        sw = p["sweep"]
        omega = (2 * math.pi * sw["f_min"], 2 * math.pi * sw["f_max"])
        try:
            result = compute_frf(model, str(sw["harmonics"]), omega, ds_max=sw["max_step"], max_points=MAX_POINTS,
                                 progress=ctx.progress, accuracy=sw.get("accuracy"),
                                 max_harmonic=limits.MAX_HARMONICS)
            check_peak_traced(result)
        except FRFError as err:
            hint = f": {err.hint}" if getattr(err, "hint", None) else ""
            raise RuntimeError(f"{err} ({err.result.points} points kept){hint}") from None
        with tempfile.TemporaryDirectory() as tmp:
            plot_frf(result, tmp)
            files = collect_files(Path(tmp))
        return Result(result.summary(), files=files)

    def outputs(self, stage, result):
        return {"frf": "result.json"}

    def lines(self, stage, result):
        from harmonic_balance.frf_accuracy import summary_lines

        s = result.data
        level = (f"P = {stage.params['force']:g} N" if stage.params["structure"]["model"] == "two_dof"
                 else f"force x {stage.params['force']:g}")
        return [f"{s['points']} points, {s['newton_iterations']} Newton iterations, "
                f"{s['time_s']:.3f} s, harmonics {s['harmonics']}, n_t {s['n_t']}",
                f"peak: omega = {s['peak_omega']:.9g} rad/s, amplitude = "
                f"{s['peak_amplitude']:.9g} m (first harmonic {s['peak_amplitude_h1']:.9g} m there)",
                *summary_lines(s),
                f"status: {s['status']}",
                f"   {level}: peak {s['peak_amplitude']:.3e} m at "
                f"{s['peak_omega'] / (2 * math.pi):.1f} Hz ({s['points']} points, {s['time_s']:.2f} s)"]

    def scalars(self, stage, result):
        s = result.data
        return {"peak_frequency_Hz": s["peak_omega"] / (2 * math.pi) if s["peak_omega"] else None,
                "peak_amplitude_m": s["peak_amplitude"], "points": s["points"],
                "harmonics_H": max(s["harmonics"]) if s.get("harmonics") else None,
                "truncation_error_rel": (s.get("truncation_error") or {}).get("peak_amplitude_rel")}
