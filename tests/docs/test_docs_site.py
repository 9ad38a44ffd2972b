"""The documentation site (``make docs``) in a real headless browser, and its sources.

Chromium (``make browser``) loads a probe page that frames a page of the built site
and reads every image (loaded? natural size as decoded) and every link (resolved
address); the test then checks that no image is broken and that every internal link
points at a file of the site and, with a fragment, at an element of that id. It also
takes a screenshot of each page (``build/docs/screenshots/``) and checks it is a real
picture. ``make test`` builds the site before pytest runs; without a built site these
tests skip with the command that builds it.
"""
from __future__ import annotations

import html
import importlib
import os
import re
import shutil
import struct
import subprocess
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

ROOT = Path(__file__).resolve().parents[2]
SITE = ROOT / "build" / "docs" / "html"
SHOTS = ROOT / "build" / "docs" / "screenshots"
BROWSER = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
#: The start page and one gallery page with figures the example wrote.
PAGES = ("index.html", "auto_examples/masing_loops.html")
#: A screenshot smaller than this is blank or an error page (measured: ~100 kB for a page).
MIN_SHOT_BYTES = 20_000

PROBE = """<!DOCTYPE html><html><body><pre id="out">pending</pre>
<iframe id="f" src="{page}" width="1280" height="900"></iframe>
<script>
document.getElementById('f').onload = function () {{
  var d = this.contentDocument, rows = [];
  for (var i = 0; i < d.images.length; i++) {{
    var im = d.images[i];
    rows.push('IMG ' + im.src + ' ' + im.complete + ' ' + im.naturalWidth + ' ' + im.naturalHeight);
  }}
  var a = d.getElementsByTagName('a');
  for (var i = 0; i < a.length; i++) if (a[i].href) rows.push('LINK ' + a[i].href);
  rows.push('TITLE ' + d.title);
  document.getElementById('out').textContent = rows.join('\\n');
}};
</script></body></html>
"""

needs_site = pytest.mark.skipif(not (SITE / "index.html").exists(),
                                reason="no built site: `make docs` builds build/docs/html")
needs_browser = pytest.mark.skipif(BROWSER is None,
                                   reason="no Chromium found (make browser installs it with apt-get as root)")


def _chromium(*args: str) -> str:
    return subprocess.run([BROWSER, "--headless", "--no-sandbox", "--disable-gpu", "--allow-file-access-from-files",
                           "--virtual-time-budget=10000", *args], capture_output=True, text=True,
                          timeout=120).stdout


def _probe(page: str) -> str:
    probe = SITE / f"_probe_{page.replace('/', '_')}"
    probe.write_text(PROBE.format(page=page))
    try:
        return html.unescape(_chromium("--dump-dom", probe.as_uri()))
    finally:
        probe.unlink()


def _ids(path: Path) -> set[str]:
    return set(re.findall(r'\bid="([^"]+)"', path.read_text(errors="replace")))


@pytest.mark.slow
@needs_site
@needs_browser
@pytest.mark.parametrize("page", PAGES)
def test_page_has_no_broken_image_or_internal_link(page):
    dom = _probe(page)
    images = re.findall(r"IMG (\S+) (\w+) (\d+) (\d+)", dom)
    links = re.findall(r"LINK (\S+)", dom)
    assert "TITLE" in dom and links, f"the probe did not read {page}: {dom[:300]}"
    for src, complete, w, h in images:
        assert complete == "true" and int(w) > 0 and int(h) > 0, f"broken image on {page}: {src}"
    if page.startswith("auto_examples/"):   # the example's own figures are on its page
        assert sum("/_images/" in src for src, *_ in images) >= 1
    internal = [u for u in links if urlparse(u).scheme == "file"]
    assert len(internal) > 10
    for url in internal:
        parts = urlparse(url)
        target = Path(unquote(parts.path))
        assert target.exists(), f"{page} links to a missing file: {url}"
        if parts.fragment and target.suffix == ".html":
            assert unquote(parts.fragment) in _ids(target), f"{page} links to a missing anchor: {url}"


@pytest.mark.slow
@needs_site
@needs_browser
@pytest.mark.parametrize("page", PAGES)
def test_page_screenshot_is_a_picture(page):
    SHOTS.mkdir(parents=True, exist_ok=True)
    shot = SHOTS / (page.replace("/", "_").replace(".html", ".png"))
    shot.unlink(missing_ok=True)
    _chromium("--window-size=1280,900", "--hide-scrollbars", f"--screenshot={shot}", (SITE / page).as_uri())
    data = shot.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > MIN_SHOT_BYTES
    width, height = struct.unpack(">II", data[16:24])
    assert (width, height) == (1280, 900)


@pytest.mark.slow
@needs_site
@needs_browser
def test_equations_render_offline():
    """MathJax is part of the site (sphinx-mathjax-offline): a method page typesets its
    equations without network (each becomes an mjx-container element)."""
    dom = _chromium("--dump-dom", (SITE / "method" / "hb_aft.html").as_uri())
    assert dom.count("<mjx-container") >= 10
    assert 'class="math notranslate nohighlight">\\[' not in dom   # no display equation left as TeX


@needs_site
def test_no_page_shows_an_error_box():
    """A markup error that Sphinx lets through is rendered into the page as a box: docutils'
    system messages, and the theme's error box over a local table of contents (the theme
    lists a page's sections itself); none may reach a reader."""
    bad = [str(p.relative_to(SITE)) for p in SITE.rglob("*.html")
           if re.search(r'class="system-message"|class="[^"]*\bcontents\b', p.read_text(errors="replace"))]
    assert not bad, bad


@needs_site
def test_generated_pages_name_their_revision_and_command():
    for name, command in (("validation", "make validation"), ("performance", "damper bench"),
                          ("stability", "damper stress")):
        text = html.unescape(re.sub(r"<[^>]+>", "", (SITE / f"{name}.html").read_text()))
        assert re.search(r"at revision [0-9a-f]{7,}", text), name
        assert re.search(rf"by\s+(\S*/)?{command}", text), name   # the stamp's command line


#: {py:mod}`name`, {py:func}`name`, ... in the Markdown pages.
ROLE = re.compile(r"\{py:(mod|func|class|meth|attr|data)\}`~?([^`]+)`")  # ~: last part shown


def _resolve(target: str):
    """Import the longest module prefix of ``target`` and walk the rest as attributes."""
    parts = target.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            obj = getattr(obj, name)
        return obj
    raise ImportError(target)


def test_every_code_reference_in_the_pages_exists():
    """Sphinx does not report a Python cross-reference that resolves to nothing (the pages
    link to the implementing code on every method page), so check each one here."""
    refs = {m.group(2) for p in (ROOT / "docs").rglob("*.md") if "_generated" not in p.parts
            for m in ROLE.finditer(p.read_text())}
    assert len(refs) > 40
    missing = []
    for target in sorted(refs):
        try:
            _resolve(target)
        except (ImportError, AttributeError):
            missing.append(target)
    assert not missing, f"references to code that does not exist: {missing}"


#: Project text speaks of the project as it is; history goes to CHANGES.md.
#: (written in pieces, so that this file itself does not match the pattern it checks)
HISTORY = re.compile(r"issue #?[0-9]+|" + "issue" + r"'s|" + r"(this|last|previous) " + "round|"
                     + "previous" + r" release", re.IGNORECASE)


def test_project_text_names_no_issue_numbers_or_rounds():
    skip = {".venv", "build", ".git", "node_modules", "_generated", "auto_examples", "out", ".damper_cache"}
    hits = []
    for folder, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if d not in skip]
        for name in files:
            if not name.endswith((".md", ".py", ".c", ".h")) or name == "CHANGES.md":
                continue
            path = Path(folder) / name
            for i, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                if HISTORY.search(line):
                    hits.append(f"{path.relative_to(ROOT)}:{i}: {line.strip()[:80]}")
    assert not hits, "\n".join(hits)
