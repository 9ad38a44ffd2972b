"""Per-direction condensation cache: a tangential run after a normal run on the same bodies
loads the normal (z) blocks and builds only the tangential (x) ones; progress callbacks."""
import io
import json

import numpy as np
import pytest

from contact_core.condense import condense, direction_key
from contact_core.spec import ContactSpec
from damper.cache import Store
from damper.cli import main as damper
from damper.run.progress import Progress

SPEC = ContactSpec(body="sphere", model="halfspace", grid=5)


@pytest.mark.slow  # > 1 s: outside the `-m "not slow"` inner loop
def test_tangential_after_normal_builds_only_x_and_equals_uncached_run(tmp_path):
    store = Store(tmp_path)
    normal = condense(SPEC, ("z",), cache=store)
    assert normal.meta["cache"]["hits"] == {"z": False} and not normal.meta["cache"]["hit"]
    assert store.contains(direction_key(SPEC, "z")) and not store.contains(direction_key(SPEC, "x"))
    steps = []
    both = condense(SPEC, ("z", "x"), cache=store, progress=lambda *a: steps.append(a))
    assert both.meta["cache"]["hits"] == {"z": True, "x": False} and not both.meta["cache"]["hit"]
    assert both.meta["cache"]["keys"]["z"] == normal.meta["cache"]["keys"]["z"]
    # only x condensed: mesh, two assemblies, one condensation per body
    assert [s[2] for s in steps] == ["mesh", "assembly body 1", "condensation body 1 x",
                                     "assembly body 2", "condensation body 2 x"]
    assert [s[:2] for s in steps] == [(k, 5) for k in range(1, 6)]
    again = condense(SPEC, ("z", "x"), cache=store, progress=lambda *a: steps.append(a))
    assert again.meta["cache"]["hit"] and len(steps) == 5          # nothing built, no calls
    fresh = condense(SPEC, ("z", "x"), cache=False)
    for cc in (both, again):                                       # bit for bit
        for name in ("Czz", "Cxx", "rigid", "probe_C1", "probe_x"):
            a, b = getattr(cc, name), getattr(fresh, name)
            assert (a is None and b is None) or np.array_equal(a, b), name
        assert np.array_equal(cc.grid.h, fresh.grid.h) and np.array_equal(cc.grid.area, fresh.grid.area)


def test_cli_tangential_after_normal_reuses_the_normal_blocks(tmp_path, capsys):
    body = ["--body", "sphere", "--radius", "0.01", "--model", "halfspace", "--grid", "5",
            "--cache-dir", str(tmp_path)]
    assert damper(["normal", *body, "--force", "100", "--json"]) == 0
    (z_entry,) = (p for p, _ in Store(tmp_path).entries())
    z_bytes = z_entry.read_bytes()
    assert Store(tmp_path).get(Store.key_of(z_entry))[1]["directions"] == ["z"]
    assert damper(["tangential", *body, "--force", "100", "--mu", "0.5", "--json"]) == 0
    capsys.readouterr()
    # one entry per direction: the second command added x and left the z entry untouched
    entries = {Store.key_of(p): Store(tmp_path).get(Store.key_of(p))[1]["directions"]
               for p, _ in Store(tmp_path).entries()}
    assert sorted(entries.values()) == [["x"], ["z"]] and entries[Store.key_of(z_entry)] == ["z"]
    # a rebuilt z entry would differ (its meta holds the build's timings); the Store's LRU
    # touches the file's time on a hit, so the bytes are compared, not the mtime
    assert z_entry.read_bytes() == z_bytes


def test_march_reports_load_steps_and_plain_progress_prints_quarters():
    from contact_core import tangential_run

    steps = []
    tangential_run.run(SPEC, 0.5, force=100.0, model="halfspace", cache=False,
                       progress=lambda *a: steps.append(a))
    march = [s for s in steps if s[2].startswith("load step")]
    assert len(march) > 4 and march[-1][:2] == (100, 100)
    done = [s[0] for s in march]
    assert done == sorted(done)                                    # travel only grows
    err = io.StringIO()
    p = Progress(1, stream=err, out=io.StringIO())
    p.start("tangential:x", "compute")
    for s in march:
        p.step(*s)
    p.close()
    lines = [ln for ln in err.getvalue().splitlines() if "load step" in ln]
    assert 1 <= len(lines) <= 4 and lines[-1].startswith("    tangential:x: 100/100")
    json.dumps(steps)                                              # plain numbers and text
