"""Mistuning studies in chunks: the shared linear ring family, --until-ci, the statistics
and the efficiency in the JSON. Linear limits on four blades (milliseconds a sample)."""
import json

import numpy as np
import pytest

from damper.cli import main
from damper.mistuning_stats import quantile_ci, quantile_ci_ranks
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.mistuning import LinearRing, LinearRingFamily, draw_factors
from harmonic_balance.bladed_disk.sector import Sector

SMALL = ["upd", "mistuning", "--blades", "4", "--engine-order", "1", "--points", "21",
         "--damper", "free", "--std", "0.02", "--seed", "11", "--serial", "--json"]
#: The family's stuck ring sums the contact stiffness in another order than ring_linear:
#: round-off of the stiffness (1e-16 relative), amplified by the resonance's sharpness.
STUCK_RTOL = 1e-10


def _run(argv, capsys, code=0):
    assert main(argv) == code
    out = capsys.readouterr()
    return json.loads(out.out) if code == 0 else out.err


@pytest.mark.parametrize("damper", ["free", "stuck"])
def test_family_ring_peaks_equal_the_linear_ring_built_alone(damper):
    sector = Sector(load_config().with_values(disk__blades=6, disk__engine_order=1))
    family = LinearRingFamily(sector, damper)
    om = 2 * np.pi * np.linspace(400.0, 480.0, 31)
    for i in range(3):
        kappa = draw_factors(6, 0.03, 23, i)
        alone, shared = LinearRing(sector, kappa, damper).peaks(om), family.ring(kappa).peaks(om)
        tol = 0.0 if damper == "free" else STUCK_RTOL   # free: the same sums, bit for bit
        np.testing.assert_allclose(shared[0], alone[0], rtol=tol, atol=0)
        np.testing.assert_allclose(shared[1], alone[1], rtol=tol, atol=0)


def test_until_ci_stops_at_the_first_chunk_whose_interval_is_narrow_enough(tmp_path, capsys):
    """A wide target: the study stops at the first chunk boundary where the 0.95 quantile
    has a two-sided interval at all (n >= 72: chunks of 20, so 80 samples)."""
    from damper.mistuning import CHUNK_UNTIL_CI

    out = _run(SMALL + ["--samples", "200", "--until-ci", "1.0", "--cache-dir", str(tmp_path)], capsys)
    n_first = next(n for n in range(1, 200) if quantile_ci_ranks(n, 0.95)[1] is not None)
    expect = -(-n_first // CHUNK_UNTIL_CI) * CHUNK_UNTIL_CI
    u = out["until_ci"]
    assert u["reached"] and u["samples_used"] == expect == len(out["samples"])
    amp = [s["amplification"] for s in out["samples"]]
    q95 = next(q for q in out["statistics"]["quantiles"] if q["q"] == 0.95)
    assert q95 == quantile_ci(amp, 0.95)
    assert u["half_width"] == q95["half_width"] <= 1.0


def test_until_ci_not_reached_reports_the_samples_run(tmp_path, capsys):
    out = _run(SMALL + ["--samples", "40", "--until-ci", "1e-9", "--cache-dir", str(tmp_path)], capsys)
    assert not out["until_ci"]["reached"] and out["until_ci"]["samples_used"] == 40
    assert out["until_ci"]["half_width"] is None        # 40 samples cannot bound the 0.95 quantile


def test_smoke_40_samples_statistics_fit_and_efficiency(tmp_path, capsys):
    out = _run(SMALL + ["--samples", "40", "--cache-dir", str(tmp_path)], capsys)
    amp = np.array([s["amplification"] for s in out["samples"]])
    st = out["statistics"]
    assert st["n"] == 40 and st["mean"]["value"] == pytest.approx(amp.mean(), rel=1e-14)
    assert st["mean"]["low"] < amp.mean() < st["mean"]["high"]
    for q in st["quantiles"]:
        assert q["value"] == pytest.approx(np.quantile(amp, q["q"]), rel=1e-14)
    assert st["fit"]["best"] in st["fit"]["fits"]
    e = out["efficiency"]
    assert e["workers"] == 1 and e["chunks"] >= 1 and 0 < e["cpu_s"]
    assert e["efficiency"] == pytest.approx(e["cpu_s"] / e["wall_s"], rel=1e-12)
    # the same study again: every sample from the cache, in the same order
    again = _run(SMALL + ["--samples", "40", "--cache-dir", str(tmp_path)], capsys)
    assert again["cached"] == 40 and [s["amplification"] for s in again["samples"]] == amp.tolist()


def test_printed_summary_has_intervals_fit_and_efficiency(tmp_path, capsys):
    argv = [a for a in SMALL if a != "--json"] + ["--samples", "12", "--cache-dir", str(tmp_path)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "mean" in text and "quantile 0.95" in text and "fit " in text
    assert "parallel efficiency" in text


def test_scene_until_ci_stops_the_same_as_the_command(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('want = ["mistuning"]\n[mistuning]\nblades = 4\nengine_order = 1\nsamples = 200\n'
                     'damper = "free"\npoints = 21\nstd = 0.02\nseed = 11\nuntil_ci = 1.0\n')
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--cache-dir", str(tmp_path / "c")]) == 0
    res = json.loads((tmp_path / "out" / "mistuning" / "result.json").read_text())
    data = res.get("data", res)
    capsys.readouterr()
    cli = _run(SMALL + ["--samples", "200", "--until-ci", "1.0", "--cache-dir", str(tmp_path / "c")], capsys)
    assert data["until_ci"] == cli["until_ci"] and cli["cached"] == len(cli["samples"])


def test_store_put_without_eviction_then_evict_trims_to_the_limit_oldest_first(tmp_path):
    """A chunk stores its samples with ``evict=False`` and evicts once at its end."""
    import os
    import time

    from damper.cache import Store

    store = Store(tmp_path / "c", max_bytes=10**9)
    paths = [store.put(f"k{i}", {"a": np.zeros(2000)}, {}, evict=False) for i in range(3)]
    for i, p in enumerate(paths):        # distinct use times: k0 the least recently used
        os.utime(p, (time.time() - 100 + i, time.time() - 100 + i))
    size = paths[0].stat().st_size
    store.max_bytes = 2 * size + size // 2
    store.evict()
    assert [p.exists() for p in paths] == [False, True, True]


def test_friction_sample_in_a_chunk_equals_the_sample_alone(tmp_path):
    """The chunk's tuned sector (the starts of every ring solve) carries nothing from one
    sample to the next: the second sample of a chunk equals the same sample run alone."""
    from dataclasses import asdict

    from damper.mistuning import Study, fingerprint, run_chunk, run_sample, sample_key, tuned_reference

    study = Study(blades=4, engine_order=1, harmonics=3, points=11, std=0.02, seed=5, samples=2)
    cfg = study.load()
    ref = tuned_reference(study, cfg)
    fp = fingerprint(cfg)
    common = {"study": asdict(study), "band_hz": ref["band_hz"], "tuned_frequency_hz": ref["tuned_frequency_hz"],
              "max_bytes": 2**30}
    items = [{"index": i, "kappa": k.tolist(), "key": sample_key(study, fp, ref["band_hz"], k)}
             for i, k in enumerate(study.patterns(4))]
    chunk = run_chunk(common | {"folder": str(tmp_path / "a"), "items": items})["results"]
    alone = run_sample(common | {"folder": str(tmp_path / "b")} | items[1])
    assert chunk[1]["error"] is None and not chunk[1]["cached"]
    assert chunk[1]["peak_per_blade"] == alone["peak_per_blade"]
    assert chunk[1]["peak_frequency_per_blade_hz"] == alone["peak_frequency_per_blade_hz"]
