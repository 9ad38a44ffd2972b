"""damper upd mistuning: the documented JSON keys, refused input (exit 2, nothing written),
resumption from the cache, a failing sample in the table, Dask against serial, the scene."""
import json

import pytest

from damper.cli import main
from harmonic_balance.bladed_disk.mistuning import draw_factors

#: A small study: four blades (EO 1, the interblade phase of UPD-24), H = 3, 11 points.
SMALL = ["upd", "mistuning", "--blades", "4", "--engine-order", "1", "--harmonics", "3",
         "--points", "11"]
KEYS = ("tuned_peak", "samples", "max_amplification", "quantiles", "time_s")
SAMPLE_KEYS = ("index", "factors", "peak_per_blade", "amplification", "frequency_hz")


def _run(argv, capsys, code=0):
    assert main(argv) == code
    out = capsys.readouterr()
    return json.loads(out.out) if code == 0 else out.err


@pytest.mark.parametrize("extra, message", [
    (["--factors", "1", "-1", "1", "1"], "blade 1 factor -1.0 must be finite and > 0"),
    (["--factors", "1", "nan", "1", "1"], "blade 1 factor nan"),
    (["--factors", "1", "1", "1"], "3 factors for 4 blades"),
    (["--std", "0.6", "--samples", "50"], "too large"),
    (["--std", "-0.01"], "must be finite and >= 0"),
    (["--samples", "0"], "samples must be >= 1"),
    (["--samples", "100000"], "above the limit"),
    (["--points", "2"], "points must be >= 3"),
    (["--band", "500", "400"], "give LO < HI"),
    (["--blades", "100000"], "above the limit"),
    (["--workers", "1000"], "above the limit"),
    (["--factors", "1", "1", "1", "1", "--std", "0.1"], "not both"),
    (["--scheduler", "tcp://127.0.0.1:9"], "cannot reach the Dask scheduler"),
    (["--workers", "2", "--serial"], "give one of"),
    (["--until-ci", "0"], "until-ci half-width must be finite and > 0"),
    (["--until-ci", "-0.01"], "until-ci half-width must be finite and > 0"),
    (["--until-ci", "nan"], "until-ci half-width must be finite and > 0"),
    (["--until-ci", "inf"], "until-ci half-width must be finite and > 0"),
    (["--factors", "1", "1", "1", "1", "--until-ci", "0.01"], "needs random samples"),
])
def test_refused_input_exit_2_nothing_written(tmp_path, capsys, monkeypatch, extra, message):
    monkeypatch.setattr("damper.tasks.CONNECT_TIMEOUT", 1)   # the unreachable scheduler: 1 s
    cache, plots = tmp_path / "cache", tmp_path / "plots"
    err = _run(SMALL + extra + ["--json", "--cache-dir", str(cache), "--plot", str(plots)], capsys, 2)
    assert message in err and "Traceback" not in err
    assert not cache.exists() and not plots.exists()


def test_study_json_keys(tmp_path, capsys):
    out = _run(SMALL + ["--std", "0.02", "--samples", "2", "--serial", "--json", "--cache-dir",
                        str(tmp_path / "c"), "--plot", str(tmp_path / "p")], capsys)
    for k in KEYS:
        assert k in out
    assert set(out["quantiles"]) == {"0.05", "0.25", "0.5", "0.75", "0.95"}
    for s in out["samples"]:
        assert all(k in s for k in SAMPLE_KEYS) and s["error"] is None and len(s["factors"]) == 4
        assert s["amplification"] == pytest.approx(max(s["peak_per_blade"]) / out["tuned_peak"], rel=1e-12)
        assert out["band_hz"][0] <= s["frequency_hz"] <= out["band_hz"][1]
    assert out["max_amplification"] == max(s["amplification"] for s in out["samples"])
    assert (tmp_path / "p" / "mistuning_histogram.png").exists()
    assert (tmp_path / "p" / "mistuning_blades.png").exists()


def test_resume_and_a_failing_sample(tmp_path, capsys, monkeypatch):
    """An interrupted (or extended) study reads its stored samples; a failing sample is a
    row with its message, not a crash, and is not stored (a later run tries it again).
    Linear limit (stuck): the same tasks and cache as the harmonic balance, faster."""
    import damper.mistuning as mt

    args = SMALL + ["--damper", "stuck", "--std", "0.02", "--seed", "3", "--serial", "--json",
                    "--cache-dir", str(tmp_path / "c")]
    first = _run(args + ["--samples", "2"], capsys)
    assert first["cached"] == 0 and first["failed"] == 0
    solve, third = mt._solve_sample, draw_factors(4, 0.02, 3, 2).tolist()

    def failing(model, kappa):
        if kappa == third:
            raise RuntimeError("ring harmonic balance failed (test)")
        return solve(model, kappa)

    monkeypatch.setattr(mt, "_solve_sample", failing)
    again = _run(args + ["--samples", "3"], capsys)
    assert again["cached"] == 2 and again["failed"] == 1
    assert [s["amplification"] for s in again["samples"][:2]] == [s["amplification"] for s in first["samples"]]
    bad = again["samples"][2]
    assert bad["amplification"] is None and "failed (test)" in bad["error"]
    monkeypatch.setattr(mt, "_solve_sample", solve)
    last = _run(args + ["--samples", "3"], capsys)
    assert last["cached"] == 2 and last["failed"] == 0


def test_every_sample_failing_prints_the_object_with_the_errors_and_exits_3(tmp_path, capsys, monkeypatch):
    import damper.mistuning as mt

    def failing(model, kappa):
        raise RuntimeError("ring harmonic balance failed (test)")

    monkeypatch.setattr(mt, "_solve_sample", failing)
    code = main(SMALL + ["--damper", "stuck", "--std", "0.02", "--samples", "2", "--serial", "--json",
                         "--cache-dir", str(tmp_path / "c")])
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert code == 3 and "every sample failed" in cap.err.splitlines()[-1]
    assert out["failed"] == 2 and out["max_amplification"] is None and out["quantiles"] is None
    assert out["statistics"] is None
    assert all("failed (test)" in s["error"] and s["amplification"] is None for s in out["samples"])


def test_given_pattern_and_linear_limit(tmp_path, capsys):
    """One given pattern of ones is the tuned disk (amplification 1); linear limit free."""
    out = _run(SMALL + ["--factors", "1", "1", "1", "1", "--damper", "free", "--serial", "--json",
                        "--cache-dir", str(tmp_path)], capsys)
    assert len(out["samples"]) == 1 and out["max_amplification"] == pytest.approx(1.0, abs=1e-12)  # measured 5.6e-15


@pytest.mark.slow
def test_dask_two_workers_equal_serial(tmp_path, capsys):
    base = SMALL + ["--std", "0.02", "--samples", "4", "--json"]
    serial = _run(base + ["--serial", "--cache-dir", str(tmp_path / "a")], capsys)
    dask = _run(base + ["--workers", "2", "--cache-dir", str(tmp_path / "b")], capsys)
    assert [s["peak_per_blade"] for s in dask["samples"]] == [s["peak_per_blade"] for s in serial["samples"]]
    assert dask["cached"] == 0


def test_scene_mistuning_stage(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text('want = ["mistuning"]\n[mistuning]\nblades = 4\nengine_order = 1\nsamples = 2\n'
                     'damper = "stuck"\npoints = 21\n')
    args = ["run", str(scene), "--out", str(tmp_path / "out"), "--cache-dir", str(tmp_path / "c")]
    assert main(args) == 0
    res = json.loads((tmp_path / "out" / "mistuning" / "result.json").read_text())
    data = res.get("data", res)
    assert len(data["samples"]) == 2 and data["max_amplification"] > 1.0
    assert (tmp_path / "out" / "mistuning" / "mistuning_histogram.png").exists()
    capsys.readouterr()
    assert main(args + ["--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert {s["name"]: s["action"] for s in rec["stages"]}["mistuning"] == "cached"
    bad = tmp_path / "bad.toml"
    bad.write_text('want = ["mistuning"]\n[mistuning]\nblades = 4\nengine_order = 1\nstd = 0.6\nsamples = 50\n')
    assert main(["run", str(bad), "--out", str(tmp_path / "o2"), "--cache-dir", str(tmp_path / "c2")]) == 2
    assert not (tmp_path / "o2").exists() and not (tmp_path / "c2").exists()


@pytest.mark.slow  # a child process that starts a two-worker Dask cluster: ~10 s
def test_ctrl_c_on_dask_is_one_line_and_exit_130(tmp_path):
    """Ctrl-C while Dask workers run samples: exit 130, our one line, no Dask traceback.
    SIGINT goes to the whole process group, as a terminal's Ctrl-C does (the workers get it
    too), as soon as the study's line shows (the workers are up and taking samples)."""
    import os
    import signal
    import subprocess
    import sys

    code = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
            "from damper.cli import main; sys.exit(main(sys.argv[1:]))")
    argv = [*SMALL, "--harmonics", "7", "--points", "41", "--std", "0.02", "--samples", "12",
            "--workers", "2", "--json", "--cache-dir", str(tmp_path / "c")]
    p = subprocess.Popen([sys.executable, "-c", code, *argv], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    seen = ""
    # the study's line: the workers are up and the samples go to them; the interrupt
    # follows it, not a wait
    while "samples of" not in seen and p.poll() is None:
        seen += p.stderr.readline()
    os.killpg(p.pid, signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert out == "" and "Traceback" not in err and "AllExit" not in err, err
    assert [ln for ln in err.splitlines() if ln.strip()] == [
        "damper upd: mistuning interrupted; the samples finished so far are in the cache, the same command resumes"]


@pytest.mark.parametrize("reply", [b"HTTP/1.1 400 Bad Request\r\n\r\n", None])
def test_a_server_that_is_no_dask_scheduler_is_refused_in_one_line(tmp_path, capsys, monkeypatch, reply):
    """A --scheduler address where something else answers is a bad address, exit 2, not a
    traceback or a hang: a web server's reply (Dask reads its bytes as a frame length of
    exabytes, a MemoryError), or none at all (Dask waits for the handshake without a bound:
    ours is CONNECT_TIMEOUT + HANDSHAKE_GRACE)."""
    import socket
    import threading

    monkeypatch.setattr("damper.tasks.CONNECT_TIMEOUT", 1)
    monkeypatch.setattr("damper.tasks.HANDSHAKE_GRACE", 1)
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    held = []

    def answer():
        try:
            conn, _ = server.accept()
            held.append(conn)       # kept open: the silent server never closes it either
            if reply is not None:
                conn.sendall(reply)
        except OSError:     # closed by the test when no connection came
            pass

    threading.Thread(target=answer, daemon=True).start()
    try:
        err = _run(SMALL + ["--scheduler", f"tcp://127.0.0.1:{server.getsockname()[1]}", "--json",
                            "--cache-dir", str(tmp_path / "cache")], capsys, 2)
    finally:
        server.close()
        for conn in held:
            conn.close()
    assert "cannot reach the Dask scheduler" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "cache").exists()


def test_fewer_blades_than_the_models_engine_order_allows_asks_for_an_engine_order(tmp_path, capsys):
    """--blades 2 with UPD-24's engine order 6 (above N_b / 2): the message names the
    option to add, not the config key the blades broke."""
    err = _run(["upd", "mistuning", "--blades", "2", "--samples", "1", "--damper", "free", "--serial",
                "--json", "--cache-dir", str(tmp_path / "c")], capsys, 2)
    assert "give the engine order too, 0 .. 1" in err and len(err.strip().splitlines()) == 1


def test_one_sample_gives_no_spread_and_no_two_sided_interval(tmp_path, capsys):
    """One sample: its value is every estimate, but its spread (null, not 0) and the
    two-sided intervals of the mean and of the 0.95 quantile are unknown (null, '-' in the
    table), and no distribution is fitted."""
    out = _run(SMALL + ["--samples", "1", "--damper", "free", "--serial", "--json",
                        "--cache-dir", str(tmp_path / "c")], capsys)
    st = out["statistics"]
    assert out["std_amplification"] is None and st["n"] == 1 and st["fit"] is None
    assert st["mean"]["low"] is None and st["mean"]["high"] is None
    q95 = next(q for q in st["quantiles"] if q["q"] == 0.95)
    assert q95["low"] is None and q95["high"] is None and q95["half_width"] is None
    assert q95["value"] == out["max_amplification"]


@pytest.mark.parametrize("worst", [[], ["--worst"]])
def test_a_band_that_cuts_off_the_tuned_peak_is_refused(tmp_path, capsys, worst):
    """UPD-24 free: the tuned peak is at 426.13 Hz; on 380 ... 424 Hz the largest tuned value
    is the band's end, which every amplification would divide by (they came out 2.6 to 3.1,
    above Whitehead's bound): refused before any sample, nothing written."""
    cache = tmp_path / "c"
    err = _run(["upd", "mistuning", "--damper", "free", "--band", "380", "424", "--json", "--cache-dir", str(cache),
                *(worst or ["--samples", "2", "--serial"])], capsys, 2)
    assert "tuned peak lies at the end 424 Hz" in err and len(err.strip().splitlines()) == 1
    assert not cache.exists()


def test_a_rattling_tuned_reference_is_warned_about(tmp_path, capsys):
    """F0 3000 N against CF 120 N: the tuned sector's contacts are open over ~97 % of the
    period at its peak (the reference of every amplification): a warning in the JSON and on
    stderr; at the default F0 30 N (contacts closed) none."""
    loud = SMALL + ["--f0", "3000", "--samples", "1", "--serial", "--json", "--cache-dir", str(tmp_path / "c")]
    assert main(loud) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert "rattles" in out["lift_off_warning"] and out["lift_off_warning"] in captured.err
    quiet = _run(SMALL + ["--samples", "1", "--serial", "--json", "--cache-dir", str(tmp_path / "c")], capsys)
    assert quiet["lift_off_warning"] is None
