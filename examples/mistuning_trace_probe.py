"""Probe: ring_mf (band traced at H_T, peaks at H 7) against ring_fast at H 7 on UPD-24 patterns (CPU time).

Usage: python examples/mistuning_trace_probe.py PATTERNS H_TS, e.g. 0,1,2,3,4 3
"""
import sys
import time

import numpy as np

from damper.mistuning import SampleModel, Study, tuned_reference
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.mistuning import draw_factors
from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
from harmonic_balance.bladed_disk.ring_mf import multi_fidelity_frf

pats = [int(p) for p in sys.argv[1].split(",")]
HTs = [int(h) for h in sys.argv[2].split(",")]
study = Study(std=0.02, samples=5, seed=1)
ref = tuned_reference(study, study.load())
model = SampleModel(study, ref["band_hz"], ref["tuned_frequency_hz"])
lo, hi = model.om[0], model.om[-1]
start = 2 * np.pi * ref["tuned_frequency_hz"]
tuned = None
for p in pats:
    kappa = draw_factors(24, 0.02, 1, p)
    res = {}
    for HT in [7] + HTs:
        ring = MistunedRingHB(model.sector, kappa, 7, cf=study.cf, f0=study.f0)
        tuned = tuned or SectorHB(ring.sector, 7, cf=ring.cf, f0=ring.f0, mu=ring.mu, n_t=ring.basis.n_t)
        c0 = time.process_time()
        c = multi_fidelity_frf(ring, (lo, hi), tuned, start_omega=start, trace_harmonics=HT)
        t = time.process_time() - c0
        res[HT] = c
        msg = f"p{p} HT{HT}: cpu {t:.2f} ev {c.evaluations} fac {c.extra['factorizations']} pts {c.extra['points']}"
        if HT < 7:
            r7 = res[7]
            d = np.abs(c.peak_per_blade / r7.peak_per_blade - 1).max()
            df = np.abs(c.peak_omega_per_blade - r7.peak_omega_per_blade).max() / 2 / np.pi
            msg += (f" | blades max rel {d:.2e} amp {c.peak / r7.peak - 1:+.2e} fmax {df:.3f} Hz "
                    f"fallback {c.extra.get('fallback')} trace {c.extra.get('trace')} "
                    f"windows {[(round(a/2/np.pi,1), round(b/2/np.pi,1)) for a, b in c.extra.get('windows', [])]}")
        print(msg, flush=True)
