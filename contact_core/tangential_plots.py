"""Plots of a tangential run: virgin curve, stick/slip maps, traction (matplotlib, Agg)."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_curve(path, problem, out: Path, reference=None) -> Path:
    """T(u) with the stuck line k_t u and an optional reference (u, T) curve."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.6))
    u, T = path.u, path.T
    ax.plot(u * 1e6, T, "o-", ms=3, label="contact model")
    u_line = np.array([0.0, min(u[-1], 1.1 * problem.mu * problem.N / problem.k_t)])
    ax.plot(u_line * 1e6, problem.k_t * u_line, ":", label="k_t u")
    if reference is not None:
        ax.plot(reference[0] * 1e6, reference[1], "--", label="Cattaneo-Mindlin")
    ax.axhline(problem.mu * problem.N, color="0.6", lw=0.8)
    ax.set(xlabel="tangential displacement u [um]", ylabel="tangential force T [N]",
           title=f"virgin curve, N = {problem.N:.4g} N, mu = {problem.mu:g}")
    ax.legend()
    return _save(fig, out / "virgin_curve.png")


def plot_stick_slip(path, problem, out: Path, fractions=(0.25, 0.5, 0.75, 0.95)) -> Path:
    """Stick (blue) and slip (red) nodes at points of the curve near T/(mu N) = fractions."""
    plt = _pyplot()
    grid = problem.contact.grid
    fig, axes = plt.subplots(1, len(fractions), figsize=(3.2 * len(fractions), 3.2), squeeze=False)
    limit = problem.mu * problem.N
    for ax, frac in zip(axes[0], fractions):
        p = path.points[int(np.argmin(np.abs(path.T - frac * limit)))]
        ax.plot(grid.x * 1e3, grid.y * 1e3, ".", color="0.85", ms=2)
        ax.plot(grid.x[p.slip] * 1e3, grid.y[p.slip] * 1e3, "s", color="tab:red", ms=3)
        ax.plot(grid.x[p.stick] * 1e3, grid.y[p.stick] * 1e3, "*", color="tab:blue", ms=4)
        ax.set(title=f"T/(mu N) = {p.T / limit:.2f}", xlabel="x [mm]", ylabel="y [mm]")
        ax.set_aspect("equal", adjustable="datalim")
    return _save(fig, out / "stick_slip_maps.png")


def plot_traction(path, problem, out: Path, fraction: float = 0.6) -> Path:
    """Traction q/area, the slip limit mu p and the slip along x on y = 0, near T/(mu N) = fraction."""
    plt = _pyplot()
    grid = problem.contact.grid
    p = path.points[int(np.argmin(np.abs(path.T - fraction * problem.mu * problem.N)))]
    line = np.isclose(grid.y, grid.y[np.argmin(np.abs(grid.y))])
    order = np.argsort(grid.x[line])
    x = grid.x[line][order]
    tau = (p.q / grid.area)[line][order]
    lim = (problem.mu * problem.f_n / grid.area)[line][order]
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(x * 1e3, lim / 1e6, "--", label="mu p")
    ax.plot(x * 1e3, tau / 1e6, "o-", ms=3, label="traction q")
    ax.set(xlabel="x [mm] (y = 0)", ylabel="traction [MPa]",
           title=f"traction and slip at T/(mu N) = {p.T / (problem.mu * problem.N):.2f}")
    ax.legend(loc="upper left")
    slip_ax = ax.twinx()
    slip_ax.plot(x * 1e3, p.s[line][order] * 1e9, "s:", ms=2, color="tab:red")
    slip_ax.set_ylabel("accumulated slip [nm]", color="tab:red")
    return _save(fig, out / "traction.png")


def plot_loop(loop_path, amplitude: float, curve_u, curve_T, out: Path) -> Path:
    """A loop computed by the contact model against Masing's branches from the virgin table."""
    from contact_core.tangential_reference import masing_branch

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 3.6))
    ax.plot(loop_path.u * 1e6, loop_path.T, "-", label="contact model (slip history)")
    T_a = float(np.interp(amplitude, curve_u, curve_T))
    down = np.linspace(amplitude, -amplitude, 100)
    ax.plot(down * 1e6, masing_branch(down, amplitude, T_a, curve_u, curve_T), "k--", label="Masing")
    ax.plot(-down * 1e6, masing_branch(-down, -amplitude, -T_a, curve_u, curve_T), "k--")
    ax.set(xlabel="u [um]", ylabel="T [N]", title=f"hysteresis loop, a = {amplitude * 1e6:.3g} um")
    ax.legend()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return _save(fig, out / "loop.png")


def plot_all(path, problem, out, reference=None) -> list:
    """All three plots into folder ``out``; returns the file paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return [plot_curve(path, problem, out, reference), plot_stick_slip(path, problem, out),
            plot_traction(path, problem, out)]


def _save(fig, path: Path) -> Path:
    """Lay out, write atomically (:func:`~contact_core.fileio.save_png`) and close ``fig``."""
    import matplotlib.pyplot as plt

    from .fileio import save_png

    fig.tight_layout()
    save_png(fig, path)
    plt.close(fig)
    return path
