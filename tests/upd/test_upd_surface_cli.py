"""``damper upd frf --contacts surface --surface-model``: the condensed surface model from the
command line, its first point by the path in CF (harmonic_balance.bladed_disk.load_path).

5 nodes per side and H 1 keep each evaluation near 1 s (the nodes are marched in time in
every one); the CLI's curve runs once per module over 3 frequencies at UPD-24's default
CF 120 N, where Newton from the stuck start does not converge and the path is needed.
"""
import json

import numpy as np
import pytest
from failure_output import no_result

from damper.cache import Store
from damper.cli import main
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk import load_path
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import TOL_REL, solve_point
from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB

NODES, H, CF = 5, 1, 120.0
BAND = (400.0, 405.0)
#: (P1)'s two sides both scale with the CF: the open load computed at two CFs agrees to
#: the round-off of the statics and the stuck solve.
OPEN_LOAD_RTOL = 1e-9
#: The CLI's first point is a Newton solution (|R| < solve.TOL_REL CF = 1.2e-8 N against a
#: stiffness of ~1e5 N/m or more on a response of ~2e-4 m: ~1e-9 relative): two solutions of
#: the same equations from different paths agree to that. Measured 1.6e-15.
FIRST_POINT_RTOL = 1e-8
#: The other grid values are the continuation's cubic Hermite interpolation on its branch
#: (solve.UPD_TOL: measured within 1.4e-4 of Newton solves on UPD-24's point model, H 7;
#: here 5e-9 at the middle point, the last is the branch's end, a Newton solution).
GRID_RTOL = 1e-3
#: Energy balance at the reported peak: exact at a Galerkin solution up to Newton's
#: tolerance (as test_upd_cli.ENERGY_IMBALANCE). Measured 1.1e-16.
ENERGY_IMBALANCE = TOL_REL


@pytest.fixture(scope="module")
def surfaces(tmp_path_factory):
    return build_surfaces(load_config(None), NODES, store=Store(tmp_path_factory.mktemp("surface_cli_cache")))


def _model(surfaces, cf):
    return CondensedSurfaceSectorHB(Sector(load_config(None)), surfaces, H, cf=cf)


def test_open_load_does_not_depend_on_the_cf_it_is_computed_at(surfaces):
    omega = 2 * np.pi * BAND[0]
    at_cf = load_path.open_load(_model(surfaces, CF), omega)
    at_double = load_path.open_load(_model(surfaces, 2 * CF), omega)
    assert at_cf == pytest.approx(at_double, rel=OPEN_LOAD_RTOL)
    assert at_cf > CF   # UPD-24 at CF 120 N: the stuck start opens a face, so the path is needed


#: The faces' prestress resultants carry the damper's force balance (N_L = N_R = CF / (2 cos g),
#: as test_upd_surface.STATIC_RTOL for the node-DOF sector): round-off of the linear statics.
STATIC_RTOL = 1e-8


def test_condensed_faces_prestress_carries_the_damper_force_balance(surfaces):
    from damper.upd_surface import static_loads

    hb = _model(surfaces, CF)
    N = CF / (2 * np.cos(np.radians(hb.sector.cfg["damper.angle_deg"])))
    assert static_loads(hb) == pytest.approx([N, N], rel=STATIC_RTOL)


@pytest.mark.parametrize("extra, words", [
    (["--surface-model", "nodes"], "--surface-model goes with --contacts surface"),
    (["--contacts", "geometry", "--surface-model", "condensed"], "add --contacts surface or drop --surface-model"),
])
def test_surface_model_without_surface_contacts_is_refused(tmp_path, capsys, monkeypatch, extra, words):
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cache"))
    code = main(["upd", "frf", "--json", *extra])
    captured = capsys.readouterr()
    assert code == 2 and no_result(captured.out, captured.err, 2)
    assert words in captured.err and len(captured.err.strip().splitlines()) == 1
    assert not (tmp_path / "cache").exists()


def test_a_path_that_cannot_converge_exits_3_with_what_to_change_and_writes_nothing(tmp_path, capsys, monkeypatch):
    """One Newton iteration per load cannot solve the path's stuck start: a SolverError."""
    monkeypatch.setattr(load_path, "MAX_ITER", 1)
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cache"))
    plots = tmp_path / "plots"
    code = main(["upd", "frf", "--contacts", "surface", "--harmonics", str(H), "--band", *map(str, BAND),
                 "--points", "3", "--json", "--plot", str(plots)])
    captured = capsys.readouterr()
    assert code == 3 and no_result(captured.out, captured.err, 3)
    line = captured.err.strip().splitlines()[-1]
    assert "path in CF" in line and "raise the CF" in line and "Traceback" not in captured.err
    assert not plots.exists()


@pytest.fixture(scope="module")
def cli_curve(tmp_path_factory):
    import contextlib
    import io

    out = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out):
        mp.setenv("DAMPER_CACHE_DIR", str(tmp_path_factory.mktemp("surface_cli_run")))
        code = main(["upd", "frf", "--contacts", "surface", "--surface-nodes", str(NODES), "--harmonics", str(H),
                     "--band", *map(str, BAND), "--points", "3", "--json"])
    assert code == 0
    return json.loads(out.getvalue())


@pytest.mark.slow
def test_cli_curve_is_the_library_path_and_newton_at_its_frequencies(cli_curve, surfaces):
    """The CLI (path from the open load in steps of ratio <= 2, then the continuation) against
    an independent solve: the path from a fixed 300 N in 3 steps at the first frequency, then
    Newton warm-started at each next one."""
    run = cli_curve["surface_model"]
    assert run["model"] == "condensed" and run["nodes_per_side"] == NODES and run["evaluations"] > 0
    assert run["start"]["loads"][-1] == CF and run["start"]["loads"][0] > CF   # the path ran
    e = cli_curve["energy_per_cycle_at_peak"]
    # the faces' input dashpots dissipate (beta_c times their stuck stiffness), their nodes' loops too
    assert abs(e["imbalance"]) < ENERGY_IMBALANCE and e["W_dashpot"] > 0.0 and e["W_friction_loops"] >= 0.0
    assert cli_curve["contact_points"] == ["left", "flat"] and all(0.0 <= v <= 1.0 for v in cli_curve["lift_off"])
    omegas = 2 * np.pi * np.asarray(cli_curve["frequency_hz"])
    x, loads = load_path.cf_path(lambda c: _model(surfaces, c), omegas[0], CF, 300.0, steps=3)
    hb = _model(surfaces, CF)
    amps = [hb.amplitude_h1(x)]
    for w in omegas[1:]:
        x = solve_point(hb, w, x, max_iter=40)
        amps.append(hb.amplitude_h1(x))
    assert cli_curve["amplitude"][0] == pytest.approx(amps[0], rel=FIRST_POINT_RTOL)
    assert cli_curve["amplitude"][1:] == pytest.approx(amps[1:], rel=GRID_RTOL)
