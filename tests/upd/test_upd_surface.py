"""The UPD with contact surfaces (`damper upd frf --contacts surface`, SurfaceSectorHB).

The coarsest surfaces (5 nodes per side) keep the condensation and the HB small; the
store is shared by the module so contact_core condenses once.
"""

import numpy as np
import pytest
from failure_output import no_result

from damper.cache import Store
from damper.cli import main
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import TOL_REL
from harmonic_balance.bladed_disk.surface_hb import SurfaceSectorHB, face_inputs

NODES = 5
#: The surfaces' frictionless statics carry CF like the point model's: the damper's force
#: balance fixes the face loads (N_L = N_R = CF / (2 cos g)) whatever the contact model;
#: the surfaces' static solve is linear per contact set, round-off ~1e-12 of CF.
STATIC_RTOL = 1e-8


@pytest.fixture(scope="module")
def surfaces(tmp_path_factory):
    store = Store(tmp_path_factory.mktemp("upd_surface_cache"))
    return build_surfaces(load_config(None), NODES, store=store)


def _face_loads(hb):
    names = [e.name for e in hb.points]
    N = hb.static["N"]
    return {f: sum(n for n, name in zip(N, names) if name.startswith(f"{f} node")) for f in hb.surfaces}


def test_surface_statics_carry_the_damper_force_balance(surfaces):
    sector = Sector(load_config(None))
    hb = SurfaceSectorHB(sector, surfaces, H=1, cf=120.0)
    N = 120.0 / (2 * np.cos(np.radians(sector.cfg["damper.angle_deg"])))
    loads = _face_loads(hb)
    assert loads["left"] == pytest.approx(N, rel=STATIC_RTOL)
    assert loads["flat"] == pytest.approx(N, rel=STATIC_RTOL)
    # the point model's statics give the same face loads (the balance is geometric)
    points = SectorHB(sector, H=1, cf=120.0).static["N"]
    assert points[0] == pytest.approx(N, rel=STATIC_RTOL)


def test_flat_inputs_are_the_centre_of_its_end_points():
    sector = Sector(load_config(None))
    G, G_next = face_inputs(sector, "flat")
    names = [c.name for c in sector.points]
    r1, r2 = names.index("right1"), names.index("right2")
    n = sector.n_dof
    # the end points' penetrations differ by theta_d times the face width
    width = sector.cfg["damper.right_width"]
    diff = sector.Q[2 * r2] - sector.Q[2 * r1]
    assert diff[n - 1] == pytest.approx(width, rel=1e-12)
    assert np.allclose(G[0], 0.5 * (sector.Q[2 * r1, :n] + sector.Q[2 * r2, :n]))
    assert G[1, n - 1] == 1.0 and np.count_nonzero(G[1]) == 1


@pytest.mark.slow
def test_surface_sector_solves_one_frequency_with_its_energy_balanced(surfaces):
    """Newton from the stuck start at 440 Hz (CF 300 N, H 3; measured 17 iterations): the
    excitation's work equals the structure's, the bodies' dashpots' and the friction's."""
    from harmonic_balance.bladed_disk.solve import energy_balance, solve_point

    hb = SurfaceSectorHB(Sector(load_config(None)), surfaces, H=3, cf=300.0)
    omega = 2 * np.pi * 440.0
    x = solve_point(hb, omega, hb.stuck_guess(omega), max_iter=80)
    e = energy_balance(hb, x, omega)
    assert e["W_friction"] > 0.0 and abs(e["imbalance"]) < TOL_REL
    assert hb.amplitude_h1(x) > 0.0


def test_unknowns_counted_before_condensing_are_the_surface_sectors(surfaces):
    """The size check counts the faces' nodes on their meshes, before any condensation: the
    count must be the unknowns of the model it guards."""
    from damper import limits
    from damper.upd_surface import check_unknowns

    sector, H = Sector(load_config(None)), 3
    n = SurfaceSectorHB(sector, surfaces, H=H, cf=120.0).stuck_guess(2 * np.pi * 440.0).size
    assert n == (sector.n_dof + sum(s.n_w for s in surfaces.values())) * (2 * H + 1)
    H_max = (limits.MAX_SURFACE_UNKNOWNS // (n // (2 * H + 1)) - 1) // 2
    check_unknowns(sector, NODES, H_max, None)
    with pytest.raises(ValueError, match=f"{n // (2 * H + 1) * (2 * H_max + 3)} unknowns"):
        check_unknowns(sector, NODES, H_max + 1, None)


@pytest.mark.parametrize("extra, words", [
    (["--surface-nodes", "3"], "surface nodes per side"),
    (["--surface-model", "nodes", "--surface-nodes", "41", "--harmonics", "1"], "lower --surface-nodes or --harmonics"),
    (["--surface-model", "nodes", "--harmonics", "50"], "or use --surface-model condensed"),
    (["--surface-nodes", "99"], "surface nodes per side"),
    (["--damper", "stuck"], "--damper nonlinear"),
    (["--accuracy", "0.01"], "drop --accuracy"),
    (["--check-steady-state"], "drop it with --contacts surface"),
])
def test_bad_surface_options_are_one_line_refusals(tmp_path, capsys, monkeypatch, extra, words):
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cache"))
    code = main(["upd", "frf", "--contacts", "surface", "--json", *extra])
    captured = capsys.readouterr()
    assert code == 2 and no_result(captured.out, captured.err, 2)
    assert words in captured.err and "Traceback" not in captured.err
    assert len(captured.err.strip().splitlines()) == 1
    assert not (tmp_path / "cache").exists()   # refused before any condensation


#: The node-DOF and the condensed sector at one frequency (5 nodes per side, penalty 100,
#: H 3, CF 300 N, 440 Hz): they differ by the truncation of each node's slip to H
#: harmonics (node-DOF only), the march's 48 samples and the bodies' dashpots (on [w; q]
#: against the condensed stuck stiffness on q; beta_c omega ~ 3e-3). Measured 1.3e-5.
CONDENSED_RTOL = 1e-3
#: Energy balance of the Galerkin solution (exact up to Newton's tolerance, TOL_REL of CF).
ENERGY_IMBALANCE = 1e-6
#: The surfaces' harmonic work (their resultants' first H harmonics against the inputs')
#: against the march's friction work (the loops at 48 samples): quadrature and the
#: resultants' harmonics above H.
MARCH_WORK_RTOL = 0.05


@pytest.mark.slow
def test_condensed_surface_sector_agrees_with_the_node_dof_sector(surfaces):
    """Newton on each formulation from its stuck start: the same first-harmonic amplitude."""
    from harmonic_balance.bladed_disk.solve import energy_balance, solve_point
    from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB
    from harmonic_balance.forces import harmonic_work

    sector, omega = Sector(load_config(None)), 2 * np.pi * 440.0
    full = SurfaceSectorHB(sector, surfaces, H=3, cf=300.0)
    cond = CondensedSurfaceSectorHB(sector, surfaces, H=3, cf=300.0, n_t=48)
    x_full = solve_point(full, omega, full.stuck_guess(omega), max_iter=80)
    x_cond = solve_point(cond, omega, cond.stuck_guess(omega), max_iter=40)
    assert cond.amplitude_h1(x_cond) == pytest.approx(full.amplitude_h1(x_full), rel=CONDENSED_RTOL)
    # energy: the excitation's work is the structure's and the surfaces' (Galerkin, exact at
    # the solution), and the surfaces' harmonic work is their marched friction work
    e = energy_balance(cond, x_cond, omega)
    assert abs(e["imbalance"]) < ENERGY_IMBALANCE
    res = cond.residual
    lfs = res.evaluate(x_cond, omega, jac=False)
    W_harm = W_march = 0.0
    for el, lf in zip(res.elements, lfs):
        if hasattr(el, "march"):
            U = (el.kinematics.operators(cond.basis, res.dofs)[0] @ x_cond).reshape(cond.nb, el.m)
            W_harm += harmonic_work(U, lf.F, cond.basis)
            W_march += lf.W
    assert W_march > 0.0 and W_harm == pytest.approx(W_march, rel=MARCH_WORK_RTOL)


#: Two exact linearisations of the same stuck sector (dense solves of ~500 unknowns and the
#: march's forward sensitivities, whose node solve stops at 1e-7 of the loads but is linear
#: while every node sticks): round-off and that tolerance, far below the 1e-2 that the
#: dashpots' placement makes.
STUCK_LINEAR_RTOL = 1e-6


def _stuck_h1(hb, omega):
    """First harmonic (complex, sector DOFs) of one Newton step from the prestress without
    vibration: the stuck linear response (every node in contact sticks there)."""
    x0 = hb.static_guess()
    R, J, _ = hb.residual(x0, omega, True)
    X = (x0 - np.linalg.solve(J, R)).reshape(hb.nb, hb.ndof)[:, :hb.sector.n_dof]
    ic, isn = hb.basis.index(1)
    return X[ic] - 1j * X[isn]


def test_node_dof_sector_with_input_dashpots_is_the_condensed_sector_when_stuck(surfaces):
    """dashpots="inputs" gives the node-DOF sector the condensed model's damping: their stuck
    linear responses agree near the stuck resonance, where the dashpots set the amplitude
    (with every node stuck the bodies' dashpots give the same: the faces' relative motion
    is then the bodies' deformation; the placements differ where nodes slip)."""
    from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB

    sector = Sector(load_config(None))
    omega = 2 * np.pi * 476.0       # near the stuck sector's resonance
    cond = _stuck_h1(CondensedSurfaceSectorHB(sector, surfaces, H=1, cf=600.0, n_t=16), omega)
    same = _stuck_h1(SurfaceSectorHB(sector, surfaces, H=1, cf=600.0, dashpots="inputs"), omega)
    assert np.abs(same - cond).max() < STUCK_LINEAR_RTOL * np.abs(cond).max()


def test_unknown_dashpot_placement_is_refused(surfaces):
    with pytest.raises(ValueError, match="dashpots must be one of"):
        SurfaceSectorHB(Sector(load_config(None)), surfaces, H=1, cf=600.0, dashpots="nodes")


def test_a_sector_with_axial_platform_dofs_is_refused_before_condensing(tmp_path, capsys, monkeypatch):
    """The surfaces are planar: a blade with an axial platform DOF is refused in one line
    before contact_core condenses anything (nothing in the cache)."""
    from damper.stress import input_fixtures as fx

    for name in ("upd_axial.toml", "axial_blade.npz"):
        (tmp_path / name).write_bytes(fx.upd_files()[name] if isinstance(fx.upd_files()[name], bytes)
                                      else fx.upd_files()[name].encode())
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cache"))
    code = main(["upd", "frf", "--contacts", "surface", "--config", str(tmp_path / "upd_axial.toml"), "--json"])
    captured = capsys.readouterr()
    assert code == 2 and "planar UPD sector" in captured.err and len(captured.err.strip().splitlines()) == 1
    assert not (tmp_path / "cache").exists()


def test_a_face_lift_off_share_counts_only_the_nodes_that_touch():
    """The potential zone holds nodes outside the contact (never touching: open all period);
    a stuck face (touching nodes never open) is 0 open, not their share of the zone."""
    from types import SimpleNamespace

    from damper.upd_surface import face_summary

    names = [f"left node {i}" for i in range(6)]
    summ = {"names": names, "normal_load_mean": [0.0, 10.0, 20.0, 20.0, 10.0, 0.0],
            "normal_load_range": [0.0, 1.0, 1.0, 1.0, 1.0, 0.0], "lift_off": [1.0, 0.0, 0.0, 0.0, 0.5, 1.0],
            "friction_energy": [0.0] * 6}
    hb = SimpleNamespace(surfaces={"left": SimpleNamespace(zone_edge=np.zeros(6, bool))})
    out = face_summary(hb, summ)
    assert out["lift_off"] == [0.5 / 4]          # the four touching nodes: 0, 0, 0, 0.5
    summ["lift_off"] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    assert face_summary(hb, summ)["lift_off"] == [0.0]
