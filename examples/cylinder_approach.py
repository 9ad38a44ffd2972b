"""Cylinder on a plane: FE approach against the literature formulas (thesis 2.2.2).
================================================================================

The seed lists Norden (two solutions, eqs 2.3-2.4), Palmgren as cited by Harris
(2.5), Brandlein (2.6), Roark (2.7), Johnson (2.8) and Kosarev (2.9). They
disagree by tens of percent and are comparisons, not oracles (references.md).
Units: Palmgren and Brandlein are dimensional fits, delta [mm] from F [N] and
L [mm]; the others are dimensionally consistent and evaluated in SI here.

Prints a table and writes ``cylinder_approach.json`` and a plot like the
thesis's Fig. 10 (normal force against approach) into ``--out``; with
``--table`` also the body-1 (cylinder) share of the approach for the four
cylinders of the thesis's Table I (section 2.2.5)::

    python examples/cylinder_approach.py --out out/cylinder [--table]
"""
from __future__ import annotations

import argparse
import io
import math
import sys
from pathlib import Path

import numpy as np

from contact_core.condense import condense
from contact_core.fileio import atomic_write
from contact_core.spec import ContactSpec

#: Cylinder 1 of the thesis (section 2.1): D = 5 mm, L = 1.2 mm, steel.
D, L, E, NU = 5e-3, 1.2e-3, 200e9, 0.3
FORCES = np.linspace(25.0, 600.0, 12)
#: The zone is sized for 3000 MPa so that one condensed model holds every force.
P_DESIGN = 3000e6
#: Thesis Table I: (D, L) of cylinders 1-4 [m].
TABLE_I = ((5e-3, 1.2e-3), (2.5e-3, 1.2e-3), (5e-3, 2.4e-3), (2.5e-3, 2.4e-3))


def formulas(F, D=D, L=L, E=E, nu=NU) -> dict:
    """Approach [m] of a steel cylinder (diameter D, length L) on a steel plane at force F [N]."""
    F = np.asarray(F, float)
    R = D / 2
    lam = (1 - nu**2) / E                 # lambda_i of one body; lambda_1 + lambda_2 = 2 lam
    lam12 = 2 * lam
    P = F / L                             # load per length [N/m]
    out = {
        "Norden 1": P * lam12 * (1 + np.log(L**3 / (lam12 * F * R))),
        "Norden 2": P * lam12 * (-0.608205 + 1.5 * np.log(L**3 / (lam12 * F * R))),
        "Palmgren/Harris": 3.84e-5 * F**0.9 / (L * 1e3) ** 0.8 * 1e-3,
        "Brandlein": 4.05e-5 * F**0.925 / (L * 1e3) ** 0.85 * 1e-3,
    }
    b_roark = 1.6 * np.sqrt(P * D * lam12)
    out["Roark"] = 2 * P * lam / math.pi * (1 / 3 + np.log(2 * D / b_roark))
    a1 = np.sqrt(4 * F * R / (L * math.pi * E))
    out["Johnson"] = P * lam / math.pi * (2 * np.log(4 * R / a1) - 1)
    lam_k = 2 * lam / math.pi
    b_k = np.sqrt(4 * F * R * lam_k / L)
    out["Kosarev"] = P * lam_k * (0.407 + np.log(2 * R / b_k) + np.log(4 * 7.5**2))
    return out


def fe_curve(D=D, L=L, grid=21, cache=None) -> dict:
    """FE approach and body-1 share over FORCES for the real half-cylinder model."""
    spec = ContactSpec(body="cylinder", radius=D / 2, length=L, grid=grid, p_design=P_DESIGN)
    cc = condense(spec, cache=cache)
    rows = {"force": [], "approach": [], "body1_share": [], "body1_share_far": [], "k_n": []}
    from contact_core import normal, report

    for F in FORCES:
        sol = normal.solve_force(cc, float(F))
        r = report.summarize(cc, sol, "cylinder")
        if r["zone_edge_in_contact"]:
            raise RuntimeError(f"F = {F} N: contact reaches the zone edge")
        for k in rows:
            rows[k].append(float(F) if k == "force" else None if r.get(k) is None else float(r[k]))
    return rows


def plot(fe: dict, lit: dict, path: Path) -> None:
    """Force against approach, FE and formulas (thesis Fig. 10)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    ax.plot(np.asarray(fe["approach"]) * 1e6, fe["force"], "ko-", lw=2, label="FE (this toolkit)")
    for name, d in lit.items():
        ax.plot(np.asarray(d) * 1e6, FORCES, "--", label=name)
    ax.set(xlabel="approach dz [um]", ylabel="normal force [N]",
           title=f"cylinder D = {D * 1e3:g} mm, L = {L * 1e3:g} mm on a plane (steel)")
    ax.legend(fontsize=8)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    plt.close(fig)
    atomic_write(path, buf.getvalue())


def main(out_dir="out/cylinder", table=False, grid=21, cache=None) -> dict:
    """Run the comparison; return {"fe": ..., "formulas": ..., "table_I": ...}."""
    from damper.cli.common import dumps

    out_dir = Path(out_dir)
    fe = fe_curve(grid=grid, cache=cache)
    lit = formulas(FORCES)
    print(f"{'F [N]':>7s} {'FE':>8s} " + " ".join(f"{k[:10]:>10s}" for k in lit) + "   (approach, um)")
    for i, F in enumerate(FORCES):
        print(f"{F:7.1f} {fe['approach'][i] * 1e6:8.3f} "
              + " ".join(f"{lit[k][i] * 1e6:10.3f}" for k in lit))
    result = {"fe": fe, "formulas": {k: v.tolist() for k, v in lit.items()}, "forces": FORCES.tolist()}
    if table:
        result["table_I"] = []
        for Di, Li in TABLE_I:
            rows = fe_curve(Di, Li, grid, cache)
            share = rows["body1_share"]
            far = [v for v in rows["body1_share_far"] if v is not None] or [float("nan")]
            result["table_I"].append({"D": Di, "L": Li, "body1_share": share, "body1_share_far": far})
            print(f"D = {Di * 1e3:g} mm, L = {Li * 1e3:g} mm: cylinder share of the approach "
                  f"{100 * min(share):.0f}-{100 * max(share):.0f} % at the centre, its compression "
                  f"outside the contact (at ~3b) {100 * min(far):.0f}-{100 * max(far):.0f} %")
    atomic_write(out_dir / "cylinder_approach.json", dumps(result, indent=1) + "\n")
    plot(fe, lit, out_dir / "cylinder_approach.png")
    return result


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="out/cylinder")
    ap.add_argument("--table", action="store_true", help="also the four cylinders of Table I")
    ap.add_argument("--grid", type=int, default=21)
    args = ap.parse_args()
    from damper.script import run as run_script

    sys.exit(run_script(lambda: main(args.out, args.table, args.grid)))
