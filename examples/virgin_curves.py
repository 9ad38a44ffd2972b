"""Virgin curves of the thesis's contacts: sphere and cylinder, CNF and CND.
=========================================================================

Prints one line per case (normal force, k_n, k_t, gross-slip displacement,
points, error against Cattaneo-Mindlin for the sphere) and a hysteresis loop
computed directly by the contact model against Masing's loop from its virgin
curve, and the CND cylinder against the thesis's fit (seed eq. 2.14, a
comparison, not an oracle); saves plots and curve files to ``--out``. ::

    python examples/virgin_curves.py                    # half-space BEM, 31 nodes per side
    python examples/virgin_curves.py --model real --grid 21
    python examples/virgin_curves.py --smoke            # tiny grid (the test runs this)
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from contact_core import hertz, tangential_run
from contact_core import tangential_curve as tc
from contact_core import tangential_reference as tr
from contact_core.curve import write_curve
from contact_core.spec import ContactSpec

MU = 0.5
#: The thesis's cases (section 2.3.2): cylinder 1 (D = 5 mm, L = 1.2 mm) at
#: N = 120 N (CNF) and at 5 um approach (CND); a 10 mm sphere at 200 N.
CASES = {
    "sphere CNF": (dict(body="sphere", radius=0.01), dict(force=200.0)),
    "sphere CND": (dict(body="sphere", radius=0.01), dict(approach=4e-6)),
    "cylinder CNF": (dict(body="cylinder", radius=2.5e-3, length=1.2e-3), dict(force=120.0)),
    "cylinder CND": (dict(body="cylinder", radius=2.5e-3, length=1.2e-3), dict(approach=5e-6)),
}


def mindlin_error(run) -> float | None:
    """Largest |T - T_Mindlin| / (mu N) over the curve (sphere only)."""
    ref = run.spec.kind.tangential_reference(run.spec, run.problem.N, MU).get("mindlin")
    if ref is None:
        return None
    N = run.problem.N
    a = ref["contact_radius"]
    T_ref = tr.mindlin_force(run.virgin.u, N, MU, a, ref["k_t"] / (8 * a))
    return float(np.abs(run.virgin.T - T_ref).max() / (MU * N))


def run_cases(model: str, grid: int) -> dict:
    """All CASES; prints a table and returns the runs by name."""
    print(f"{'case':14s} {'N [N]':>9s} {'k_n [N/m]':>11s} {'k_t [N/m]':>11s} {'u_gs [um]':>9s} "
          f"{'points':>6s} {'err/muN':>8s} {'time [s]':>8s}")
    runs = {}
    for name, (geometry, load) in CASES.items():
        spec = ContactSpec(grid=grid, load_hint=load.get("force", 0.0), **geometry)
        t0 = time.perf_counter()
        run = tangential_run.run(spec, MU, model=model, command=" ".join(sys.argv), **load)
        err = mindlin_error(run)
        print(f"{name:14s} {run.problem.N:9.2f} {run.k_n:11.4e} {run.problem.k_t:11.4e} "
              f"{run.virgin.u[-1] * 1e6:9.4f} {len(run.virgin.points):6d} "
              f"{'-' if err is None else f'{err:.2e}':>8s} {time.perf_counter() - t0:8.2f}")
        runs[name] = run
    return runs


def thesis_eq_2_14(T, length: float, diameter: float):
    """Seed eq. 2.14, the thesis's fit of its CND cylinder curves (dz = 5 um):
    delta [um] = 14.337 T^1.010 / L^1.052 * D^0.144, T in N, L and D in um. Returns m."""
    return 14.337 * np.asarray(T) ** 1.010 / (length * 1e6) ** 1.052 * (diameter * 1e6) ** 0.144 * 1e-6


def compare_with_thesis(run) -> None:
    """Our CND cylinder curve against the thesis's fit (a comparison, not an oracle)."""
    limit = run.problem.mu * run.problem.N
    print(f"cylinder CND vs seed eq. 2.14 ({run.model} model):")
    for frac in (0.25, 0.5, 0.75):
        T = frac * limit
        u = float(np.interp(T, run.virgin.T, run.virgin.u))
        u_fit = float(thesis_eq_2_14(T, run.spec.length, 2 * run.spec.radius))
        print(f"  T = {T:7.2f} N: u = {u * 1e6:.3f} um, eq. 2.14 {u_fit * 1e6:.3f} um "
              f"({u / u_fit - 1:+.1%})")


def loop_vs_masing(run, fraction: float = 0.6) -> dict:
    """Direct loop at a = fraction * u_gs against Masing's loop from the virgin curve."""
    a = fraction * run.virgin.u[-1]
    path, energy = tc.hysteresis_loop(run.problem, a)
    W_masing = tr.masing_loop_energy(a, run.curve.u, run.curve.T)
    print(f"loop a = {a * 1e6:.3f} um: W direct {energy['W_friction']:.4e} J, "
          f"Masing {W_masing:.4e} J ({energy['W_friction'] / W_masing - 1:+.2%})")
    return {"path": path, "a": a, "W": energy, "W_masing": W_masing}


def plot(runs: dict, loop: dict, out: Path) -> list:
    """Curves (CNF vs CND, sphere vs Mindlin) and the loop against Masing."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4))
    for name, run in runs.items():
        ax = axes[0] if name.startswith("sphere") else axes[1]
        ax.plot(run.virgin.u * 1e6, run.virgin.T, "o-", ms=3, label=f"{name} (N = {run.problem.N:.0f} N)")
    s = runs["sphere CNF"]
    a = hertz.sphere(s.problem.N, s.spec.radius, s.spec.Estar)["a"]
    Gs = tr.shear_modulus_star(s.spec.E1, s.spec.nu1, s.spec.E2, s.spec.nu2)
    u = np.linspace(0, tr.mindlin_slip_displacement(s.problem.N, MU, a, Gs), 100)
    axes[0].plot(u * 1e6, tr.mindlin_force(u, s.problem.N, MU, a, Gs), "k--", label="Cattaneo-Mindlin")
    path = loop["path"]
    axes[2].plot(path.u * 1e6, path.T, "-", label="contact model (slip history)")
    v = s.curve
    ub = np.linspace(loop["a"], -loop["a"], 100)
    Ta = loop["W"]["T_amplitude"]
    axes[2].plot(ub * 1e6, tr.masing_branch(ub, loop["a"], Ta, v.u, v.T), "k--", label="Masing")
    axes[2].plot(-ub * 1e6, tr.masing_branch(-ub, -loop["a"], -Ta, v.u, v.T), "k--")
    for ax, title in zip(axes, ("sphere", "cylinder D 5 mm, L 1.2 mm", "sphere: loop")):
        ax.set(xlabel="u [um]", ylabel="T [N]", title=title)
        ax.legend(fontsize=8)
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "virgin_curves.png", dpi=120)
    plt.close(fig)
    return [out / "virgin_curves.png"]


def main(argv=None) -> int:
    from damper.script import out_folder

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--model", choices=tangential_run.MODELS, default="bem")
    parser.add_argument("--grid", type=int, default=31)
    parser.add_argument("--out", type=out_folder, default=Path("out/virgin_curves"))
    parser.add_argument("--smoke", action="store_true", help="tiny grid, quick check")
    args = parser.parse_args(argv)
    runs = run_cases(args.model, 9 if args.smoke else args.grid)
    loop = loop_vs_masing(runs["sphere CNF"])
    compare_with_thesis(runs["cylinder CND"])
    for name, run in runs.items():
        write_curve(run.curve, args.out / f"{name.replace(' ', '_')}.json")
    plot(runs, loop, args.out)
    print(f"curves and plots in {args.out}")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
