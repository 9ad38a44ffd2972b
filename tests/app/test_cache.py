"""The content-addressed Store: round trip, misses, size limit, concurrent writers, the CLI."""
import json
import multiprocessing as mp

import numpy as np
import pytest

from damper.cache import Store, make_key
from damper.cli import main as damper


def test_round_trip_and_keys(tmp_path):
    s = Store(tmp_path)
    a = {"C": np.arange(12.0).reshape(3, 4), "i": np.array([1, 2, 3])}
    key = make_key("stage", {"mu": 0.5}, [1, 2])
    assert key == make_key("stage", {"mu": 0.5}, [1, 2]) != make_key("stage", {"mu": 0.6}, [1, 2])
    assert s.get(key) is None and not s.contains(key)
    s.put(key, a, {"note": "x", "n": 3})
    arrays, meta = s.get(key)
    assert meta == {"note": "x", "n": 3}
    assert all(np.array_equal(arrays[k], a[k]) and arrays[k].dtype == a[k].dtype for k in a)
    assert (s.hits, s.misses, s.writes) == (1, 1, 1)


def test_unreadable_entry_is_a_miss_and_bad_keys_are_refused(tmp_path):
    s = Store(tmp_path)
    s.path("abc").parent.mkdir(parents=True, exist_ok=True)
    s.path("abc").write_bytes(b"not a zip file")
    assert s.get("abc") is None
    for bad in ("", "../x", "a/b", "A B"):
        with pytest.raises(ValueError):
            s.path(bad)
    with pytest.raises(ValueError):
        s.put("k", {"meta": np.zeros(1)}, {})
    with pytest.raises(ValueError):                   # NaN never enters the cache as "a number"
        s.put("k", {}, {"x": float("nan")})


def test_size_limit_evicts_least_recently_used(tmp_path):
    blob = {"x": np.zeros(1000)}                      # ~8 kB per entry
    size = len(np.zeros(1000).tobytes())
    s = Store(tmp_path, max_bytes=int(3.5 * size) + 3000)   # room for three entries, not four
    for i in range(3):
        s.put(f"k{i}", blob, {"i": i})
    import os
    import time

    os.utime(s.path("k0"), (time.time() + 10, time.time() + 10))   # k0 used last
    s.put("k3", blob, {"i": 3})          # over the limit: k1, the least recently used, goes
    assert s.contains("k0") and s.contains("k3") and not s.contains("k1") and s.contains("k2")
    assert s.info()["bytes"] <= s.max_bytes
    assert s.info()["entries"] == 3
    assert s.clear() == 3 and s.info()["entries"] == 0


def _writer(folder, worker, rounds):
    s = Store(folder)
    for r in range(rounds):
        # the same key from every worker (same content) and one key per worker
        s.put("shared", {"x": np.arange(20000.0)}, {"v": 1})
        s.put(f"w{worker}_{r % 3}", {"x": np.full(5000, float(worker))}, {"w": worker})
        got = s.get("shared")
        assert got is not None and np.array_equal(got[0]["x"], np.arange(20000.0))


def test_concurrent_writers_never_corrupt(tmp_path):
    procs = [mp.get_context("fork").Process(target=_writer, args=(tmp_path, w, 30)) for w in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
    assert all(p.exitcode == 0 for p in procs)
    s = Store(tmp_path)
    assert s.info()["entries"] == 1 + 4 * 3
    for w in range(4):
        for r in range(3):
            arrays, meta = s.get(f"w{w}_{r}")
            assert meta == {"w": w} and np.all(arrays["x"] == w)
    assert not list(tmp_path.glob(".*.tmp"))          # no temporary file left behind


def test_cache_cli_info_and_clear(tmp_path, capsys):
    s = Store(tmp_path)
    s.put("a1", {"x": np.zeros(10)}, {})
    assert damper(["cache", "info", "--json", "--cache-dir", str(tmp_path)]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["entries"] == 1 and info["bytes"] > 0
    assert damper(["cache", "clear", "--cache-dir", str(tmp_path)]) == 0
    assert "removed 1" in capsys.readouterr().out
    assert Store(tmp_path).info()["entries"] == 0
    assert damper(["cache", "info", "--cache-max-mb", "-1", "--cache-dir", str(tmp_path)]) == 2


@pytest.mark.slow
def test_two_concurrent_runs_of_one_scene_share_the_cache_safely(tmp_path):
    import subprocess
    import sys

    from apphelpers import SMALL

    scene = tmp_path / "s.toml"
    scene.write_text(SMALL.read_text().replace('want = ["virgin_curve", "k_t", "loop", "frf", "report"]',
                                               'want = ["virgin_curve", "loop"]'))
    code = "import sys; from damper.cli import main; sys.exit(main(sys.argv[1:]))"
    cmd = [sys.executable, "-c", code, "run", str(scene), "--json", "--cache-dir", str(tmp_path / "cache")]
    procs = [subprocess.Popen(cmd + ["--out", str(tmp_path / f"out{i}")], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for i in range(2)]
    outs = [p.communicate(timeout=600) for p in procs]
    assert all(p.returncode == 0 for p in procs), [e for _, e in outs]
    curves = [json.loads((tmp_path / f"out{i}" / "tangential_damper" / "curve.json").read_text()) for i in range(2)]
    for c in curves:
        c.pop("provenance")                          # holds the time each run computed it
    assert curves[0] == curves[1]
    store = Store(tmp_path / "cache")
    for path, _ in store.entries():                   # every entry whole and readable
        assert store.get(Store.key_of(path), stage=None) is not None or store.get(
            Store.key_of(path), stage=json.loads(str(np.load(path)["meta"]))["stage"]) is not None
    assert not list((tmp_path / "cache").glob(".*.tmp"))
    third = json.loads(subprocess.run(cmd + ["--out", str(tmp_path / "out3")], capture_output=True,
                                      text=True, check=True).stdout)
    assert {s["action"] for s in third["stages"]} <= {"cached", "skip"}


def test_a_folder_started_by_the_contact_core_cache_is_the_stores_too(tmp_path):
    """contact_core's DiskCache and the damper store share the default folder: one that
    the library's cache started carries the tag, so the store uses it instead of refusing
    it as a user's folder (a gallery run of two examples met that refusal)."""
    import numpy as np

    from contact_core.cache import DiskCache
    from damper.cache import Store, is_cache_folder

    folder = tmp_path / "shared"
    DiskCache(folder).put("abc", {"a": np.ones(2)}, {"m": 1})
    assert is_cache_folder(folder)
    store = Store(folder).prepare()
    store.put("k1", {"x": np.zeros(3)}, {"n": 2})
    assert store.get("k1")[1] == {"n": 2}
    assert DiskCache(folder).get("abc")[1] == {"m": 1}


def test_the_contact_core_cache_does_not_tag_a_folder_of_yours(tmp_path):
    """A folder that already holds other files gets entries but no tag (it may be the user's)."""
    import numpy as np

    from contact_core.cache import TAG_NAME, DiskCache

    (tmp_path / "notes.txt").write_text("mine")
    DiskCache(tmp_path).put("abc", {"a": np.ones(2)}, {})
    assert not (tmp_path / TAG_NAME).exists()
