"""Fixtures of the application tests: a small scene run once per session into a shared cache."""
import pytest
from apphelpers import SMALL


@pytest.fixture(scope="session")
def small_run(tmp_path_factory):
    """(store, out folder, RunRecord) of the small scene, computed once for the session."""
    from damper.cache import Store
    from damper.run.runner import run_scene
    from damper.scene import load_scene

    root = tmp_path_factory.mktemp("small_run")
    store = Store(root / "cache")
    out = root / "out"
    rec = run_scene(load_scene(SMALL), store, out, echo=lambda text: None)
    return store, out, rec

