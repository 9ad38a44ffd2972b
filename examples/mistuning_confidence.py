"""Confidence of a mistuning study: does the 0.95 quantile's interval hold?
========================================================================

A study of N samples (``damper.mistuning``, UPD-24, damper free: the linear ring)
gives the amplification's 0.95 quantile with its distribution-free 95 % interval
(``damper.mistuning_stats``, order statistics). An independent study of 4 N samples
(another seed, so other patterns) estimates the same quantile more precisely: the first
study's interval should contain it, in about 93 % of such pairs (less than the interval's
coverage: the second estimate scatters too;
``damper.mistuning_stats.containment_probability``). The script prints both, the fitted
distributions' 0.95 quantiles, and how many samples ``--until-ci`` needs for a few
half-widths (the prefix of the large study: the stopping rule checked after each chunk of
20 in index order, as the study does it).

Both studies run in this process and store their samples in ``--cache-dir`` (a rerun reads
them). ::

    OPENBLAS_NUM_THREADS=1 nice python examples/mistuning_confidence.py --out out/mt_confidence \\
        [--samples 1000] [--damper free] [--cache-dir out/mt_cache] [--quick]

``--quick`` (the documentation build): 80 against 320 samples of an 8-blade disk. A
damper-free sample of UPD-24 costs ~0.35 s CPU (the peak search refines every local
maximum of every blade), so the full run takes about half an hour of CPU.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from damper.cache import Store
from damper.mistuning import CHUNK_UNTIL_CI, Study, run_study
from damper.mistuning_stats import containment_probability, quantile_ci, quantile_half_width

STD, SEEDS = 0.02, (1, 2)


def study(n: int, seed: int, damper: str, store: Store, blades: int | None) -> dict:
    t0 = time.process_time()
    eo = None if blades is None else blades // 4      # the interblade phase of UPD-24 (EO 6 of 24)
    out = run_study(Study(std=STD, samples=n, seed=seed, damper=damper, blades=blades, engine_order=eo),
                    store, serial=True, echo=lambda t: None)
    out["cpu_s"] = time.process_time() - t0
    return out


def amplifications(out: dict) -> np.ndarray:
    return np.array([s["amplification"] for s in out["samples"] if s["error"] is None])


def until_ci_samples(amp: np.ndarray, width: float) -> int | None:
    """Samples --until-ci ``width`` would run on this sequence (None: not reached)."""
    for n in range(CHUNK_UNTIL_CI, amp.size + 1, CHUNK_UNTIL_CI):
        if quantile_half_width(amp[:n], 0.95) <= width:
            return n
    return None


def plot(a: np.ndarray, b: np.ndarray, q: dict, ref: float, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for x, lab, c in ((a, f"{a.size} samples (seed {SEEDS[0]})", "C0"),
                      (b, f"{b.size} samples (seed {SEEDS[1]})", "C1")):
        xs = np.sort(x)
        ax.step(xs, np.arange(1, xs.size + 1) / xs.size, where="post", color=c, label=lab)
    ax.axhline(0.95, color="0.5", lw=0.8)
    ax.axvspan(q["low"], q["high"], color="C0", alpha=0.2, label="0.95 quantile: 95 % interval")
    ax.axvline(ref, color="C1", ls="--", lw=1, label="0.95 quantile of the large study")
    ax.set_xlabel("amplification factor")
    ax.set_ylabel("empirical distribution function")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def confidence_row(n: int, damper: str, store: Store, blades: int | None = None) -> dict:
    """The comparison of the module docstring: a study of ``n`` samples (seed 1) and an
    independent one of 4 ``n`` (seed 2); the row (JSON-able) and the two samples."""
    small = study(n, SEEDS[0], damper, store, blades)
    large = study(4 * n, SEEDS[1], damper, store, blades)
    x, y = amplifications(small), amplifications(large)
    q, ref = quantile_ci(x, 0.95), float(np.quantile(y, 0.95))
    fits = {k: o["statistics"]["fit"] for k, o in (("small", small), ("large", large))}
    row = {"case": "confidence", "damper": damper, "std": STD, "blades": small["blades"],
           "n_small": int(x.size), "n_large": int(y.size), "q95_small": q["value"],
           "q95_low": q["low"], "q95_high": q["high"], "coverage": q["coverage"], "q95_large": ref,
           "contained": bool(q["low"] <= ref <= q["high"]),
           "containment_probability": containment_probability(int(x.size), int(y.size)),
           "q95_large_interval": quantile_ci(y, 0.95),
           "fit_best": {k: f and f["best"] for k, f in fits.items()},
           "fit_q95": {k: f and f["best"] and f["fits"][f["best"]]["quantiles"]["0.95"] for k, f in fits.items()},
           "until_ci_samples": {f"{w:g}": until_ci_samples(y, w) for w in (0.05, 0.02, 0.01, 0.005)},
           "cpu_s": {"small": small["cpu_s"], "large": large["cpu_s"]},
           "cpu_per_sample_s": (small["cpu_s"] + large["cpu_s"]) / (x.size + y.size),
           "efficiency": {"small": small["efficiency"], "large": large["efficiency"]}}
    return row, x, y


def row_lines(row: dict) -> list:
    """The printed comparison."""
    ok = row["contained"]
    return [f"{row['damper']} damper, std {STD}, {row['blades']} blades",
            f"0.95 quantile of {row['n_small']} samples: {row['q95_small']:.4f}, 95 % interval "
            f"[{row['q95_low']:.4f}, {row['q95_high']:.4f}] (coverage {row['coverage']:.4f})",
            f"0.95 quantile of {row['n_large']} independent samples: {row['q95_large']:.4f} -> "
            + ("inside" if ok else "outside") + " the interval (a pair holds with probability "
            f"{row['containment_probability']:.3f}: the large study's estimate scatters too)",
            f"fitted {row['fit_best']['small']} 0.95 quantile (small study): {row['fit_q95']['small']}",
            "samples --until-ci would need (large study's sequence): "
            + ", ".join(f"+-{w}: {m}" for w, m in row["until_ci_samples"].items()),
            f"CPU: {row['cpu_s']['small']:.1f} s and {row['cpu_s']['large']:.1f} s "
            f"({row['cpu_per_sample_s']:.3f} s a sample)"]


def main(argv=None) -> int:
    from damper.script import out_folder

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=out_folder, default=Path("out/mt_confidence"))
    p.add_argument("--samples", type=int, help="samples of the first study (the second: 4x; default 1000)")
    p.add_argument("--damper", choices=("free", "stuck", "nonlinear"), default="free")
    p.add_argument("--cache-dir", type=Path, help="sample cache (default: a temporary folder)")
    p.add_argument("--blades", type=int, help="N_b (default: the UPD model's 24; EO = N_b / 4)")
    p.add_argument("--quick", action="store_true", help="80 against 320 samples of 8 blades")
    a = p.parse_args(argv)
    if a.quick and (a.samples is not None or a.blades is not None):   # not silently replaced
        p.error("--quick runs 80 samples of 8 blades: drop --samples and --blades, or --quick")
    n, blades = (80, 8) if a.quick else (1000 if a.samples is None else a.samples, a.blades)
    if n < 72:
        p.error("--samples must be >= 72 (the 0.95 quantile's two-sided interval needs them)")
    with tempfile.TemporaryDirectory() as tmp:
        row, x, y = confidence_row(n, a.damper, Store(a.cache_dir or tmp), blades)
    for line in row_lines(row):
        print(line)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "mistuning_confidence.json").write_text(json.dumps(row, indent=1) + "\n")
    q = {"low": row["q95_low"], "high": row["q95_high"]}
    plot(x, y, q, row["q95_large"], a.out / "mistuning_confidence.png")
    return 0   # a miss is a possible outcome of a 95 % interval, reported, not an error


if __name__ == "__main__":
    from damper.script import run as run_script

    sys.exit(run_script(main))
