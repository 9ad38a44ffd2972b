"""``damper upd optimize --contacts surface``: the condensed surface model's peaks walked over CF
(harmonic_balance.bladed_disk.surface_peak) against an independent ``upd frf --contacts surface``
curve at the lowest load, and the options that do not apply to surfaces refused.

Tiny settings keep it to minutes: H 1, 5 nodes per side (the smallest count a surface
takes), three loads 300 ... 1200 N of UPD-24 (F0 30 N).
"""
import contextlib
import io
import json

import numpy as np
import pytest
from failure_output import no_result

from damper.cache import Store
from damper.cli import main
from damper.upd_surface import build_surfaces
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.load_path import first_point
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf
from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB

NODES, H = 5, 1
CF_RANGE, POINTS = (300.0, 1200.0), 3
#: Half-width of the independent curve's band around the walked peak, relative, and its points:
#: wide enough that the continuation's refinement (solve.PEAK_XTOL) finds the maximum inside it.
BAND, BAND_POINTS = 0.01, 5
#: Both peaks are maxima of the same amplitude over the frequency, located to a relative
#: frequency tolerance (the walk's surface_peak.PEAK_XTOL = 1e-4, the curve's solve.PEAK_XTOL):
#: the amplitude's error is second order in it, (1e-4 / relative half-power width ~1e-2)^2 ~ 1e-4.
PEAK_AMPLITUDE_RTOL = 2e-4
#: The peak frequency is first order in the search's tolerance: twice the walk's 1e-4.
PEAK_FREQUENCY_RTOL = 2e-4


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    out, err = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        mp.setenv("DAMPER_CACHE_DIR", str(tmp_path_factory.mktemp("surface_optimize")))
        code = main(["upd", "optimize", "--contacts", "surface", "--surface-nodes", str(NODES),
                     "--harmonics", str(H), "--cf-range", *map(str, CF_RANGE), "--points", str(POINTS),
                     "--json"])
    assert code == 0, err.getvalue()
    return json.loads(out.getvalue()), err.getvalue()


def _frf_peak(cf: float, f_hz: float):
    """``upd frf --contacts surface --cf cf``'s curve (first point by the path from the open load,
    then the continuation, peak refined) over a narrow band around f_hz: (peak Hz, amplitude)."""
    cfg = load_config(None)
    surfaces = build_surfaces(cfg, NODES, cf, Store().prepare())
    sector = Sector(cfg)

    def make(c):
        return CondensedSurfaceSectorHB(sector, surfaces, H, cf=c)
    omegas = 2 * np.pi * f_hz * np.linspace(1 - BAND, 1 + BAND, BAND_POINTS)
    hb = make(cf)
    x0, _ = first_point(make, omegas[0], cf)
    c = frf(hb, omegas, x0=x0)
    return c.peak_omega / (2 * np.pi), c.peak_amplitude


@pytest.mark.slow
def test_the_last_walked_peak_is_the_frf_peak_at_that_load(cli_run):
    """The smallest load, reached by the walk's warm starts from every larger one, against
    ``upd frf``'s own path from the open load (one curve: each costs ~40 s on a shared core)."""
    out, _ = cli_run
    loads = out["surface_model"]["loads"]
    assert [r["cf"] for r in loads] == pytest.approx(out["cf"][::-1])   # largest first, no refinement
    r = loads[-1]
    f, a = _frf_peak(r["cf"], r["peak_hz"])
    assert r["peak_amplitude_h1"] == pytest.approx(a, rel=PEAK_AMPLITUDE_RTOL)
    assert r["peak_hz"] == pytest.approx(f, rel=PEAK_FREQUENCY_RTOL)


@pytest.mark.slow
def test_optimum_is_the_smallest_walked_peak_and_the_estimate_came_first(cli_run):
    out, err = cli_run
    amp = out["peak_amplitude"]
    assert out["optimum_peak_amplitude"] == min(amp)
    assert out["optimum_cf"] == out["cf"][int(np.argmin(amp))]
    assert out["interior"] == (0 < int(np.argmin(amp)) < POINTS - 1)
    run = out["surface_model"]
    # every evaluation is some load's, but the estimate's one (the first model's, before the walk)
    assert run["nodes_per_side"] == NODES and run["evaluations"] == sum(r["evaluations"] for r in run["loads"]) + 1
    assert "building the faces" in err.splitlines()[0]   # said before the slow set-up
    assert "residual evaluations" in err.splitlines()[1] and "min CPU" in err.splitlines()[1]


@pytest.mark.parametrize("points, H, measured", [(3, 1, 155), (3, 3, 264)])
def test_the_walks_estimated_evaluations_are_within_2x_of_the_measured(points, H, measured):
    """The walks of surface_peak's constants' comment (CF 300 ... 1200 N, 5 nodes per side: the
    minimum at the range's end, so no refinement); the estimate is a rough guide, 2x is its aim."""
    from harmonic_balance.bladed_disk.surface_peak import expected_evaluations

    walk, refine = expected_evaluations(points, H)
    assert measured / 2 <= walk <= 2 * measured
    assert refine > 0


@pytest.mark.parametrize("extra, words", [
    (["--accuracy", "0.01"], "drop --accuracy"),
    (["--grid", "20"], "drop --grid"),
    (["--workers", "2"], "drop --workers"),
    (["--surface-model", "nodes"], "drop --surface-model nodes"),
    (["--points", "41"], "lower --points"),
    (["--surface-nodes", "3"], "surface nodes per side"),
])
def test_options_that_do_not_apply_to_surfaces_are_one_line_refusals(tmp_path, capsys, monkeypatch, extra, words):
    monkeypatch.setenv("DAMPER_CACHE_DIR", str(tmp_path / "cache"))
    code = main(["upd", "optimize", "--contacts", "surface", "--json", *extra])
    captured = capsys.readouterr()
    assert code == 2 and no_result(captured.out, captured.err, 2)
    assert words in captured.err and len(captured.err.strip().splitlines()) == 1
    assert not (tmp_path / "cache").exists()
