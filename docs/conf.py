"""Sphinx configuration of the damper-toolkit documentation (``make docs``).

Built offline: no intersphinx, no remote images, nothing fetched; MathJax is copied into
the site (sphinx-mathjax-offline), so the pages render their equations offline too. Before the build,
``docs/tools/generate.py`` (run below) writes the pages that come from data:
the API module lists (every module of the three libraries and the application),
the validation table (``docs/data/validation.json``), the performance page
(``docs/data/bench.json``) and the stability page (``docs/data/stress.json``), into
``docs/_generated/`` (git-ignored). The gallery runs every script in ``examples/``
(``docs/tools/gallery.py`` gives the quick mode of the slow ones, and removes the pages of
examples that no longer exist) and the build fails when one fails.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

# Make ctypes loading and plotting safe at import time on a headless build machine.
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ["COLUMNS"] = "100"   # the command reference: the same line width on every machine

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE / "tools"))

import gallery  # noqa: E402  (docs/tools/gallery.py)
import generate  # noqa: E402  (docs/tools/generate.py)

generate.all_pages(HERE)
gallery.prune_stale(HERE)   # pages of removed examples (sphinx-gallery keeps them)

project = "damper-toolkit"
author = "the damper-toolkit authors"
copyright = "the damper-toolkit authors, MIT licence"
try:
    from importlib.metadata import version as _version

    release = _version("damper-toolkit")
except Exception:  # noqa: BLE001  (not installed: the docs still build)
    release = "0.1.0"

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinx-mathjax-offline",   # MathJax 3 into _static/mathjax: equations render without network
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "tools", "data", "_generated/*.md", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.codeobj.json", "auto_examples/*.md5",
                    "**/sg_execution_times.rst"]
# config.cache: the gallery's settings hold callables, which Sphinx cannot pickle (harmless).
suppress_warnings = ["config.cache"]

myst_enable_extensions = ["dollarmath", "amsmath", "deflist", "colon_fence"]
myst_heading_anchors = 3

# API reference: numpydoc sections, members in source order, no inherited noise.
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_typehints = "none"          # the numpydoc Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()

html_theme = "furo"
html_title = "damper-toolkit"
html_static_path: list[str] = []
html_extra_path = ["_generated/extra"]   # schemas/*.schema.json: the input files' JSON Schemas
html_show_sourcelink = False
html_last_updated_fmt = None

sphinx_gallery_conf = gallery.config(ROOT, HERE)


# The docstrings write magnitudes as |x| (plain-text mathematics), which reStructuredText
# reads as substitution references. Escape every bar outside literal blocks and tables
# before numpydoc and autodoc parse the docstring.
def _escape_bars(lines: list[str]) -> None:
    literal_indent = None
    for i, line in enumerate(lines):
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if not stripped or indent > literal_indent:
                continue
            literal_indent = None
        if stripped.endswith("::"):
            literal_indent = indent
        if "|" in line and not (stripped.startswith("|") and stripped.endswith("|")):
            lines[i] = line.replace("\\|", "|").replace("|", "\\|")


def _process_docstring(app, what, name, obj, options, lines):
    _escape_bars(lines)


def setup(app):
    app.connect("autodoc-process-docstring", _process_docstring, priority=100)


import warnings  # noqa: E402

# numpydoc reports sections it does not know (e.g. "Class Attributes") as Python warnings;
# they are rendered as plain text, which is what the docstrings mean.
warnings.filterwarnings("ignore", message="Unknown section", category=UserWarning)
