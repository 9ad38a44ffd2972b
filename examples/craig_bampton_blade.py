"""Bring your own blade: a scikit-fem FE blade, Craig-Bampton reduced, with the UPD-24 damper.
===========================================================================================

Run:  .venv/bin/python examples/craig_bampton_blade.py [--out out/cb_blade] [--modes 6]
then: damper upd frf --config out/cb_blade/upd.toml

The blade (2D plane stress, thickness 20 mm, steel E = 200 GPa, nu = 0.3,
rho = 7850 kg/m^3; x tangential towards blade j+1, y radial outward): a shank 4 mm wide
from y = -15 mm (root, clamped to a rigid disk) to the platform block 30 x 6 mm
(y = 0 .. 6 mm) and a beam-like airfoil 4 mm wide and 72 mm long on top. First
bending mode 391 Hz (UPD-24: 426 Hz); the flexible shank lets the platform move with
the airfoil, so the damper matters (stuck: 516 Hz). 9-node quadrilaterals (ElementQuad2).

Craig-Bampton: boundary DOFs (kept physical) are the two platform contact points,
the underside corners (+15, 0) mm (touched by damper j: role ``left``) and (-15, 0) mm
(touched by damper j-1's flat: role ``right``), u and v each, and the tangential u of
the airfoil tip (the EO force and the response); plus ``--modes`` fixed-interface modes.
The blade sits on a rigid disk (no K_next); damping C = beta K of the config.
Load: F0 = 10 N at the tip (:data:`F0`), the default CF = 120 N.

Harmonics: H = 3 by default. At H = 5 a Newton sweep on a fixed frequency grid stops
near 530 Hz, most likely at a 5:1 superharmonic resonance of the blade's second bending
family (free 2.09 kHz, stuck 2.81 kHz); above CF/F0 ~ 20 the curve folds (docs, user
guide: the bladed disk): ``solve.frf`` traces both by arc-length continuation.
Prints the CB natural frequencies against the full FE model's, writes ``blade.npz``
and ``upd.toml`` (the default damper, band around the free and stuck EO resonances)
and runs the damped forced response with the Python API.
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from harmonic_balance.bladed_disk.blade import (  # noqa: E402
    craig_bampton,
    generalized_eigenfrequencies,
    make_blade,
    write_npz,
)

MM = 1e-3
#: Steel, plane stress with an out-of-plane thickness [Pa, -, kg/m^3, m].
E, NU, RHO, THICKNESS = 2.0e11, 0.3, 7850.0, 0.02
#: Geometry [m]: shank half width and depth, platform half width and height, airfoil
#: half width and length.
SHANK, DEPTH = 2 * MM, 15 * MM
PLATFORM, PLATFORM_H = 15 * MM, 6 * MM
AIRFOIL, LENGTH = 2 * MM, 72 * MM
#: EO force amplitude at the airfoil tip [N] (UPD-24's 30 N acts on a modal DOF of
#: 0.06 kg; the tip's modal mass here is smaller).
F0 = 10.0


def fe_blade(along: int = 27) -> dict:
    """Assemble the FE blade; ``along`` elements over the airfoil's length.

    Returns
    -------
    dict: M, K (N, N) sparse [kg, N/m] with the root clamped (its DOFs removed),
    named (u, v) DOF indices ``left``, ``right`` of the platform points and ``tip``,
    mesh and basis.
    """
    from skfem import Basis, BilinearForm, ElementQuad2, ElementVector, MeshQuad, asm
    from skfem.helpers import dot
    from skfem.models.elasticity import linear_elasticity

    xs = np.unique(np.round(np.r_[np.linspace(-PLATFORM, -AIRFOIL, 7), -SHANK, 0.0, SHANK,
                                  np.linspace(AIRFOIL, PLATFORM, 7)], 12))
    ys = np.unique(np.round(np.r_[np.linspace(-DEPTH, 0.0, 5), np.linspace(0.0, PLATFORM_H, 4),
                                  np.linspace(PLATFORM_H, PLATFORM_H + LENGTH, along + 1)], 12))
    mesh = MeshQuad.init_tensor(xs, ys)
    cx, cy = mesh.p[:, mesh.t].mean(axis=1)
    keep = (((cy < 0) & (np.abs(cx) < SHANK)) | ((cy > 0) & (cy < PLATFORM_H))
            | ((cy > PLATFORM_H) & (np.abs(cx) < AIRFOIL)))
    mesh = mesh.remove_elements(np.flatnonzero(~keep))
    basis = Basis(mesh, ElementVector(ElementQuad2()))
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    lam_ps = 2 * lam * mu / (lam + 2 * mu)  # plane stress

    @BilinearForm
    def mass(u, v, w):
        return RHO * dot(u, v)

    K = THICKNESS * asm(linear_elasticity(lam_ps, mu), basis)
    M = THICKNESS * asm(mass, basis)
    root = basis.get_dofs(lambda x: np.isclose(x[1], -DEPTH)).all()
    free = np.setdiff1d(np.arange(K.shape[0]), root)
    new = -np.ones(K.shape[0], dtype=int)
    new[free] = np.arange(free.size)

    def node_dofs(x, y):
        i = int(np.argmin(np.hypot(mesh.p[0] - x, mesh.p[1] - y)))
        return tuple(int(new[d]) for d in basis.nodal_dofs[:, i])

    return {"M": M[free][:, free].tocsc(), "K": K[free][:, free].tocsc(),
            "left": node_dofs(PLATFORM, 0.0), "right": node_dofs(-PLATFORM, 0.0),
            "tip": node_dofs(0.0, PLATFORM_H + LENGTH), "mesh": mesh, "basis": basis}


def fe_frequencies(fe: dict, count: int) -> np.ndarray:
    """Lowest ``count`` natural frequencies [Hz] of the full FE blade (root clamped)."""
    import scipy.sparse.linalg as spla

    w2 = spla.eigsh(fe["K"], count, fe["M"], sigma=0.0, which="LM", return_eigenvectors=False)
    return np.sqrt(np.sort(w2)) / (2 * np.pi)


def reduce_blade(fe: dict, modes: int):
    """Craig-Bampton blade (:class:`~harmonic_balance.bladed_disk.blade.Blade`) and T."""
    boundary = [*fe["left"], *fe["right"], fe["tip"][0]]
    M, K, T = craig_bampton(fe["M"], fe["K"], boundary, modes)
    names = ["left_u", "left_v", "right_u", "right_v", "tip_u"] + [f"eta{i + 1}" for i in range(modes)]
    blade = make_blade({"M": M, "K": K, "dofs": names, "left": ["left_u", "left_v"],
                        "right": ["right_u", "right_v"], "forced": "tip_u"}, "craig-bampton")
    return blade, T


def write_case(out: Path, blade, band_hz) -> Path:
    """Write ``blade.npz`` and ``upd.toml`` (default damper, this blade, ``band_hz``)."""
    out.mkdir(parents=True, exist_ok=True)
    write_npz(blade, out / "blade.npz")
    toml = out / "upd.toml"
    toml.write_text("# Craig-Bampton blade (examples/craig_bampton_blade.py) with the UPD-24 damper\n"
                    "[blade]\nfile = \"blade.npz\"\n\n"
                    f"[load]\nf0 = {F0}\nband_hz = [{band_hz[0]:.1f}, {band_hz[1]:.1f}]\n")
    return toml


def linear_band(config_path) -> tuple[float, float, float, float]:
    """Free and stuck EO natural frequencies [Hz] of the case and a band around both."""
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.sector import Sector, natural_frequencies

    sector = Sector(load_config(config_path))
    eo = sector.cfg.engine_order
    f_free = natural_frequencies(sector, eo, "free")[0]
    f_stuck = natural_frequencies(sector, eo, "stuck")[0]
    return f_free, f_stuck, 0.93 * f_free, 1.05 * f_stuck


def run(out: Path, modes: int = 6, harmonics: int = 3, points: int = 100, count: int = 4) -> dict:
    """The whole example; returns the numbers it prints."""
    from harmonic_balance.bladed_disk.config import load_config
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.solve import frf

    t0 = time.perf_counter()
    fe = fe_blade()
    f_fe = fe_frequencies(fe, count)
    blade, _ = reduce_blade(fe, modes)
    f_cb = generalized_eigenfrequencies(blade.M, blade.K, count)
    t_red = time.perf_counter() - t0
    toml = write_case(out, blade, (1.0, 2.0))  # band set below from the linear limits
    f_free, f_stuck, lo, hi = linear_band(toml)
    toml = write_case(out, blade, (lo, hi))
    sector = Sector(load_config(toml))
    curve = frf(SectorHB(sector, harmonics), 2 * np.pi * np.linspace(lo, hi, points))
    return {"fe_dofs": int(fe["K"].shape[0]), "cb_dofs": blade.n, "fe_hz": f_fe.tolist(),
            "cb_hz": f_cb.tolist(), "cb_rel_error": (f_cb / f_fe - 1).tolist(),
            "reduction_time_s": t_red, "free_hz": f_free, "stuck_hz": f_stuck,
            "peak_frequency_hz": curve.peak_omega / (2 * np.pi), "peak_amplitude": curve.peak_amplitude,
            "frf_time_s": curve.time_s, "config": str(toml)}


def main(argv=None) -> int:
    from damper.script import count

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="out/cb_blade", help="directory of blade.npz and upd.toml")
    ap.add_argument("--modes", type=int, default=6, help="fixed-interface modes kept")
    ap.add_argument("--harmonics", type=int, default=3, help="highest harmonic (module docstring)")
    ap.add_argument("--points", type=count(3), default=100, help="frequency points")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    res = run(Path(args.out), args.modes, args.harmonics, args.points)
    if args.json:
        print(json.dumps(res))
        return 0
    print(f"FE blade {res['fe_dofs']} DOFs -> Craig-Bampton {res['cb_dofs']} DOFs "
          f"({res['reduction_time_s']:.2f} s)")
    print(" mode   FE [Hz]    CB [Hz]   rel. error")
    for i, (a, b) in enumerate(zip(res["fe_hz"], res["cb_hz"])):
        print(f"  {i + 1:2d}  {a:9.2f}  {b:9.2f}  {b / a - 1:10.2e}")
    print(f"EO resonance: free {res['free_hz']:.2f} Hz, stuck {res['stuck_hz']:.2f} Hz; with the "
          f"damper: peak {res['peak_frequency_hz']:.2f} Hz, {res['peak_amplitude']:.4e} m "
          f"({res['frf_time_s']:.2f} s)")
    print(f"next: damper upd frf --config {res['config']} --harmonics 3")
    return 0


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
