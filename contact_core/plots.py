"""Plots of a normal contact result (matplotlib, Agg backend): pressure map,
contact area against Hertz, F-approach curve. Files are written atomically."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import bodies
from .fileio import save_png


def _mirror(x, y, v, symmetry):
    """Unfold the modelled part to the full face by its symmetry images."""
    xs, ys, vs = [x], [y], [v]
    if symmetry in ("quarter", "half"):
        xs.append(x)
        ys.append(-y)
        vs.append(v)
    if symmetry == "quarter":
        xs += [-x, -x]
        ys += [y, -y]
        vs += [v, v]
    return np.concatenate(xs), np.concatenate(ys), np.concatenate(vs)


def plot_all(result: dict, body, out_dir: str | Path) -> list[Path]:
    """Write pressure_map.png, contact_area.png and (if present) f_approach.png.

    ``body`` is the body kind or its name (``contact_core.bodies``): it draws
    its reference contact and names its reference curves.
    """
    kind = bodies.get(body)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    m = result["maps"]
    sym = result["meta"].get("symmetry", "full")
    x, y, p = _mirror(np.asarray(m["x"]), np.asarray(m["y"]), np.asarray(m["pressure"]), sym)
    _, _, c = _mirror(np.asarray(m["x"]), np.asarray(m["y"]), np.asarray(m["contact"]), sym)
    files = []
    fig, ax = plt.subplots(figsize=(6, 5))
    sc = ax.scatter(x * 1e3, y * 1e3, c=p / 1e6, s=12, cmap="viridis")
    fig.colorbar(sc, label="pressure [MPa]")
    ax.set(xlabel="x [mm]", ylabel="y [mm]", title=f"{kind.name}: pressure, F = {result['force']:.4g} N")
    if np.ptp(y) <= 3 * np.ptp(x):
        ax.set_aspect("equal")
    files.append(save_png(fig, out_dir / "pressure_map.png"))
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 5))
    ax.plot(x[c > 0] * 1e3, y[c > 0] * 1e3, "rs", ms=3, label="in contact")
    ax.plot(x[c == 0] * 1e3, y[c == 0] * 1e3, "b*", ms=3, label="open")
    h = result.get("hertz")
    if h:
        kind.draw_reference_contact(ax, h)
    ax.set(xlabel="x [mm]", ylabel="y [mm]", title="contact area")
    if np.ptp(y) <= 3 * np.ptp(x):
        ax.set_aspect("equal")
    ax.legend(loc="upper right")
    files.append(save_png(fig, out_dir / "contact_area.png"))
    plt.close(fig)

    if h:
        files.append(_profiles(result, kind, out_dir, plt))
    if "curve" in result:
        cv = result["curve"]
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.plot(np.asarray(cv["approach"]) * 1e6, cv["force"], "o-", label="FE")
        F = np.asarray(cv["force"])
        ref = kind.reference_f_approach(h, F) if h else None
        if ref is not None:
            ax.plot(ref * 1e6, F, "k--", label=kind.reference_label)
        ax.set(xlabel="approach [um]", ylabel="force [N]", title="force vs approach")
        ax.legend()
        files.append(save_png(fig, out_dir / "f_approach.png"))
        plt.close(fig)
    return files


def _profiles(result: dict, kind: bodies.Body, out_dir: Path, plt) -> Path:
    """Pressure along x on the row y = 0 (and, cylinder, at the end y = L/2) vs Hertz."""
    m, h = result["maps"], result["hertz"]
    x, y, p = (np.asarray(m[k]) for k in ("x", "y", "pressure"))
    fig, ax = plt.subplots(figsize=(6, 4.5))
    where = {"y0": np.abs(y) <= 1e-12, "ymax": np.isclose(y, y.max())}
    for row, label in kind.profile_rows:
        sel = where[row]
        order = np.argsort(x[sel])
        ax.plot(x[sel][order] * 1e3, p[sel][order] / 1e6, "o-", ms=3, label=label)
    size = kind.reference_size(h)
    xs = np.linspace(0, size, 200)
    ax.plot(xs * 1e3, h["p0"] * np.sqrt(1 - (xs / size) ** 2) / 1e6, "k--",
            label=kind.reference_label)
    ax.set(xlabel="x [mm]", ylabel="pressure [MPa]", title=f"{kind.name}: pressure profiles")
    ax.legend()
    path = save_png(fig, out_dir / "pressure_profiles.png")
    plt.close(fig)
    return path
