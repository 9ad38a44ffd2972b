"""Plots of a normal contact result (matplotlib, Agg backend): pressure map,
contact area against Hertz, F-approach curve. Files are written atomically."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from .fileio import atomic_write


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


def _save(fig, path: Path) -> Path:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    return atomic_write(path, buf.getvalue())


def plot_all(result: dict, body: str, out_dir: str | Path) -> list[Path]:
    """Write pressure_map.png, contact_area.png and (if present) f_approach.png."""
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
    ax.set(xlabel="x [mm]", ylabel="y [mm]", title=f"{body}: pressure, F = {result['force']:.4g} N")
    if np.ptp(y) <= 3 * np.ptp(x):
        ax.set_aspect("equal")
    files.append(_save(fig, out_dir / "pressure_map.png"))
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 5))
    ax.plot(x[c > 0] * 1e3, y[c > 0] * 1e3, "rs", ms=3, label="in contact")
    ax.plot(x[c == 0] * 1e3, y[c == 0] * 1e3, "b*", ms=3, label="open")
    h = result.get("hertz")
    if h and body == "sphere":
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(h["a"] * 1e3 * np.cos(t), h["a"] * 1e3 * np.sin(t), "k-", label="Hertz")
    elif h and body == "cylinder":
        for s in (-1, 1):
            ax.axvline(s * h["b"] * 1e3, color="k", label="Hertz" if s > 0 else None)
    ax.set(xlabel="x [mm]", ylabel="y [mm]", title="contact area")
    if np.ptp(y) <= 3 * np.ptp(x):
        ax.set_aspect("equal")
    ax.legend(loc="upper right")
    files.append(_save(fig, out_dir / "contact_area.png"))
    plt.close(fig)

    if h:
        files.append(_profiles(result, body, out_dir, plt))
    if "curve" in result:
        cv = result["curve"]
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.plot(np.asarray(cv["approach"]) * 1e6, cv["force"], "o-", label="FE")
        if body == "sphere" and h:
            F = np.asarray(cv["force"])
            R = h["a"] ** 2 / h["approach"]
            a = (3 * F * R / (4 * h["k_n"] / (2 * h["a"]))) ** (1 / 3)
            ax.plot(a**2 / R * 1e6, F, "k--", label="Hertz")
        ax.set(xlabel="approach [um]", ylabel="force [N]", title="force vs approach")
        ax.legend()
        files.append(_save(fig, out_dir / "f_approach.png"))
        plt.close(fig)
    return files


def _profiles(result: dict, body: str, out_dir: Path, plt) -> Path:
    """Pressure along x on the row y = 0 (and, cylinder, at the end y = L/2) vs Hertz."""
    m, h = result["maps"], result["hertz"]
    x, y, p = (np.asarray(m[k]) for k in ("x", "y", "pressure"))
    fig, ax = plt.subplots(figsize=(6, 4.5))
    rows = [(np.abs(y) <= 1e-12, "FE, y = 0")]
    if body == "cylinder":
        rows.append((np.isclose(y, y.max()), "FE, end y = L/2"))
    for sel, label in rows:
        order = np.argsort(x[sel])
        ax.plot(x[sel][order] * 1e3, p[sel][order] / 1e6, "o-", ms=3, label=label)
    size = h["a"] if body == "sphere" else h["b"]
    xs = np.linspace(0, size, 200)
    ax.plot(xs * 1e3, h["p0"] * np.sqrt(1 - (xs / size) ** 2) / 1e6, "k--",
            label="Hertz" if body == "sphere" else "2D Hertz")
    ax.set(xlabel="x [mm]", ylabel="pressure [MPa]", title=f"{body}: pressure profiles")
    ax.legend()
    path = _save(fig, out_dir / "pressure_profiles.png")
    plt.close(fig)
    return path
