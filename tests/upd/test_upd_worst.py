"""Worst mistuning pattern of the linear ring: the adjoint gradient, the search against
differential evolution and random patterns, Whitehead's bound; the CLI."""
import json

import numpy as np
import pytest
from scipy.optimize import differential_evolution

from damper.cli import main
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.mistuning import tuned_linear_peak, whitehead_bound
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.worst import LinearPeak, worst_pattern

#: Adjoint gradient against central differences (step 1e-6: the differences' truncation
#: and the peak search's 1e-10 frequency tolerance leave ~1e-5).
GRAD_RTOL = 1e-4
#: The required agreement of the search with an independent optimizer.
DE_RTOL = 0.01
BOUND = 0.06   # 3 std at std 0.02


@pytest.fixture(scope="module")
def peak4():
    sector = Sector(load_config().with_values(disk__blades=4, disk__engine_order=1))
    om = 2 * np.pi * np.linspace(390.0, 470.0, 101)
    return sector, om, LinearPeak(sector, "free", om)


def test_peak_gradient_equals_finite_differences(peak4):
    _, _, p = peak4
    k = np.array([1.02, 0.985, 1.0, 0.995])
    _, g = p.value_and_grad(k)
    h = 1e-6
    fd = np.array([(p.peak(k + h * e)[0] - p.peak(k - h * e)[0]) / (2 * h) for e in np.eye(4)])
    assert np.abs(g - fd).max() <= GRAD_RTOL * np.abs(fd).max()


def test_worst_pattern_against_differential_evolution_random_and_whitehead(peak4):
    """Four blades, damper free, factors within 1 +- 0.06: the search's amplification equals
    differential evolution's (no gradients, its own seed) to DE_RTOL, exceeds every one of
    100 uniform random patterns at std 0.02 (all inside the box) and stays below
    Whitehead's bound."""
    sector, om, p = peak4
    a_t = tuned_linear_peak(sector, om, "free")[1]
    r = worst_pattern(p, BOUND, seed=2)
    de = differential_evolution(lambda k: -p.peak(k)[0], [(1 - BOUND, 1 + BOUND)] * 4,
                                seed=20261127, tol=1e-6, popsize=8, polish=True)
    assert r["peak"] == pytest.approx(-de.fun, rel=DE_RTOL)
    rng = np.random.default_rng(20261127)
    random_max = 0.0
    for _ in range(100):
        k = 1 + 0.02 * rng.uniform(-np.sqrt(3), np.sqrt(3), 4)
        # the largest blade peak: blade 0's peak of each rotation of the pattern
        random_max = max(random_max, max(p.peak(np.roll(k, -j))[0] for j in range(4)))
    assert r["peak"] > random_max
    assert r["peak"] / a_t < whitehead_bound(4)


def test_cli_worst_prints_and_writes_the_pattern(tmp_path, capsys):
    out = tmp_path / "worst.json"
    assert main(["upd", "mistuning", "--blades", "4", "--engine-order", "1", "--damper", "free",
                 "--worst", "--std", "0.02", "--json", "--out", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    written = json.loads(out.read_text())
    assert printed["factors"] == written["factors"]
    k = np.array(written["factors"])
    assert np.all(np.abs(k - 1) <= BOUND + 1e-12)
    assert 1.0 < written["amplification"] < written["whitehead_bound"]


@pytest.mark.parametrize("extra, message", [
    (["--worst", "--std", "0.02", "--max-evaluations", "0"], "--max-evaluations must be >= 1"),
    (["--worst", "--damper", "free", "--max-evaluations", "5"], "drop it with --damper free|stuck"),
    (["--max-evaluations", "5"], "go with --worst"),
    (["--worst", "--damper", "free", "--bound", "0.9"], "--bound <= 0.75"),
    (["--bound", "0.1"], "go with --worst"),
])
def test_cli_worst_refusals_exit_2_nothing_written(tmp_path, capsys, extra, message):
    out = tmp_path / "w.json"
    args = ["upd", "mistuning", "--blades", "4", "--engine-order", "1", "--out", str(out)] + extra
    assert main(args) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("out, message", [
    ("/proc/damper_worst.json", "cannot write in /proc"),   # root's permission bits say yes, the write fails
    ("worst/", "is a folder; give a file name"),            # Path() drops the /: a file "worst" was written
])
def test_cli_worst_out_that_cannot_be_written_is_refused_before_the_search(tmp_path, capsys, monkeypatch, out,
                                                                          message):
    import damper.mistuning_worst

    searched = []
    monkeypatch.setattr(damper.mistuning_worst, "run_worst", lambda *a, **kw: searched.append(a) or {})
    monkeypatch.chdir(tmp_path)
    assert main(["upd", "mistuning", "--blades", "4", "--engine-order", "1", "--damper", "free", "--worst",
                 "--out", out]) == 2
    assert message in capsys.readouterr().err and not searched
    assert not list(tmp_path.iterdir())
