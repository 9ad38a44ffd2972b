"""The damper FMU: prestress kept, energy closed, and driven by the platform motion of the
HB periodic solution it returns the HB's contact forces on the platforms."""
import numpy as np
import pytest
from slaves import Slave
from upd_system_loads import CF

from harmonic_balance.bladed_disk import fmus
from harmonic_balance.bladed_disk.hb import SectorHB, neighbour_map
from harmonic_balance.bladed_disk.solve import start_point

FORCES = ("F_left_x", "F_left_y", "F_right_x", "F_right_y")


@pytest.mark.parametrize("version", [2, 3])
def test_prestress_stays(part_fmus, specs, version):
    """At the start inputs (the frictionless prestress) nothing moves: forces = k_n p0 ones."""
    _, d = specs
    s = Slave(part_fmus["damper", version], version)
    s.start_stepping()
    F0 = np.array(s.get(*FORCES))
    for _ in range(200):
        s.step(2e-6)
    F1 = np.array(s.get(*FORCES, "y_d"))
    s.close()
    assert F1[:4] == pytest.approx(F0, abs=1e-9 * CF)
    assert F1[4] == pytest.approx(d.q0[1], rel=1e-12)
    assert F0 == pytest.approx([-60.0, 60.0, 60.0, 60.0], rel=1e-12)  # CF/2 on each face


def _hb_platforms(sector, f):
    """HB (H = 7) at f: platform motions of blade j's left and blade j+1's right point
    (harmonic coefficients (n_b, 2) each) and the contact forces on them (n_b, 2) each."""
    hb = SectorHB(sector, 7, cf=CF)
    w = 2 * np.pi * f
    x = start_point(hb, w)
    X = x.reshape(hb.nb, hb.ndof)
    b = sector.blade
    P = {"left": X[:, list(b.left)], "right": neighbour_map(hb.basis, sector.cfg.phi) @ X[:, list(b.right)]}
    res = hb.residual.evaluate(x, w, jac=False)
    W = sum(hb.contact_summary(x, w)["friction_energy"])
    F = {"left": np.zeros((hb.nb, 2)), "right": np.zeros((hb.nb, 2))}
    for i, k in enumerate(hb.contacts):
        Qs, Qp = fmus._rows(sector, i)
        loc = res[k].F  # local [f_t, N] harmonics with the dashpots
        side = "right" if sector.points[i].neighbour else "left"
        F[side] -= np.outer(loc[:, 0], Qs[3:]) + np.outer(loc[:, 1], Qp[3:])
    return hb.basis, P, F, W


@pytest.mark.slow
def test_driven_by_the_hb_motion_it_returns_the_hb_forces(sector, part_fmus):
    """Platform points moved as in the HB periodic solution at the CF = 120 N peak: the
    FMU's steady force first harmonics equal the HB's (the same laws in the time domain
    against the AFT). Bound 1 % of the largest force harmonic (the HB's truncation at H = 7:
    measured ...)."""
    f = 448.25
    basis, P, F_hb, W_hb = _hb_platforms(sector, f)
    w, n = 2 * np.pi * f, 2400
    s = Slave(part_fmus["damper", 2], 2)
    s.start_stepping()
    h = 1.0 / f / n
    rec = np.empty((n, 4))
    periods = 12
    energies = ("W_platforms", "W_friction", "W_dashpots", "energy")
    for p in range(periods):
        if p == periods - 1:
            e0 = np.array(s.get(*energies))
        for k in range(n):
            th = w * s.t
            vals = {}
            for side in ("left", "right"):
                q = basis.evaluate(P[side], th)
                v = w * basis.evaluate(basis.dtheta @ P[side], th)
                vals |= {f"q_{side}_x": q[0], f"q_{side}_y": q[1], f"v_{side}_x": v[0],
                         f"v_{side}_y": v[1]}
            s.set(**vals)
            s.step(h)
            if p == periods - 1:
                rec[k] = s.get(*FORCES)
    e1 = np.array(s.get(*energies))
    s.close()
    th = w * (((periods - 1) * n + np.arange(1, n + 1)) * h)
    h1_fmu = 2.0 / n * (np.exp(-1j * th) @ rec)
    ic, isn = basis.index(1)
    h1_hb = np.concatenate([F_hb["left"][ic] - 1j * F_hb["left"][isn],
                            F_hb["right"][ic] - 1j * F_hb["right"][isn]])
    scale = np.abs(h1_hb).max()
    d = e1 - e0
    print(np.abs(h1_fmu - h1_hb) / scale, np.abs(h1_hb), d, W_hb)
    assert np.abs(h1_fmu - h1_hb).max() < 0.01 * scale
    # energy over the last period: the platforms' work = friction + dashpots + stored change
    assert d[0] == pytest.approx(d[1] + d[2] + d[3], rel=1e-3)
    assert d[1] == pytest.approx(W_hb, rel=0.01)  # friction energy per cycle against the HB's
