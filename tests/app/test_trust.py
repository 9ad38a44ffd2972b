"""Nothing lost, nothing hangs: the cache owns only its own files, entries are checked on
read, file modes follow the umask, a failed or interrupted run writes no output folder,
sweeps go on past a failing variant, and every refusal is one line before any work."""
import csv
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from processes import gone_after_kill

from contact_core.fileio import atomic_write
from damper.cache import TAG_NAME, NotACacheError, Store, is_cache_folder
from damper.cli import main as damper
from damper.run.graph import Kind, Result, Stage
from damper.run.progress import Progress
from damper.run.runner import Interrupted, execute, plan_scene
from damper.scene import parse_scene

ROOT = Path(__file__).resolve().parents[2]
BACKBONE = (ROOT / "examples" / "scenes" / "backbone.toml").read_text()
BLOB = {"x": np.arange(2000.0)}             # ~16 kB per entry


def _quiet():
    sink = io.StringIO()
    return Progress(0, stream=sink, live=False, out=sink)


# -- the cache folder is the cache's own ---------------------------------------------
def test_clear_and_eviction_leave_a_users_file_in_the_cache_folder(tmp_path):
    s = Store(tmp_path / "c", max_bytes=3 * 16500)
    for i in range(3):
        s.put(f"k{i}", BLOB, {"i": i})
    assert is_cache_folder(tmp_path / "c")
    user = tmp_path / "c" / "matrices.npz"           # a user's file dropped into the tagged folder
    user.write_bytes(b"the user's own data")
    (tmp_path / "c" / "notes.txt").write_text("keep")
    for i in range(3, 8):                            # over the limit: least recently used entries go
        s.put(f"k{i}", BLOB, {"i": i})
    assert s.info()["entries"] < 8 and s.contains("k7")
    assert user.read_bytes() == b"the user's own data"
    left = s.info()["entries"]
    assert s.clear() == left and not s.entries()
    assert user.read_bytes() == b"the user's own data" and (tmp_path / "c" / "notes.txt").read_text() == "keep"


def test_a_folder_of_the_users_is_neither_cleared_nor_written(tmp_path, capsys):
    proj = tmp_path / "proj"
    proj.mkdir()
    (proj / "matrices.npz").write_bytes(b"user data")
    assert damper(["cache", "clear", "--cache-dir", str(proj)]) == 2
    err = capsys.readouterr().err
    assert "not a damper cache" in err and err.count("\n") == 1
    with pytest.raises(NotACacheError, match="not a damper cache"):
        Store(proj).put("k", BLOB, {})
    assert sorted(p.name for p in proj.iterdir()) == ["matrices.npz"]


def test_entry_names_cannot_be_mistaken_for_user_files(tmp_path):
    s = Store(tmp_path)
    s.put("abc", BLOB, {})
    (tmp_path / "abc.npz").write_bytes(b"user")          # a user's file named like the old entries
    assert [p.name for p, _ in s.entries()] == ["entry-abc.damper-cache"]
    assert (tmp_path / TAG_NAME).read_text().startswith("Signature: 8a477f597d28d172789f06886806bc55")


# -- entries are checked on read ---------------------------------------------------------
def test_an_entry_copied_over_another_key_or_stage_is_a_miss_with_one_warning(tmp_path):
    said = []
    s = Store(tmp_path, warn=said.append)
    s.put("aaa", {"v": np.array([10.0])}, {"F": 10}, stage="frf")
    s.put("bbb", {"v": np.array([60.0])}, {"F": 60}, stage="frf")
    s.path("bbb").write_bytes(s.path("aaa").read_bytes())    # the 10 N entry under the 60 N key
    assert s.get("bbb", stage="frf") is None and s.get("bbb", stage="frf") is None
    assert s.get("aaa", stage="loop") is None                  # the right key, another stage
    assert s.get("aaa", stage="frf")[1] == {"F": 10}
    assert len(said) == 1 and "holds another result" in said[0]


def test_an_unreadable_entry_is_a_miss_with_one_warning(tmp_path):
    said = []
    s = Store(tmp_path, warn=said.append)
    for key in ("e1", "e2"):
        s.put(key, BLOB, {})
    s.path("e1").write_bytes(b"")                   # emptied
    s.path("e2").write_bytes(s.path("e2").read_bytes()[:300])   # truncated
    assert s.get("e1") is None and s.get("e2") is None
    assert len(said) == 1 and "unreadable" in said[0]


class _Level(Kind):
    """A stage kind that records its computations: one stage per excitation level."""

    name = "level"
    modules = ("damper.cache",)
    computed: list = []

    def instances(self, data):
        return [Stage(f"level:{F:g}N", self, {"force": F}, products=("backbone",)) for F in (10.0, 60.0)]

    def compute(self, stage, inputs, ctx):
        self.computed.append(stage.name)
        if stage.params["force"] == getattr(self, "fail_at", None):
            raise getattr(self, "error", RuntimeError)("did not converge")
        return Result({"peak": stage.params["force"]}, {"x": np.array([stage.params["force"]])})


def _run(store, out=None, kind=None):
    scene = parse_scene(BACKBONE)
    kind = kind or _Level()
    plan = plan_scene(scene, store, kinds=(kind,))
    return kind, execute(scene, plan, store, out, _quiet())


def test_a_stage_entry_copied_over_another_key_is_recomputed(tmp_path):
    store = Store(tmp_path / "c", warn=lambda text: None)
    kind, first = _run(store)
    keys = {s.name: s.key for s in first.plan.stages}
    store.path(keys["level:60N"]).write_bytes(store.path(keys["level:10N"]).read_bytes())
    kind.computed.clear()
    _, again = _run(Store(tmp_path / "c", warn=lambda text: None), kind=kind)
    assert kind.computed == ["level:60N"]                       # the swapped entry only
    assert again.results["level:60N"].data == {"peak": 60.0} and again.results["level:10N"].data == {"peak": 10.0}


# -- the umask ------------------------------------------------------------------------------
@pytest.mark.parametrize("mask", [0o002, 0o022, 0o077])
def test_files_follow_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        out = atomic_write(tmp_path / "out" / "report.html", "<html/>")
        s = Store(tmp_path / "cache")
        entry = s.put("k", BLOB, {})
    finally:
        os.umask(old)
    for path in (out, entry, tmp_path / "cache" / TAG_NAME):
        assert path.stat().st_mode & 0o777 == 0o666 & ~mask, path


# -- a cache this user cannot write --------------------------------------------------------
def test_a_read_only_cache_is_read_and_never_written(tmp_path, monkeypatch):
    s = Store(tmp_path)
    s.put("old", BLOB, {"v": 1})
    said = []
    ro = Store(tmp_path, warn=said.append)
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, m: False if Path(p) == tmp_path else real(p, m))
    ro.prepare()
    assert ro.readonly and len(said) == 1 and "cannot be written" in said[0]
    before = sorted(os.listdir(tmp_path))
    ro.put("new", BLOB, {"v": 2})
    assert sorted(os.listdir(tmp_path)) == before                  # nothing written
    assert ro.get("new")[1] == {"v": 2} and ro.get("old")[1] == {"v": 1}   # kept in memory, read from disk


def test_no_cache_keeps_everything_in_memory(tmp_path):
    s = Store(tmp_path / "c", memory=True)
    s.put("k", BLOB, {"v": 1})
    assert s.get("k")[1] == {"v": 1} and not (tmp_path / "c").exists()


# -- a failed or interrupted run writes no output folder -------------------------------------
@pytest.mark.parametrize("error", [RuntimeError, KeyboardInterrupt])
def test_a_failed_or_interrupted_run_writes_nothing_and_says_what_is_cached(tmp_path, error):
    kind = _Level()
    kind.fail_at, kind.error = 60.0, error
    expected = Interrupted if error is KeyboardInterrupt else RuntimeError
    with pytest.raises(expected) as info:
        _run(Store(tmp_path / "c"), tmp_path / "out", kind)
    text = getattr(info.value, "message", None) or str(info.value)
    assert "level:60N" in text and "level:10N" in text and "cached" in text and "nothing written" in text
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # a child process and a cold FE condensation: a few seconds
def test_ctrl_c_during_a_run_is_one_line_and_exit_130(tmp_path):
    scene = tmp_path / "kn.toml"
    scene.write_text('want = ["k_n", "report"]\n[contact.damper]\nbody = "cylinder"\ndiameter = 5.0e-3\n'
                     "length = 1.2e-3\nforce = 120.0\ngrid = 21\n")
    # Python leaves SIGINT ignored when its parent ignored it (pytest under `nohup ... &`):
    # the child restores the interactive default, as in a terminal.
    code = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
            "from damper.cli import main; sys.exit(main(sys.argv[1:]))")
    env = dict(os.environ, DAMPER_CACHE_DIR=str(tmp_path / "cache"))
    p = subprocess.Popen([sys.executable, "-c", code, "run", str(scene), "--out", str(tmp_path / "ok")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    seen = ""
    # the plain progress line of the first stage: the interrupt follows it, not a wait
    while "condense" not in seen and p.poll() is None:
        seen += p.stderr.readline()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    lines = [ln for ln in (seen + err).splitlines() if ln.strip() and not ln.startswith(("[", " "))]
    assert p.returncode == 130, err
    assert lines == [lines[-1]] and lines[-1].startswith("damper run: interrupted in stage condense:"), lines
    assert "Traceback" not in err and not (tmp_path / "ok").exists()


# -- sweeps go on past a failing variant ---------------------------------------------------------
def _sweep(tmp_path, monkeypatch, *extra):
    from damper.run import backbone_stages

    def compute(self, stage, inputs, ctx):
        if stage.params["backbone"]["slip_force"] == 70.0:
            raise RuntimeError("continuation stopped: singular Jacobian")
        return Result({"slip": stage.params["backbone"]["slip_force"]})

    monkeypatch.setattr(backbone_stages.Backbone, "compute", compute)
    monkeypatch.setattr(backbone_stages.Backbone, "scalars", lambda self, s, r: {"slip_N": r.data["slip"]})
    monkeypatch.setattr(backbone_stages.Backbone, "lines", lambda self, s, r: [])
    scene = tmp_path / "bb.toml"
    scene.write_text(BACKBONE.replace('want = ["backbone", "report"]', 'want = ["backbone"]'))
    return damper(["sweep", str(scene), "--param", "backbone.slip_force", "--values", "60", "70", "80",
                   "--serial", "--out", str(tmp_path / "s"), "--cache-dir", str(tmp_path / "c"), *extra])


def test_a_sweep_goes_on_past_a_failing_variant_and_exits_3(tmp_path, monkeypatch, capsys):
    assert _sweep(tmp_path, monkeypatch) == 3
    rows = list(csv.DictReader((tmp_path / "s" / "sweep.csv").open()))
    assert [r["backbone.slip_force"] for r in rows] == ["60", "70", "80"]
    assert [bool(r["error"]) for r in rows] == [False, True, False]
    assert "singular Jacobian" in rows[1]["error"] and rows[2]["backbone.slip_N"] == "80"
    assert "1 of 3 variant(s) failed" in capsys.readouterr().err


def test_fail_fast_stops_at_the_first_failure(tmp_path, monkeypatch, capsys):
    assert _sweep(tmp_path, monkeypatch, "--fail-fast") == 3
    assert "singular Jacobian" in capsys.readouterr().err and not (tmp_path / "s").exists()


# -- refusals: one line, before any work ----------------------------------------------------------
def test_version_and_numpy_scalars_in_messages(capsys):
    with pytest.raises(SystemExit) as info:
        damper(["--version"])
    assert info.value.code == 0 and capsys.readouterr().out.startswith("damper ")
    from damper.cli import _text

    assert _text(ValueError("T = np.float64(7.0) falls below np.float64(8.5)")) == "T = 7.0 falls below 8.5"


def test_a_warning_repeated_by_its_cause_prints_once(capsys, monkeypatch):
    import warnings

    from damper.cli import _one_line_warnings

    monkeypatch.setattr(warnings, "showwarning", warnings.showwarning)
    _one_line_warnings("frf")
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        for _ in range(5):
            np.float64(1e300) * np.float64(1e300)
    err = capsys.readouterr().err
    assert err.count("overflow") == 1 and err.startswith("damper frf: warning:")


def test_input_stage_cases_run_and_classify(tmp_path):
    from damper.stress import inputs

    rows = inputs.run(log=lambda s: None, match=["omega 1 1e300", "elements wobble", "scene loopamp",
                                                 "clear a folder of the user's", "npz negM"])
    assert len(rows) == 5 and all(r["ok"] and r["outcome"] == "clear_error" for r in rows), rows


def test_the_fork_runner_detects_a_traceback_and_a_hang(tmp_path, monkeypatch):
    from damper.cli import loop
    from damper.stress import forkrun

    (tmp_path / "a").mkdir()
    monkeypatch.setattr(loop, "run", lambda args: {}["boom"])          # a bug: KeyError
    r = forkrun.run(["loop", "--curve", "x.json", "--amplitude", "1"], tmp_path / "a", 20.0)
    assert r.code == 1 and "Traceback (most recent call last)" in r.stderr and "KeyError" in r.stderr
    pid_file = tmp_path / "hung.pid"
    monkeypatch.setattr(loop, "run", lambda args: (pid_file.write_text(str(os.getpid())), time.sleep(60)))
    r = forkrun.run(["loop", "--curve", "x.json", "--amplitude", "1"], tmp_path / "a", 3.0)
    # the time limit ended it (no exit code), and the hung child is gone, not waited on
    assert r.code is None and gone_after_kill(int(pid_file.read_text()))


def test_scene_problems_found_before_any_work_name_their_key_and_line(tmp_path):
    from damper.scene import SceneError

    np.savez(tmp_path / "m.npz", M=np.eye(2), K=np.array([[2.0, -1.0], [-1.0, np.nan]]), force=np.ones(2))
    text = BACKBONE.replace('model = "two_dof"', 'model = "matrices"\nmatrices = "m.npz"\nelement_dofs = [7]')
    for key in ("m_tip", "m_platform", "k_blade", "k_disk", "zeta"):
        text = "\n".join(ln for ln in text.splitlines() if not ln.startswith(key))
    with pytest.raises(SceneError) as info:
        parse_scene(text, "bb.toml", base=tmp_path)
    msg = str(info.value)
    assert "bb.toml:12: structure.matrices:" in msg and "K must be finite, got nan at entry (1, 1)" in msg
    assert json.dumps(msg)  # one message, all problems of the file


def test_write_errors_name_the_target_never_the_temporary_file(tmp_path):
    (tmp_path / "adir").mkdir()
    (tmp_path / "afile").write_text("x")
    for target in (tmp_path / "adir", tmp_path / "afile" / "r.json"):
        with pytest.raises(OSError) as info:
            atomic_write(target, "{}")
        assert str(target) in str(info.value) and ".tmp" not in str(info.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir", "afile"]
    assert damper(["frf", "--model", "sdof", "--omega", "0.9", "1.1", "--out", str(tmp_path / "adir")]) == 2
