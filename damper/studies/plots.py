"""Figures of the studies (matplotlib, Agg; files written atomically)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from contact_core.fileio import save_png


def plot(name: str, result: dict, out_dir) -> None:
    """Write the figures of study ``name`` into ``out_dir``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    if name in ("cylinders", "compression"):
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
        for m in result["models"]:
            lab = f"cyl {m['cylinder']}"
            if name == "cylinders":
                axes[0].plot(np.asarray(m["approach"]) * 1e6, m["force"], "o-", label=lab)
                axes[1].plot(np.asarray(m["tangential_approach"]) * 1e6, m["tangential_force"], "o-", label=lab)
            else:
                axes[0].plot(m["force"], np.asarray(m["body1_share"]) * 100, "o-", label=lab)
                far = [np.nan if v is None else 100 * v for v in m["body1_share_far"]]
                axes[1].plot(m["force"], far, "o-", label=lab)
        if name == "cylinders":
            axes[0].set(xlabel="normal approach [um]", ylabel="normal force [N]", title="Fig. 21")
            axes[1].set(xlabel="tangential displacement [um]", ylabel="tangential force [N]", title="Fig. 29")
        else:
            axes[0].set(xlabel="F [N]", ylabel="body-1 share at centre [%]")
            axes[1].set(xlabel="F [N]", ylabel="body-1 compression outside contact [%]")
        for ax in axes:
            ax.legend(fontsize=7)
        save_png(fig, out / f"{name}.png", dpi=110)
        plt.close(fig)
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for c in result["cases"]:
        axes[0].plot(np.asarray(c["u"]) * 1e6, c["T"], label=c["case"])
        y = np.asarray(c["y"])
        row = np.abs(y) <= 1e-12
        x = np.asarray(c["x"])[row]
        order = np.argsort(x)
        axes[1].plot(x[order] * 1e3, np.asarray(c["pressure"])[row][order] / 1e6, label=c["case"])
    axes[0].set(xlabel="u [um]", ylabel="T [N]", title="virgin curves (Figs. 47, 52)")
    axes[1].set(xlabel="x [mm]", ylabel="pressure at y = 0 [MPa]", title="pressure (Figs. 45-46)")
    for ax in axes:
        ax.legend(fontsize=7)
    save_png(fig, out / "eccentric.png", dpi=110)
    plt.close(fig)
