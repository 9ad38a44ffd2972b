"""Plots of a mistuning study (``damper upd mistuning --plot``, the scene's mistuning stage):
the amplification factors' histogram with the fitted density and the 0.95 quantile's
interval, and every sample's per-blade peaks over the tuned peak."""
from __future__ import annotations

import numpy as np


def plot_study(out: dict, folder) -> dict:
    """``mistuning_histogram.png`` (amplification factors) and ``mistuning_blades.png``
    (every sample's per-blade peaks over the tuned peak), written atomically."""
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    from contact_core.fileio import save_png

    ok = [s for s in out["samples"] if s["error"] is None]
    amp = np.array([s["amplification"] for s in ok])
    folder = Path(folder)
    fig, ax = plt.subplots(figsize=(6, 4))
    counts, edges, _ = ax.hist(amp, bins=max(5, min(40, amp.size // 4)), color="C0", alpha=0.8)
    ax.axvline(1.0, color="k", lw=1, label="tuned")
    ax.axvline(out["whitehead_bound"], color="C3", ls="--", lw=1, label="(1 + sqrt(N_b)) / 2")
    _plot_statistics(ax, out["statistics"], amp.size * (edges[1] - edges[0]), edges)
    ax.set_xlabel("amplification factor (worst blade / tuned peak)")
    ax.set_ylabel("samples")
    ax.set_title(f"{len(ok)} samples, N_b = {out['blades']}, damper {out['damper']}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths = {"histogram": str(save_png(fig, folder / "mistuning_histogram.png"))}
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(7, 4))
    blades = np.arange(out["blades"])
    for s in ok:
        ax.plot(blades, np.array(s["peak_per_blade"]) / out["tuned_peak"], ".", color="0.6", ms=3)
    worst = max(ok, key=lambda s: s["amplification"])
    ax.plot(blades, np.array(worst["peak_per_blade"]) / out["tuned_peak"], "o-", color="C3",
            label=f"sample {worst['index']} (max {worst['amplification']:.3f})")
    ax.axhline(1.0, color="k", lw=1)
    ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
    ax.set_xlabel("blade")
    ax.set_ylabel("peak / tuned peak")
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths["blades"] = str(save_png(fig, folder / "mistuning_blades.png"))
    plt.close(fig)
    return paths


def _plot_statistics(ax, st: dict, per_density: float, edges) -> None:
    """The best fitted density (scaled to the histogram's counts) and the 0.95 quantile
    with its interval (shaded) on the histogram's axes."""
    from scipy import stats

    fit = st.get("fit")
    if fit and fit["best"]:
        f = fit["fits"][fit["best"]]
        x = np.linspace(edges[0], edges[-1], 300)
        pdf = getattr(stats, f["family"]).pdf(x, *f["params"].values())
        ax.plot(x, per_density * pdf, color="C1", lw=1.5,
                label=f"{f['family']} fit (KS D {f['ks_distance']:.3f})")
    q = next((q for q in st["quantiles"] if q["q"] == 0.95), None)
    if q is not None and q["value"] is not None:
        ax.axvline(q["value"], color="C2", lw=1, label="0.95 quantile")
        if q["low"] is not None and q["high"] is not None:
            ax.axvspan(q["low"], q["high"], color="C2", alpha=0.2, label="its 95 % interval")
