"""Each tool at its own H for 1 % (damper.bench.peer_accuracy): the scan stops at the first H
within 1 % of the reference, and the ratio is of the times at those H."""
from pathlib import Path

import pytest

from damper.bench import peer_accuracy, peers
from harmonic_balance.bench_models import sdof

REF = {"amplitude": 1.0}


def _peak(H, c):
    """A peak converging like c / H^2 to the reference."""
    return 1.0 + c / H**2


def test_scan_stops_at_the_first_h_within_one_percent_and_rows_give_the_time_ratio(monkeypatch, tmp_path):
    ours_c, peer_c = 0.05, 0.5          # within 1 % at H >= 3 (ours), H >= 11 (the peer)

    def fake_ours(name, work, case=None):
        H = case.harmonics
        return {"complete": True, "peak_amplitude": _peak(H, ours_c), "time_s": 0.1 * H, "cpu_s": 0.1 * H,
                "check_s": 0.05 * H}

    def fake_peer(kind, case, path, work, settings, octave=None, timeout=600.0):
        H = case.harmonics
        a = _peak(H, peer_c)   # a curve whose largest point is the peak, with its neighbours
        return {"complete": True, "omega": [0.9, 1.0, 1.1], "a1": [0.5 * a, a, 0.5 * a],
                "time_s": 0.2 * H, "cpu_s": 0.3 * H, "wall_s": 0.2 * H, "status": "complete"}

    monkeypatch.setattr(peers, "run", fake_peer)
    case = sdof(1.0)
    ours = peer_accuracy.scan_ours(case, Path(tmp_path), REF, fake_ours, log=lambda s: None)
    peer = peer_accuracy.scan_peer("pyharm", case, "python", Path(tmp_path), {}, REF, log=lambda s: None)
    assert ours["H"] == 3 and [t["H"] for t in ours["scan"]] == [1, 3]
    assert peer["H"] == 11 and peer["error"] == pytest.approx(peer_c / 121)
    e = peer_accuracy.row(case.name, "pyHarm", case, ours, peer).extra
    assert e["speedup_cpu_1pct"] == pytest.approx(0.3 * 11 / (0.1 * 3))
    assert e["speedup_1pct"] == pytest.approx(0.2 * 11 / (0.1 * 3))
    assert e["speedup_curve_1pct"] == pytest.approx(0.2 * 11 / (0.05 * 3))   # our curve without its check


def test_a_peer_that_never_reaches_one_percent_has_no_ratio(monkeypatch, tmp_path):
    monkeypatch.setattr(peers, "run", lambda *a, **k: {"complete": False, "error": "diverged",
                                                       "status": "free start: diverged", "wall_s": 1.0})
    case = sdof(1.0)
    peer = peer_accuracy.scan_peer("pyharm", case, "python", Path(tmp_path), {}, REF, log=lambda s: None)
    assert peer["H"] is None and len(peer["scan"]) == len(peer_accuracy.SCAN)
    ours = {"H": 3, "time_s": 1.0, "cpu_s": 1.0}
    e = peer_accuracy.row(case.name, "pyHarm", case, ours, peer).extra
    assert e["speedup_cpu_1pct"] is None and e["status"] == "free start: diverged"
