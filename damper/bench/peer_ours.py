"""Our curve of a benchmark case timed as the peers' drivers time theirs (like with like).

Usage: ``python -m damper.bench.peer_ours CASE H OUT.json``

A peer's driver (:mod:`.peer_pyharm`) imports the peer first, then times the build of its
system and its continuation over the band, and nothing else: no command-line parsing, no
output files, no stability of the points (pyHarm computes none) and no estimate of the
truncation error (it makes none). This child does the same for ours: the library and
everything the curve loads imported first (:data:`PRELOAD`), then the model built and
:func:`harmonic_balance.frf.compute_frf` called with the ``damper frf`` command's
settings except ``stability="off"`` and ``truncation_check=False``. The peak is refined as
the command refines it (that is part of what brings ours within 1 % at a given H), so the
curve and its peak are the command's: :mod:`.peer_accuracy` checks that they agree.

CASE: a name of :func:`harmonic_balance.bench_models.by_name`; H: harmonics 0..H.
OUT.json: ``peak_amplitude`` (first harmonic at the refined peak), ``peak_omega``,
``points``, ``evaluations``, ``solve_s`` (wall) and ``cpu_s`` (process time) of the build
and the curve, and ``error`` (a message) when it raised.
"""
from __future__ import annotations

import importlib
import json
import sys
import time

#: Modules the curve loads on first use (measured: 0.2 s of CPU in a fresh process on a
#: 42-point 3-mass curve that itself costs 0.05 s), imported before the clock starts as
#: the peer's driver imports the peer before its clock starts.
PRELOAD = ("scipy.linalg", "fmu_src.element", "harmonic_balance.frf", "harmonic_balance.frf_accuracy",
           "harmonic_balance.stability", "harmonic_balance.bench_models", "harmonic_balance.peaks")


def run(name: str, harmonics: int) -> dict:
    """The curve of case ``name`` at H = ``harmonics`` (module docstring): its numbers."""
    for module in PRELOAD:
        importlib.import_module(module)
    from dataclasses import replace

    from harmonic_balance.bench_models import by_name
    from harmonic_balance.frf import compute_frf

    case = replace(by_name(name), harmonics=int(harmonics))
    out = {"error": None}
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        r = compute_frf(case.model(), case.harmonics, case.band, stability="off", truncation_check=False)
        out.update(peak_amplitude=r.peak_amplitude_h1, peak_omega=r.peak_omega, points=r.points,
                   evaluations=r.evaluations, status=r.status)
    except (ValueError, RuntimeError) as err:   # a failed curve is a result of the benchmark
        out["error"] = f"{type(err).__name__}: {err}"[:300]
    out["solve_s"], out["cpu_s"] = time.perf_counter() - t0, time.process_time() - c0
    return out


if __name__ == "__main__":
    with open(sys.argv[3], "w") as f:
        json.dump(run(sys.argv[1], int(sys.argv[2])), f)
