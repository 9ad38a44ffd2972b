"""The example gallery's settings: which arguments each example runs with, and its plots.

Every script in ``examples/`` runs in the documentation build (sphinx-gallery); the build
fails when one raises or exits with a non-zero code. :data:`ARGS` gives each script its
command line there: the long ones run in their quick mode (the same code on smaller
sizes), and every script writes its files into ``build/docs/gallery_out/<name>/``,
whose PNG files become the page's figures (:func:`png_scraper`). A script missing from
:data:`ARGS` runs without arguments. The build starts no process pool and no Dask
cluster: the arguments keep such examples in this process (``--workers 1``, quick modes
that run their samples serially).
"""
from __future__ import annotations

import ast
import atexit
import os
import shutil
import sys
from pathlib import Path

#: Where the examples write their files during the build (the scraper reads PNGs here).
OUT: Path = Path(__file__).resolve().parents[2] / "build" / "docs" / "gallery_out"

#: Command line of each example in the build. ``{out}`` is the example's own output folder.
#: Why each quick mode: the full run is a benchmark or study of minutes to hours (its
#: docstring says how to run it); the quick mode runs the same code paths on small sizes.
ARGS: dict[str, list[str]] = {
    "normal_validation.py": ["--out", "{out}"],
    "cylinder_approach.py": ["--out", "{out}", "--grid", "11"],       # thesis grid 21: minutes
    "virgin_curves.py": ["--smoke", "--out", "{out}"],               # 31-node BEM + FE: minutes
    "masing_loops.py": ["--out", "{out}"],
    "contact_surface.py": ["--quick", "--out", "{out}"],             # full: grids 21 and 13
    "frf_sdof.py": ["--out", "{out}"],
    "fmu_closed_loop.py": ["--quick"],                               # 30 cycles x 14 bisections
    "craig_bampton_blade.py": ["--out", "{out}"],
    "upd_geometry_compare.py": ["--quick", "--cache-dir", "{out}/cache"],   # full: ~20 min of TI
    "bench_contact.py": ["--quick", "--out", "{out}"],               # full: grids to 41, minutes
    "bench_contact2d.py": ["--sizes", "3", "16", "--cycles", "3", "--repeats", "1",   # full: about a minute
                           "--fmu-sliders", "4", "--fmu-steps", "2000"],
    "bench_element.py": ["--sizes", "4", "64", "--samples", "2000", "--repeats", "3"],
    "bench_fmu.py": ["--sliders", "3,50", "--steps", "20000", "--py-steps", "2000", "--repeats", "1"],
    "bench_hb.py": ["--smoke"],                                      # full: with solve_ivp, minutes
    "bench_hb_robust.py": ["--smoke"],                               # full map: hours
    "bench_tangential.py": ["--smoke"],                              # full: BEM 61, FE 21
    "bench_upd.py": ["--quick", "--workers", "1", "--out", "{out}"],  # full: ~1 h of TI; no process pool
    "upd_cosim.py": ["--quick", "--out", "{out}"],                   # full: ~15 min of co-simulation
    "upd_surface_timeint.py": ["--quick"],                           # full: ~1 h of ring TI
    "upd_surface_peak.py": ["--quick", "--cf", "600"],               # full: hours (peaks, ring TI)
    "bench_mistuning.py": ["--quick", "--rows", "scaling", "--out", "{out}"],  # full: N_b to 48, Dask: ~15 min
    "mistuning_confidence.py": ["--quick", "--out", "{out}"],        # full: 1000 + 4000 samples, ~30 min
}


def prune_stale(docs: Path) -> list[str]:
    """Remove the gallery's generated files of examples that no longer exist.

    sphinx-gallery writes ``docs/auto_examples/<name>.*`` (and images) per script but never
    deletes them; a removed example would leave a page outside every toctree, which the
    build (warnings as errors) refuses. Returns the names removed.
    """
    gen = docs / "auto_examples"
    if not gen.is_dir():
        return []
    sources = {p.stem for p in (docs.parent / "examples").glob("*.py")}
    stale = sorted({p.name.split(".", 1)[0] for p in gen.glob("*.rst")} - sources - {"index"})
    for name in stale:
        for f in [*gen.glob(f"{name}.*"), *gen.glob(f"images/sphx_glr_{name}_*"),
                  *gen.glob(f"images/thumb/sphx_glr_{name}_*")]:
            f.unlink()
    return stale


def _out(script_vars) -> Path:
    return OUT / Path(script_vars["src_file"]).stem


def reset_argv(gallery_conf, script_vars) -> list[str]:
    """sphinx-gallery hook: the example's arguments (:data:`ARGS`), with a fresh output folder
    and ``__file__``, ``__doc__`` set."""
    name = Path(script_vars["src_file"]).name
    # Scripts find the repository or re-run themselves through __file__, as when run from
    # the command line (sphinx-gallery leaves it undefined).
    src = Path(script_vars["src_file"])
    script_vars["example_globals"]["__file__"] = str(src)
    # ... and their argparse descriptions from __doc__ (sphinx-gallery blanks it).
    script_vars["example_globals"]["__doc__"] = ast.get_docstring(ast.parse(src.read_text()), clean=False)
    out = _out(script_vars)
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True, exist_ok=True)
    return [a.replace("{out}", str(out)) for a in ARGS.get(name, [])]


class _ExampleExit(RuntimeError):
    """An example called ``sys.exit`` with a failure code."""


_real_exit = sys.exit
#: The example running now (set and cleared by :func:`reset_exit`).
_running: list[str] = []


def _exit(code=0):
    """``sys.exit`` inside an example: success returns (the call is the script's last line),
    failure raises, so the gallery reports the example as failed and the build stops."""
    if code not in (0, None):
        raise _ExampleExit(f"the example exited with code {code!r}")


def reset_exit(gallery_conf, fname, when):
    """sphinx-gallery hook (before and after each example): route ``sys.exit`` through
    :func:`_exit` while an example runs (a ``SystemExit`` would end the whole build)."""
    sys.exit = _exit if when == "before" else _real_exit
    if when == "before":
        _running[:] = [str(fname)]
    else:
        _running.clear()


def _ended_inside_an_example() -> None:
    """At interpreter exit: an example that raised SystemExit itself (not through sys.exit)
    ends the whole build, with exit code 0; turn that into a failure that names it."""
    if _running:
        print(f"gallery: the build ended inside the example {_running[0]} (SystemExit raised "
              "directly): use sys.exit(main()) there", file=sys.stderr, flush=True)
        os._exit(1)


atexit.register(_ended_inside_an_example)


def png_scraper(block, block_vars, gallery_conf):
    """sphinx-gallery image scraper: the PNG files the example wrote into its folder.

    Each file is reported once (the first code block after it appeared), in name order.
    """
    from sphinx_gallery.scrapers import figure_rst

    out = _out({"src_file": block_vars["src_file"]})
    seen = block_vars.setdefault("_pngs_seen", set())
    new = sorted(p for p in out.rglob("*.png") if p not in seen)
    paths = []
    for src, dest in zip(new, block_vars["image_path_iterator"]):
        shutil.copyfile(src, dest)
        seen.add(src)
        paths.append(dest)
    return figure_rst(paths, gallery_conf["src_dir"])


def config(root: Path, docs: Path) -> dict:
    """The ``sphinx_gallery_conf`` of ``docs/conf.py``."""
    return {
        "examples_dirs": str(root / "examples"),
        "gallery_dirs": str(docs / "auto_examples"),
        "filename_pattern": r".*\.py$",              # run every example
        "ignore_pattern": r"__init__\.py",
        "reset_argv": "gallery.reset_argv",
        "reset_modules": ("matplotlib", "gallery.reset_exit"),
        "reset_modules_order": "both",
        "image_scrapers": ("matplotlib", "gallery.png_scraper"),
        "abort_on_example_error": True,
        "only_warn_on_example_error": False,
        "download_all_examples": False,
        "remove_config_comments": True,
        "plot_gallery": "True",
        "within_subsection_order": "FileNameSortKey",
        "show_memory": False,
        "backreferences_dir": None,
        "capture_repr": (),
    }
