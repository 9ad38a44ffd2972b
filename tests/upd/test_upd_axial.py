"""Bring your own blade with an axial platform DOF: the damper's contacts slip along and
across (ContactElement with two tangents, the C core's 2D element). Without axial motion
the sector is UPD-24's; with it, the cyclic sector solution satisfies the ring's equations
and the contacts slip axially."""
import json

import numpy as np
import pytest

from harmonic_balance.bladed_disk.blade import blade_arrays
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.ring import RingHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import start_point, sweep
from harmonic_balance.bladed_disk.timeint import march_ring

#: HB solutions of the same equations: Newton guarantees |R| < solve.TOL_REL max(F0, CF)
#: = 1e-10; measured 1.3e-15 relative (revision a12e5f1: quadratic convergence overshoots
#: the stopping test).
SAME_RTOL = 1e-10
#: Axial platform mode: mass [kg] and stiffness [N/m] (a few hundred Hz, as the in-plane).
M_W, K_W = 0.1, 8e5


@pytest.fixture(scope="module")
def builtin():
    return Sector(load_config())


def axial_config(tmp_path, builtin, forced="u_a"):
    """UPD-24 plus an axial platform DOF w_p (its own spring to ground), roles [u, v, w]."""
    arr = blade_arrays(builtin.blade)
    n = arr["M"].shape[0]
    grow = lambda A, d: np.pad(A, ((0, 1), (0, 1)), constant_values=0.0) + np.diag([0.0] * n + [d])  # noqa: E731
    arr.update(M=grow(arr["M"], M_W), K=grow(arr["K"], K_W), K_next=grow(arr["K_next"], 0.0),
               dofs=np.append(arr["dofs"], "w_p"), left=np.array(["u_p", "v_p", "w_p"]),
               right=np.array(["u_p", "v_p", "w_p"]), forced=np.array(forced))
    np.savez(tmp_path / "axial.npz", **arr)
    path = tmp_path / "upd.toml"
    path.write_text("[blade]\n" + f"file = {json.dumps('axial.npz')}\n")
    return load_config(str(path))


def test_without_axial_motion_the_sector_is_upd24(tmp_path, builtin):
    sector = Sector(axial_config(tmp_path, builtin))
    assert sector.rows_per_point == 3 and sector.Q.shape[0] == 3 * sector.n_contacts
    band = 2 * np.pi * np.linspace(430, 460, 6)
    hb = SectorHB(sector, 3)
    assert all(el.m == 3 for el in hb.points)
    # Newton solutions at the grid points (frf's grid values are interpolated on each
    # model's own branch: equal only to the interpolation's accuracy)
    ref = SectorHB(builtin, 3)
    a = [hb.amplitude_h1(x) for x in sweep(hb, band)]
    b = [ref.amplitude_h1(x) for x in sweep(ref, band)]
    assert a == pytest.approx(b, rel=SAME_RTOL)


def test_axial_forcing_slips_across_and_the_sector_is_the_ring(tmp_path, builtin):
    sector = Sector(axial_config(tmp_path, builtin, forced="w_p"))
    hb, ring = SectorHB(sector, 3, cf=60.0), RingHB(sector, 3, cf=60.0)
    w = 2 * np.pi * 440.0
    hb.set_f0(40.0)
    ring.set_f0(40.0)
    x = start_point(hb, w)
    assert np.linalg.norm(hb(x, w, False)) < 1e-9 * np.linalg.norm(hb.Fext)
    res = hb.residual.evaluate(x, w, jac=False)
    loops = [res[i] for i in hb.contacts]
    assert any(np.ptp(lp.q[:, 1]) > 1e-3 * np.ptp(lp.q[:, 0]) and lp.W > 0 for lp in loops)
    xr = ring.from_sector(x)
    assert np.linalg.norm(ring(xr, w, False)) < 1e-9 * np.linalg.norm(ring.Fext)


def test_ring_time_integration_refuses_two_slip_directions(tmp_path, builtin):
    sector = Sector(axial_config(tmp_path, builtin))
    with pytest.raises(ValueError, match="two slip directions"):
        march_ring(sector, [2 * np.pi * 450.0], max_periods=1)
