"""Each tool at its own H for 1 % (damper.bench.peer_accuracy): the scan stops at the first H
within 1 % of the reference, and the ratio is of the times at those H."""
from pathlib import Path

import pytest

from damper.bench import peer_accuracy, peers, peers_1pct
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


def test_curve_alone_is_kept_only_when_its_peak_is_the_commands(tmp_path):
    ours = {"H": 5, "peak_amplitude": 0.25, "cpu_s": 0.4, "time_s": 0.5}

    def same(name, H, work, timeout):
        return {"error": None, "peak_amplitude": 0.25 * (1 + 0.1 * peer_accuracy.CURVE_SAME_REL),
                "cpu_s": 0.1, "solve_s": 0.2}

    def other(name, H, work, timeout):   # a different curve must not lend its time
        return {"error": None, "peak_amplitude": 0.25 * (1 + 10 * peer_accuracy.CURVE_SAME_REL),
                "cpu_s": 0.1, "solve_s": 0.2}

    kept = peer_accuracy.with_curve_alone(ours, "x", Path(tmp_path), curve=same)
    assert kept["cpu_curve_s"] == 0.1 and kept["time_curve_s"] == 0.2
    refused = peer_accuracy.with_curve_alone(ours, "x", Path(tmp_path), curve=other)
    assert "cpu_curve_s" not in refused and "not the command's" in refused["curve_status"]
    peer = {"H": 7, "cpu_s": 2.0, "time_s": 3.0, "error": 0.005}
    e = peer_accuracy.row("x", "pyHarm", sdof(1.0), kept, peer).extra
    assert e["speedup_cpu_curve_1pct"] == pytest.approx(2.0 / 0.1)
    assert e["speedup_cpu_1pct"] == pytest.approx(2.0 / 0.4)
    assert peer_accuracy.row("x", "pyHarm", sdof(1.0), refused, peer).extra["speedup_cpu_curve_1pct"] is None


def test_curve_alone_gives_the_commands_peak(tmp_path):
    """The like-with-like child (damper.bench.peer_ours) traces the command's curve: the
    single-DOF soft case at H = 3 in both, peaks equal to CURVE_SAME_REL."""
    from damper.bench.hb_classes import run_ours

    case = sdof(1.0)
    o = run_ours(case.name, Path(tmp_path), peer_accuracy.replace(case, harmonics=3))
    c = peer_accuracy.curve_alone(case.name, 3, Path(tmp_path))
    assert c["error"] is None and c["cpu_s"] > 0.0
    assert c["peak_amplitude"] == pytest.approx(o["peak_amplitude"], rel=peer_accuracy.CURVE_SAME_REL)


def test_markdown_has_a_cell_per_column_and_a_dash_for_no_ratio():
    row = {"model": "sdof soft", "tool": "pyHarm", "H_ours": 1, "H_peer": None, "cpu_ours_s": 0.1,
           "status": "free start: diverged"}
    lines = peer_accuracy.markdown([row])
    cells = lines[2].strip("|").split("|")
    assert len(cells) == len(peer_accuracy.COLUMNS) + 1
    assert cells[3].strip() == "-" and cells[4].strip() == "0.100"


def test_runner_without_pyharm_exits_2_naming_the_interpreter(tmp_path, capsys):
    missing = tmp_path / "no_python"
    assert peers_1pct.main(["--pyharm", str(missing), "--case", "sdof soft", "--json"]) == 2
    err = capsys.readouterr().err
    assert str(missing) in err and err.count("\n") == 1
