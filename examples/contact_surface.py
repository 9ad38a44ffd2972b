"""Contact surface: the condensed faces as 3D contact points against the contact core.
===================================================================================

The contact surface of the harmonic balance (``harmonic_balance.surface``: one 3D
contact point per node pair of the condensed FE faces, penalty normal with lift-off,
2D Coulomb friction, the bodies' Guyan-condensed flexibility between the nodes) under a
constant normal force and a cyclic tangential displacement, against the contact core's
direct cyclic stick/slip solve on the same bodies, mesh and mu
(``contact_core.tangential_curve.hysteresis_loop``), and the flat face's pressure
under an eccentric normal load against ``contact_core.normal.solve_force`` (thesis
section 3.3.1, cases e0, e2, e6). Prints a table (case, nodes, errors of k_t, energy
per cycle, force amplitude and pressure, seconds) and saves ``loops.png``. ::

    python examples/contact_surface.py            # cylinder grid 21, flat grid 13
    python examples/contact_surface.py --quick    # grids 15 and 9 (the tests' sizes)
"""
from __future__ import annotations

import argparse
import io
import sys
import time
from pathlib import Path

import numpy as np

from contact_core import normal
from contact_core import tangential_curve as tc
from contact_core.condense import condense
from contact_core.fileio import atomic_write
from contact_core.spec import ContactSpec
from contact_core.tangential import TangentialProblem
from damper.cache import Store
from harmonic_balance import surface as sf
from harmonic_balance import surface_static as ss

MU = 0.5
#: Cylinder of the contact tests (R 2.5 mm, L 1.2 mm) at 100 N; the thesis's flat face
#: (W 1.2 mm x L 5 mm) at 500 N with eccentricities e / (W/2) of cases e0, e2, e6.
CYLINDER = {"body": "cylinder", "radius": 2.5e-3, "length": 1.2e-3, "model": "real"}
FLAT = {"body": "flat", "width": 1.2e-3, "length": 5e-3}
CASES = (("cylinder", CYLINDER, 100.0, 0.0), ("flat e0", FLAT, 500.0, 0.0),
         ("flat e2", FLAT, 500.0, 0.2), ("flat e6", FLAT, 500.0, 0.65))
#: Loop amplitude as a share of the virgin curve's gross-slip displacement.
SHARE = 0.7
#: Load steps per leg of the surface loop.
STEPS = 30


def run_case(spec, force, e, cache):
    """One case: the core's loop and normal state, the surface's; errors and timings."""
    cc = condense(spec, directions=("z", "x", "y"), cache=cache)
    e = e * 0.5 * spec.width if spec.body == "flat" else 0.0
    t0 = time.perf_counter()
    sol = normal.solve_force(cc, force, e if spec.body == "flat" else None)
    core = TangentialProblem(cc, sol.f, MU)
    a = SHARE * core.gross_slip_displacement(core.initial_state())
    path_c, ref = tc.hysteresis_loop(core, a)
    t_core = time.perf_counter() - t0
    t0 = time.perf_counter()
    surface = sf.build(cc, MU)
    state = ss.preload(surface, force, e)
    path_s, got = ss.hysteresis_loop(surface, state, a, steps=STEPS)
    t_surf = time.perf_counter() - t0
    f = surface.normal_forces(state.x)
    p_ref = sol.f / cc.grid.area
    return {"nodes": cc.n, "k_t": ss.stuck_stiffness(surface, state) / core.k_t - 1.0,
            "W": got["W_friction"] / ref["W_friction"] - 1.0,
            "T": got["T_amplitude"] / ref["T_amplitude"] - 1.0,
            "p": float(np.max(np.abs(f / cc.grid.area - p_ref)) / p_ref.max()),
            "same_set": bool(np.array_equal(f > 0, sol.f > 0)),
            "contact": int((sol.f > 0).sum()), "t_core": t_core, "t_surface": t_surf,
            "loops": ((path_c.u, path_c.T), (path_s.u, path_s.T))}


def save_plot(out: Path, rows) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(rows), figsize=(4 * len(rows), 3.6))
    for ax, (name, r) in zip(np.atleast_1d(axes), rows):
        (uc, Tc), (us, Ts) = r["loops"]
        ax.plot(uc * 1e6, Tc, "k-", lw=2.5, alpha=0.35, label="contact core (cyclic solve)")
        ax.plot(us * 1e6, Ts, "C1-", lw=1.0, label="surface (3D points)")
        ax.set(title=name, xlabel="u [um]", ylabel="T [N]")
    np.atleast_1d(axes)[0].legend(fontsize=7)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    atomic_write(out / "loops.png", buf.getvalue())


def main(argv=None) -> int:
    from damper.script import out_folder

    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=out_folder, default=Path("out/contact_surface"))
    p.add_argument("--quick", action="store_true", help="the tests' grids (15 and 9)")
    p.add_argument("--cache-dir", default=None, help="condensation cache (default: the damper cache's "
                   "folder, $DAMPER_CACHE_DIR or .damper_cache)")
    args = p.parse_args(argv)
    # the damper's own store (tagged folder, size limit), as every damper stage uses: a
    # bare contact_core DiskCache in the same default folder would make it a foreign one
    cache = Store(args.cache_dir).prepare()
    grids = {"cylinder": 15, "flat": 9} if args.quick else {"cylinder": 21, "flat": 13}
    rows = []
    print(f"{'case':9} {'nodes':>5} {'contact':>7} {'k_t err':>9} {'W err':>9} {'T err':>9} "
          f"{'p err':>9} {'set':>4} {'core s':>7} {'surf s':>7}")
    for name, geo, force, e in CASES:
        spec = ContactSpec(**geo, grid=grids[geo["body"]])
        r = run_case(spec, force, e, cache)
        rows.append((name, r))
        print(f"{name:9} {r['nodes']:5d} {r['contact']:7d} {r['k_t']:9.1e} {r['W']:9.1e} {r['T']:9.1e} "
              f"{r['p']:9.1e} {'=' if r['same_set'] else 'DIFF':>4} {r['t_core']:7.2f} {r['t_surface']:7.2f}")
    save_plot(args.out, [rows[0], rows[-1]])
    print(f"plot: {args.out}/loops.png")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
