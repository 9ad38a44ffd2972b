"""Points, time and peak error of forced-response curves on small friction model classes.
======================================================================================

Runnable against any version of ``harmonic_balance`` that has ``compute_frf`` (the same
script measures an old revision and the current one side by side in one run)::

    git archive REV harmonic_balance | tar -x -C /tmp/old
    ln -sfn "$PWD/fmu_src" /tmp/old/ && ln -sfn "$PWD/contact_core" /tmp/old/
    PYTHONPATH=/tmp/old .venv/bin/python examples/bench_hb_speed.py sdof p3
    .venv/bin/python examples/bench_hb_speed.py sdof p3

Cases (SI units; H harmonics 0..H):

* ``sdof``: m = k = 1, c = 0.04, Jenkins link k_t = 1, slip force 0.5, F = 1, H = 15,
  0.5 -> 2 rad/s (the soft single-DOF curve, with peak refinement and stability).
* ``p3``: NLvib's 3-mass friction chain: m = [1, 1, 1], grounded chain of springs
  k = [1, 1, 1, 1], C = 0.02 K, force F on mass 2 (the response), Jenkins links
  ground-mass 1 and mass 1-mass 2 of stiffness knl and slip force 1, H = 7, for
  F in (0.5, 1, 2) and knl in (20, 200, 2000), 0.5 -> 2 and 2 -> 0.5 rad/s.
* ``p5``: a 5-mass chain (m = 1, grounded chain of six unit springs, C = 0.02 K, force
  1 on mass 3, the response) with three Jenkins links: ground-mass 1 (k 50, slip 0.5),
  mass 2-mass 3 (k 500, slip 1), mass 4-mass 5 (k 200, slip 2); H = 7, 0.3 <-> 2.2 rad/s.
* ``stiff``: the sdof oscillator with k_t = 2e3, 5e3, 1e4 (H = 7) and 1e4 (H = 15),
  c = 0.04, slip 0.5, F = 1, 0.9 -> 1.1 rad/s (curves whose peak refinement failed).

The peak error is that of the first-harmonic amplitude at the refined peak against a
dense trace of the same model (same H and friction-link evaluation, ``ds_max`` =
REF_STEP, curve tolerance REF_TOL where there is one), computed once per case and kept
in ``--ref-file``. Times: wall clock and this process's CPU time of one run (noisy on a
shared machine: compare revisions side by side, in one run).
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import harmonic_balance  # noqa: E402
from harmonic_balance.aft import FrictionLink  # noqa: E402
from harmonic_balance.frf import compute_frf  # noqa: E402
from harmonic_balance.linear import LinearModel  # noqa: E402
from harmonic_balance.model import Model, jenkins_element, sdof_model  # noqa: E402

#: Largest scaled continuation step of the dense reference traces.
REF_STEP = 0.002


def chain(masses: int, links, force: float, forced: int) -> Model:
    """Grounded spring chain (unit masses and springs, C = 0.02 K) with Jenkins links
    ``links`` = [(dof_a, dof_b or None, k, slip)], force on ``forced`` (the response)."""
    K = 2.0 * np.eye(masses) - np.eye(masses, k=1) - np.eye(masses, k=-1)
    lin = LinearModel(M=np.eye(masses), C=0.02 * K, K=K)
    els = [FrictionLink(jenkins_element(k, fs), a, b, f"link{i}") for i, (a, b, k, fs) in enumerate(links)]
    f = np.zeros(masses, dtype=complex)
    f[forced] = force
    return Model(lin, els, {1: f}, forced)


def cases(names):
    """(label, model, H, (omega_start, omega_end)) of the selected case families."""
    out = []
    if "sdof" in names:
        out.append(("sdof soft", sdof_model(1, 1, 0.04, 1.0, 0.5, 1.0), 15, (0.5, 2.0)))
    if "p3" in names:
        for F in (0.5, 1.0, 2.0):
            for knl in (20.0, 200.0, 2000.0):
                m = chain(3, [(0, None, knl, 1.0), (0, 1, knl, 1.0)], F, 1)
                out.append((f"p3 F={F:g} knl={knl:g} up", m, 7, (0.5, 2.0)))
                out.append((f"p3 F={F:g} knl={knl:g} down", m, 7, (2.0, 0.5)))
    if "p5" in names:
        m = chain(5, [(0, None, 50.0, 0.5), (1, 2, 500.0, 1.0), (3, 4, 200.0, 2.0)], 1.0, 2)
        out.append(("p5 up", m, 7, (0.3, 2.2)))
        out.append(("p5 down", m, 7, (2.2, 0.3)))
    if "stiff" in names:
        for kt, H in ((2e3, 7), (5e3, 7), (1e4, 7), (1e4, 15)):
            out.append((f"sdof kt={kt:g} H={H}", sdof_model(1, 1, 0.04, kt, 0.5, 1.0), H, (0.9, 1.1)))
    return out


def run(model, H, rng, **kw):
    """(result, error message or None, wall time [s], CPU time of this process [s])."""
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        r = compute_frf(model, H, rng, **kw)
        err = None
    except RuntimeError as e:
        r = getattr(e, "result", None)
        err = str(e)
    return r, err, time.perf_counter() - t0, time.process_time() - c0


#: Curve tolerance of the dense references (where compute_frf has one).
REF_TOL = 1e-4


def reference(label, model, H, rng, refs):
    """Dense first-harmonic peak (omega, amplitude) of the case, cached in ``refs``."""
    if label not in refs:
        dense = {"tolerance": REF_TOL} if "tolerance" in compute_frf.__code__.co_varnames else {}
        r, err, _, _ = run(model, H, rng, ds_max=REF_STEP, max_points=200000, stability=False, **dense)
        refs[label] = None if err else [r.peak_omega, r.peak_amplitude_h1]
    return refs[label]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*", metavar="CASE",
                    help="case families: sdof, p3, p5, stiff (default: all)")
    exact = "aft" in compute_frf.__code__.co_varnames  # exact friction links by default
    ap.add_argument("--ref-file", default=f"/tmp/bench_hb_speed_refs_{'exact' if exact else 'sampled'}.json",
                    help="dense reference peaks, computed when missing (one file per AFT kind: "
                    "the exact links' references for a version with them)")
    ap.add_argument("--no-ref", action="store_true", help="skip the dense references")
    ap.add_argument("--json", help="write the rows to this file")
    a = ap.parse_args(sys.argv[1:] if argv is None else argv)
    families = ("sdof", "p3", "p5", "stiff")
    if set(a.cases) - set(families):
        ap.error(f"unknown case families {sorted(set(a.cases) - set(families))}: use {', '.join(families)}")
    a.cases = a.cases or list(families)
    refs = {}
    if not a.no_ref and os.path.exists(a.ref_file):
        with open(a.ref_file) as f:
            refs = json.load(f)
    print(f"harmonic_balance from {os.path.dirname(harmonic_balance.__file__)}")
    print(f"{'case':<26} {'points':>6} {'time s':>7} {'cpu s':>6} {'peak omega':>10} {'peak h1':>11} "
          f"{'err h1 %':>8} {'err w %':>7}  status")
    rows = []
    for label, model, H, rng in cases(a.cases):
        r, err, dt, cpu = run(model, H, rng)
        ref = None if a.no_ref else reference(label, model, H, rng, refs)
        if not a.no_ref:
            with open(a.ref_file, "w") as f:
                json.dump(refs, f, indent=1)
        pts = r.points if r is not None else 0
        w = r.peak_omega if r is not None else float("nan")
        a1 = r.peak_amplitude_h1 if r is not None else float("nan")
        e_a = 100 * (a1 / ref[1] - 1) if ref else float("nan")
        e_w = 100 * (w / ref[0] - 1) if ref else float("nan")
        status = ("FAIL: " + err[:70]) if err else r.status[:70]
        rows.append({"case": label, "points": pts, "time_s": dt, "cpu_s": cpu, "peak_omega": w, "peak_h1": a1,
                     "err_h1_pct": e_a, "err_omega_pct": e_w, "ok": err is None, "status": status})
        print(f"{label:<26} {pts:>6} {dt:>7.3f} {cpu:>6.3f} {w:>10.6g} {a1:>11.6g} {e_a:>8.3f} {e_w:>7.3f}  "
              f"{status}", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    return rows


if __name__ == "__main__":
    main()
