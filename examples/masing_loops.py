"""Masing loops of a sphere contact: the Iwan element against Mindlin-Deresiewicz.
===============================================================================

The Cattaneo-Mindlin virgin curve of a steel sphere (R = 10 mm, N = 100 N,
mu = 0.5; references.md) is tabulated with m segments (uniform in T, flat after
gross slip) and turned into an Iwan element. Its steady loop under a harmonic
tangential force of amplitude T* = x mu N (the displacement amplitude is the
exact inverse of the table's virgin curve) gives the energy per cycle, compared
with the Mindlin-Deresiewicz closed form. Prints a table (m, x, W, W_MD, error,
time per loop) and saves ``loops.png`` (loops over the virgin curve) and
``energy.png`` (W against x, with the small-x law T*^3 / (36 a mu N G*)). ::

    python examples/masing_loops.py                # m = 16 .. 255
    python examples/masing_loops.py --smoke        # tiny (the test runs this)
"""
from __future__ import annotations

import argparse
import io
import sys
import time
from pathlib import Path

import numpy as np

from contact_core.fileio import atomic_write
from fmu_src.element import IwanElement

# Steel on steel (references.md): E* = 109.9 GPa, G* = 22.6 GPa.
E_MOD, NU, RADIUS, N_LOAD, MU = 200e9, 0.3, 10e-3, 100.0, 0.5
E_STAR = E_MOD / (2.0 * (1.0 - NU**2))
G_STAR = E_MOD / (2.0 * (1.0 + NU)) / (2.0 * (2.0 - NU))
A_HERTZ = (3.0 * N_LOAD * RADIUS / (4.0 * E_STAR)) ** (1.0 / 3.0)
U_SLIP = 3.0 * MU * N_LOAD / (16.0 * G_STAR * A_HERTZ)
SAMPLES = 256


def sphere_table(m: int):
    """Cattaneo-Mindlin curve, m segments uniform in T, plus a flat gross-slip tail."""
    T = MU * N_LOAD * np.arange(m + 1) / m
    u = U_SLIP * (1.0 - (1.0 - T / (MU * N_LOAD)) ** (2.0 / 3.0))
    return np.append(u, 2.0 * U_SLIP), np.append(T, MU * N_LOAD)


def mindlin_deresiewicz(x):
    """Energy per cycle [J] at T* = x mu N (Mindlin-Deresiewicz)."""
    return (9.0 * MU**2 * N_LOAD**2 / (10.0 * A_HERTZ * G_STAR)) * (
        1.0 - (1.0 - x) ** (5.0 / 3.0) - (5.0 * x / 6.0) * (1.0 + (1.0 - x) ** (2.0 / 3.0)))


def loop_for_force(el, u_tab, T_tab, x):
    """Steady loop at force amplitude x mu N: (u, F, W_cycle, seconds)."""
    a = np.interp(x * MU * N_LOAD, T_tab, u_tab)    # exact inverse of the table
    u = a * np.cos(2.0 * np.pi * np.arange(SAMPLES) / SAMPLES)
    t0 = time.perf_counter()
    loop = el.periodic(u)
    return u, loop.F, loop.W_cycle, time.perf_counter() - t0


def study(ms, xs):
    rows = []
    for m in ms:
        u_tab, T_tab = sphere_table(m)
        el = IwanElement.from_curve(u_tab, T_tab, N_ref=N_LOAD)
        for x in xs:
            _, _, W, dt = loop_for_force(el, u_tab, T_tab, x)
            W_md = mindlin_deresiewicz(x)
            rows.append(dict(m=m, x=x, W=W, W_md=W_md, err=W / W_md - 1.0, seconds=dt))
    return rows


def save_plots(out: Path, m: int, xs) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    u_tab, T_tab = sphere_table(m)
    el = IwanElement.from_curve(u_tab, T_tab, N_ref=N_LOAD)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    uv = np.linspace(-U_SLIP, U_SLIP, 401)
    ax.plot(uv * 1e6, el.virgin(uv), "k--", lw=1, label="virgin curve")
    for x in xs:
        u, F, _, _ = loop_for_force(el, u_tab, T_tab, x)
        ax.plot(np.append(u, u[0]) * 1e6, np.append(F, F[0]), lw=1.4, label=f"T*/(mu N) = {x:g}")
    ax.set(xlabel="u [um]", ylabel="F [N]", title=f"Iwan element, {m} segments")
    ax.legend(fontsize=8)
    _save(fig, out / "loops.png")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    xx = np.geomspace(0.01, 0.99, 40)
    ax.loglog(xx, mindlin_deresiewicz(xx), "k-", label="Mindlin-Deresiewicz")
    T = xx * MU * N_LOAD
    ax.loglog(xx, T**3 / (36 * A_HERTZ * MU * N_LOAD * G_STAR), "k:", label="small-x law")
    ax.loglog(xx, [loop_for_force(el, u_tab, T_tab, x)[2] for x in xx], "C1o", ms=3,
              label=f"Iwan element ({m} segments)")
    ax.set(xlabel="T* / (mu N)", ylabel="energy per cycle [J]")
    ax.legend()
    _save(fig, out / "energy.png")


def _save(fig, path: Path) -> None:
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    atomic_write(path, buf.getvalue())


def main(argv=None) -> int:
    from damper.script import out_folder

    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=out_folder, default=Path("out/masing_loops"))
    p.add_argument("--smoke", action="store_true", help="tiny study (for the tests)")
    args = p.parse_args(argv)
    ms = (8, 32) if args.smoke else (16, 64, 255)      # 255 segments: 256 sliders at most
    xs = (0.3, 0.9) if args.smoke else (0.1, 0.3, 0.6, 0.9, 0.99)
    rows = study(ms, xs)
    print(f"{'segments':>8} {'T*/muN':>7} {'W [J]':>12} {'W_MD [J]':>12} {'rel.err':>9} {'time':>9}")
    for r in rows:
        print(f"{r['m']:8d} {r['x']:7.2f} {r['W']:12.5e} {r['W_md']:12.5e} {r['err']:9.1e} "
              f"{r['seconds'] * 1e6:7.1f}us")
    save_plots(args.out, ms[-1], xs)
    print(f"plots: {args.out}/loops.png, {args.out}/energy.png")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
