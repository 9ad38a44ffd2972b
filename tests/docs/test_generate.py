"""docs/tools/generate.py: the "More" list of the user guide holds only pages no index names."""
import importlib.util
import shutil
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _generate():
    """docs/tools/generate.py, with its folder on the path (it imports its sibling tables.py)."""
    spec = importlib.util.spec_from_file_location("generate", DOCS / "tools" / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _copy_pages(tmp_path):
    (tmp_path / "user").mkdir()
    for p in [*DOCS.glob("*.md"), *(DOCS / "user").glob("*.md")]:
        shutil.copy(p, tmp_path / p.relative_to(DOCS))


@pytest.fixture(autouse=True)
def _tools_on_path(monkeypatch):
    monkeypatch.syspath_prepend(str(DOCS / "tools"))


def test_every_page_an_index_names_is_listed_once(tmp_path):
    """Each page of docs/ and docs/user/ is in a toctree of index.md or user/index.md, so
    the "More" list is empty (a page in both would show twice in the contents)."""
    _copy_pages(tmp_path)
    _generate().more_pages(tmp_path)
    assert (tmp_path / "_generated" / "more.md").read_text() == ""


def test_a_page_no_index_names_goes_to_more(tmp_path):
    _copy_pages(tmp_path)
    (tmp_path / "user" / "new_stage.md").write_text("# New stage\n")
    (tmp_path / "notes.md").write_text("# Notes\n")
    _generate().more_pages(tmp_path)
    more = (tmp_path / "_generated" / "more.md").read_text()
    assert "\nnew_stage\n" in more and "\n../notes\n" in more and "mistuning" not in more


def _plots():
    spec = importlib.util.spec_from_file_location("plots", DOCS / "tools" / "plots.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: The eight bytes every PNG file starts with.
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_accuracy_figures_one_per_model_class_from_the_recorded_data(tmp_path):
    (tmp_path / "data").mkdir()
    plots = _plots()
    for name in plots.SOURCES:
        shutil.copy(DOCS / "data" / f"{name}.json", tmp_path / "data")
    plots.accuracy_plots(tmp_path)
    md = (tmp_path / "_generated" / "accuracy_plots.md").read_text()
    for stem, _, _ in plots.CLASSES:
        png = tmp_path / "_generated" / f"accuracy_{stem}.png"
        assert png.read_bytes()[:8] == PNG_SIGNATURE
        assert f"{{figure}} /_generated/accuracy_{stem}.png" in md


def test_accuracy_figures_without_data_say_how_to_record_it(tmp_path):
    _plots().accuracy_plots(tmp_path)
    assert "make docs-accuracy" in (tmp_path / "_generated" / "accuracy_plots.md").read_text()
    assert not list((tmp_path / "_generated").glob("*.png"))
