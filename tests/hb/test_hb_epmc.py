"""EPMC backbones against the exact describing function and the forced-response peaks."""
import numpy as np
from hbcases import two_dof
from jenkins_ref import describing_function
from refcheck import check

from harmonic_balance.epmc import compute_backbone
from harmonic_balance.frf import compute_frf
from harmonic_balance.model import sdof_model

#: Backbone against the H = 1 describing function: the AFT sampling error at the default
#: n_t = 256, deterministic (no round-off at this level). Measured 3.3e-6 in frequency,
#: 5.4e-5 in damping (revision a12e5f1); 10x each.
DF_OMEGA_RTOL = 3e-5
DF_XI_RTOL = 5e-4
#: Forced peaks on the backbone: 1 % (measured 0.27 % at the largest forcing).
PEAK_RTOL = 1e-2


def test_sdof_jenkins_backbone_matches_the_describing_function():
    c, kt, fs = 0.04, 1.0, 0.05
    bb = compute_backbone(sdof_model(1, 1, c, kt, fs, 1.0), 1, (1e-3, 10))
    assert bb.status == "complete" and bb.a[0] == 1e-3 and abs(bb.a[-1] - 10) < 1e-9
    w_ex, xi_ex = [], []
    for a in bb.a:
        a1, b1 = describing_function(kt, fs, a)
        w_ex.append(np.sqrt(1 + a1 / a))                # (k + a1/a - omega^2 m) a = 0
        xi_ex.append(c - b1 / (a * w_ex[-1]))           # (xi m - c) a omega = -b1
    df = "describing function of the Jenkins element"
    check("EPMC backbone frequency [rad/s], Jenkins oscillator, H = 1, every point", bb.omega, w_ex,
          rtol=DF_OMEGA_RTOL, source=df)
    check("EPMC artificial damping xi [1/s], Jenkins oscillator, H = 1, every point", bb.xi, xi_ex,
          rtol=DF_XI_RTOL, source=df)
    assert bb.damping_ratio.max() > 5 * bb.damping_ratio[0]  # friction damping shows (9x)


def test_two_dof_forced_peaks_lie_on_the_backbone():
    bb = compute_backbone(two_dof(True), "odd:3", (1e-3, 3))
    assert np.all(np.diff(bb.amplitude) > 0)
    for P in (0.01, 0.05, 0.2):
        r = compute_frf(two_dof(True, P=P), "odd:3", (0.5, 1.3))
        w_bb = np.interp(r.peak_amplitude, bb.amplitude, bb.omega)
        check(f"forced peak frequency [rad/s], 2-DOF Jenkins model, P = {P:g}", r.peak_omega, w_bb, rtol=PEAK_RTOL,
              kind="self-consistency", source="EPMC backbone at the peak's amplitude (phase resonance)")


def test_backbone_cli_json(capsys):
    import json

    from damper.cli import main

    code = main(["backbone", "--model", "sdof", "--contact-stiffness", "1", "--slip-force", "0.05",
                 "--amplitude", "1e-3", "1", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["status"] == "complete" and out["points"] == len(out["omega"])
    assert main(["backbone", "--model", "sdof", "--amplitude", "0", "1"]) == 2
