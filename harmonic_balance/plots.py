"""Figures of a forced-response curve: the curve, the loops at the peak, the harmonics.

matplotlib (Agg backend) only; every file is written through ``atomic_write`` so a
failure leaves no half-written image.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from contact_core.fileio import save_png


def plot_frf(result, out_dir) -> list[Path]:
    """Write frf.png, loops.png and harmonics.png for an FRFResult; return the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    prob, b = result.problem, result.problem.basis
    paths = []
    fig, ax = plt.subplots(figsize=(6, 4))
    _plot_stability(ax, result)
    if np.all(np.isfinite(result.amplitude_h1)):
        ax.plot(result.omega, result.amplitude_h1, "--", label="first harmonic |X_1|")
    if np.isfinite(result.peak_amplitude):
        ax.plot([result.peak_omega], [result.peak_amplitude], "o", label="refined peak")
    ax.set(xlabel="omega [rad/s]", ylabel="amplitude [m]",
           title=f"FRF, harmonics {list(b.harmonics)}")
    ax.legend()
    fig.tight_layout()
    paths.append(save_png(fig, out / "frf.png"))
    plt.close(fig)

    x, w = result.peak_solution, result.peak_omega
    if result.extra.get("peak_problem") is not None:   # a peak raised in H: its richest level
        prob, x = result.extra["peak_problem"], result.extra["peak_level_solution"]
        b = prob.basis
    fig, ax = plt.subplots(figsize=(6, 4))
    for (u, F, W), link in zip(prob.residual.link_samples(x), prob.residual.elements):
        if u is None:   # no samples (a linear element): no loop to draw
            continue
        ax.plot(np.append(u, u[0]), np.append(F, F[0]), label=f"{link.name} (W = {W:.3g} J)")
    ax.set(xlabel="relative displacement [m]", ylabel="friction force [N]",
           title=f"hysteresis loops at the peak, omega = {w:.6g} rad/s")
    ax.legend()
    fig.tight_layout()
    paths.append(save_png(fig, out / "loops.png"))
    plt.close(fig)

    r = prob.response(x, w)
    mags = [b.magnitude(r, h) for h in b.harmonics]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.bar([str(h) for h in b.harmonics], np.maximum(mags, 1e-300))
    ax.set_yscale("log")
    ax.set(xlabel="harmonic", ylabel="|X_h| [m]", title="response harmonics at the peak")
    fig.tight_layout()
    paths.append(save_png(fig, out / "harmonics.png"))
    plt.close(fig)
    return paths


def _plot_stability(ax, result):
    """The curve, solid where stable (or stability unknown), dashed where Hill finds it unstable."""
    om, amp = np.asarray(result.omega), np.asarray(result.amplitude)
    if result.stable is None or all(result.stable):
        ax.plot(om, amp, "-", color="C0", label="peak |x| over the period")
        return
    st = np.asarray(result.stable, dtype=bool)
    labels = {True: "stable", False: "unstable (Hill)"}
    start = 0
    for i in range(1, len(om) + 1):
        if i == len(om) or st[i] != st[start]:
            j = min(i + 1, len(om))  # overlap one point so the segments join
            ax.plot(om[start:j], amp[start:j], "-" if st[start] else "--", color="C0",
                    label=labels.pop(bool(st[start]), None))
            start = i
