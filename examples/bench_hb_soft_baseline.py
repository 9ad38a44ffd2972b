"""Cost per point of the stiff-contact case, runnable against any version of harmonic_balance.
=============================================================================================

The stiff-contact cost goal compares the 1e6 k contact with the soft-contact cost of an
older revision. This script uses only ``compute_frf`` and ``sdof_model`` (present in
every version), so the same measurement runs on the code of any revision and on
today's, on the same machine, back to back::

    git worktree add /tmp/old 368c9f4^          # the revision to compare with
    mkdir -p /tmp/oldpath && ln -sfn /tmp/old/harmonic_balance /tmp/oldpath/ \
        && ln -sfn "$PWD/fmu_src" /tmp/oldpath/
    PYTHONPATH=/tmp/oldpath .venv/bin/python examples/bench_hb_soft_baseline.py 1,10
    .venv/bin/python examples/bench_hb_soft_baseline.py 1,10,1e6

Case: m = k = P = 1, c = 0.04, slip force 0.5, H = 15, 0.5 -> 2 rad/s, no peak
refinement; best wall time of three runs per stiffness ratio (the machine's load
noise), points and residual evaluations per point.
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import harmonic_balance  # noqa: E402
from harmonic_balance.frf import compute_frf  # noqa: E402
from harmonic_balance.model import sdof_model  # noqa: E402


def _ratios(text: str) -> list[float]:
    """Comma-separated contact stiffness ratios, each a positive finite number."""
    try:
        kts = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, e.g. 1,10,1e6; "
                                         f"got {text!r}") from None
    bad = [k for k in kts if not (np.isfinite(k) and k > 0.0)]
    if bad:
        raise argparse.ArgumentTypeError(f"stiffness ratios must be positive and finite, got {bad}")
    return kts


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ratios", nargs="?", type=_ratios, default=[1.0, 10.0],
                    help="contact stiffness over structure stiffness, comma-separated "
                         "(default 1,10)")
    kts = ap.parse_args(sys.argv[1:] if argv is None else argv).ratios
    extra = {"stability": False} if "stability" in compute_frf.__code__.co_varnames else {}
    print(f"harmonic_balance from {os.path.dirname(harmonic_balance.__file__)}")
    print(f"{'kt/k':>8} {'n_t':>5} {'points':>6} {'eval/pt':>7} {'best s':>7} {'ms/pt':>6}")
    rows = []
    for kt in kts:
        best = None
        for _ in range(3):
            t0 = time.perf_counter()
            try:
                r = compute_frf(sdof_model(1.0, 1.0, 0.04, kt, 0.5, 1.0), 15, (0.5, 2.0),
                                refine=False, max_points=3000, **extra)
            except RuntimeError as err:
                print(f"{kt:>8.0e} failed: {str(err)[:90]}")
                break
            dt = time.perf_counter() - t0
            best = min(best or (dt, r), (dt, r), key=lambda p: p[0])
        if best is None:
            continue
        dt, r = best
        rows.append((kt, r.n_t, r.points, r.evaluations / r.points, dt, 1e3 * dt / r.points))
        print(f"{kt:>8.0e} {r.n_t:>5} {r.points:>6} {r.evaluations / r.points:>7.2f} {dt:>7.3f} "
              f"{1e3 * dt / r.points:>6.2f}", flush=True)
    return rows


if __name__ == "__main__":
    main()
