"""Package the friction element as an FMI 2.0 or 3.0 co-simulation FMU.

An FMU holds: ``modelDescription.xml`` (from the variable table in
:mod:`fmu_src.fmu_xml`), the virgin curve as ``resources/curve.txt``, the C
sources (the FMI wrapper of ``fmu_src/fmi`` and the core ``fmu_src/core``,
so ``fmpy compile`` can rebuild it: FMI 2 ``<SourceFiles>``, FMI 3
``sources/buildDescription.xml``) and a Linux binary compiled from those very
sources (``binaries/linux64/damper.so`` or ``binaries/x86_64-linux/damper.so``).

The curve is checked by building the element through :mod:`fmu_src.element`
(the same C code the FMU runs), so a curve the FMU would refuse is refused here
with a ``ValueError`` and no file is written. The ``.fmu`` is written through a
temporary file and a rename: never half-written.

Run ``python -m fmu_src.fmu_build --write-header`` after changing a variable
table to regenerate ``fmu_src/fmi/damper_vr.h`` and ``point_vr.h``. The contact-point
FMU (2D element + normal law) is packaged by :mod:`fmu_src.fmu_point` with the same
helpers.
"""
from __future__ import annotations

import argparse
import io
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from contact_core.fileio import atomic_write
from fmu_src import fmu_xml

FMI_DIR = Path(__file__).resolve().parent / "fmi"
CORE_DIR = Path(__file__).resolve().parent / "core"
HEADER_PATH = FMI_DIR / "damper_vr.h"

#: Model hooks available to the wrapper (model.h): the element, the contact point, a
#: baseline, a linear blade (fmu_src.blade_fmu) and an underplatform damper (fmu_src.upd_fmu).
MODELS = {"iwan": "model_iwan.c", "passthrough": "model_passthrough.c", "point": "model_point.c",
          "blade": "model_blade.c", "upd": "model_upd.c"}
#: Binary folder of each FMI version on 64-bit Linux.
PLATFORM = {2: "linux64", 3: "x86_64-linux"}
#: How a curve table that is not concave is handled (iwan.h iwan_fit).
FIT_MODES = ("reject", "concave")
_FMI_HEADERS = {
    2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
    3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h"),
}
_WRAPPER_HEADERS = ("fmu_instance.h", "fmu_internal.h", "model.h", "model_table.h")
#: Input bound of the Iwan model (model_iwan.c U_BOUND_RTOL): the force error of a
#: slider, about k eps |u|, stays below this fraction of its slip strength.
U_BOUND_RTOL = 1e-6
#: The friction-law core compiled into every FMU (fmu_src/core), and its headers.
CORE_SOURCES = ("iwan.c", "iwan_periodic.c")
CORE_HEADERS = ("iwan.h", "iwan_internal.h", "iwan_sweep.h")
#: What the contact point adds to the core (the 2D element and the normal law).
POINT_SOURCES = ("iwan2d.c", "contact_point.c")
POINT_HEADERS = ("iwan2d.h", "iwan2d_internal.h", "contact_point.h")


def core_files(model: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(C sources, headers) of fmu_src/core compiled into the FMU of ``model``."""
    if model == "point":
        return CORE_SOURCES + POINT_SOURCES, CORE_HEADERS + POINT_HEADERS
    if model == "blade":
        return (), ()
    return CORE_SOURCES, CORE_HEADERS
#: The one compile-flag list shared with CMake and the pip extension (one flag a line).
CFLAGS_FILE = CORE_DIR / "cflags.txt"


def shared_cflags() -> tuple[str, ...]:
    """Flags of ``fmu_src/core/cflags.txt`` (comments and blank lines skipped)."""
    lines = (line.strip() for line in CFLAGS_FILE.read_text().splitlines())
    return tuple(line for line in lines if line and not line.startswith("#"))


#: Flags of the binary inside the FMU: the shared list plus those of a shared library.
CFLAGS = (*shared_cflags(), "-fPIC", "-shared", "-fvisibility=hidden", "-Wl,--no-undefined")


def c_sources(fmi_version: int, model: str = "iwan") -> list[str]:
    """Names of the C files compiled into the FMU (all flat in ``sources/``)."""
    _check_version(fmi_version)
    if model not in MODELS:
        raise ValueError(f"model must be one of {sorted(MODELS)}, not {model!r}")
    # model_table.c: the resource files' reader and opener, which every model uses
    return [f"fmi{fmi_version}.c", "fmu_instance.c", "fmu_state.c", MODELS[model], "model_table.c",
            *core_files(model)[0]]


def _check_version(fmi_version: int) -> None:
    if fmi_version not in PLATFORM:
        raise ValueError(f"--fmi-version must be 2 or 3, not {fmi_version!r}")


def check_curve(u, T, n_ref: float, fit: str = "reject", tail: str = "slope"):
    """Validate a virgin curve by building the element from it.

    Parameters
    ----------
    u, T : array_like, shape (m,)
        Virgin curve: displacement [m] and tangential force [N].
    n_ref : float
        Normal load the curve was computed at [N], > 0.
    fit : {"reject", "concave"}
        A non-concave table is an error, or is replaced by its concave majorant.
    tail : {"slope", "flat"}
        What follows the last point (see :meth:`IwanElement.from_curve`).

    Returns
    -------
    (u, T) : tuple of ndarray, shape (m,)
        The table as float arrays.

    Raises
    ------
    ValueError
        Non-finite, non-positive load, bad table, or not concave with ``fit="reject"``.
    """
    from fmu_src.element import IwanElement  # the FMU's own C core, via ctypes

    if fit not in FIT_MODES:
        raise ValueError(f"fit must be one of {FIT_MODES}, not {fit!r}")
    u = np.asarray(u, dtype=float).ravel()
    T = np.asarray(T, dtype=float).ravel()
    if u.shape != T.shape or u.size < 2:
        raise ValueError(f"curve needs u and T of equal length >= 2, got {u.size}, {T.size}")
    if u.size + (tail == "flat") > 4096:  # FMU_MAX_CURVE_POINTS in fmu_instance.h
        raise ValueError(f"curve has {u.size} points; the FMU reads at most 4096 "
                         "(reduce it: fmu_src.curve_fit.prepare_table)")
    if not (np.isfinite(n_ref) and n_ref > 0):
        raise ValueError(f"reference normal load must be finite and > 0, got {n_ref!r}")
    IwanElement.from_curve(u, T, float(n_ref), fit=fit, tail=tail)
    return u, T


def curve_resource_text(u, T, n_ref: float, fit: str) -> str:
    """Text of ``resources/curve.txt``, read by ``read_curve`` in fmu_instance.c.

    Numbers are written with ``repr`` (17 significant digits at most), which
    ``strtod`` reads back to the identical double.
    """
    lines = ["damper-curve 1", f"n_ref {float(n_ref)!r}", f"fit {FIT_MODES.index(fit)}",
             f"points {len(u)}"]
    lines += [f"{float(a)!r} {float(b)!r}" for a, b in zip(u, T)]
    return "\n".join(lines) + "\n"


def _copy_sources(dest: Path, fmi_version: int, model: str,
                  iface: fmu_xml.Interface | None = None) -> list[str]:
    """Copy the C sources and headers flat into ``dest`` (with the model's variable
    table and the fmu_vars.h that picks it); return the .c names. ``iface`` (default:
    the model's committed one) is written from its table when it has no committed header."""
    dest.mkdir(parents=True)
    names = c_sources(fmi_version, model)
    sources, headers = core_files(model)
    iface = fmu_xml.INTERFACES[model] if iface is None else iface
    committed = iface in HEADERS.values()
    for name in names + list(_WRAPPER_HEADERS + headers) + ([iface.header] if committed else []):
        src = CORE_DIR if name in sources + headers else FMI_DIR
        shutil.copy(src / name, dest / name)
    if not committed:
        (dest / iface.header).write_text(fmu_xml.render_vr_header(iface))
    (dest / "fmu_vars.h").write_text(fmu_xml.render_fmu_vars(iface))
    for name in _FMI_HEADERS[fmi_version] + ("LICENSE.txt",):
        shutil.copy(FMI_DIR / "headers" / name,
                    dest / ("FMI_HEADERS_LICENSE.txt" if name == "LICENSE.txt" else name))
    return names


def compile_binary(source_dir: Path, names: list[str], out: Path,
                   compiler: str | None = None, extra_flags: tuple = ()) -> None:
    """Compile ``names`` from ``source_dir`` into the shared library ``out``
    (``extra_flags``: e.g. ``-Werror`` in CI).

    Raises
    ------
    RuntimeError
        The compiler failed (its message is included).
    """
    cc = compiler or os.environ.get("CC", "cc")
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [cc, *CFLAGS, *extra_flags, f"-I{source_dir}", *[str(source_dir / n) for n in names],
           "-o", str(out), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"compiling the FMU binary failed:\n{' '.join(cmd)}\n{proc.stderr}")


def input_bound(element) -> float:
    """Largest |u| [m] the FMU of ``element`` accepts (the same number model_iwan.c computes).

    U_BOUND_RTOL * (smallest slip distance at N_ref, scale 1) / eps: beyond it the
    round-off of a slider force, about k eps |u|, exceeds U_BOUND_RTOL of its slip
    strength (and at about 1/U_BOUND_RTOL times the bound u - z cannot resolve the
    slip distance at all). Infinite for an element without sliders.
    """
    if element.n_sliders == 0:
        return float("inf")
    radii = element.fs / element.k            # rad_j = fs_j / k_j, as iwan.c derives it
    return U_BOUND_RTOL * float(np.min(radii)) / float(np.finfo(float).eps)


def _documentation(u_bound: float) -> str:
    rows = "".join(f"<tr><td>{v.name}</td><td>{v.causality}</td><td>{v.unit}</td>"
                   f"<td>{v.description}</td></tr>" for v in fmu_xml.VARIABLES)
    bound = ("any finite value" if not u_bound < float("inf")
             else f"|u| &lt;= {u_bound!r} m")
    return ("<html><body><h1>damper friction element</h1><p>Masing/Iwan friction element "
            "built from a contact's virgin curve (resources/curve.txt). Outputs follow the "
            "current inputs (direct feedthrough); the history is committed in doStep only. "
            "The input is taken as a straight line between communication points (FMI 2: "
            "with the input derivatives), which the element follows exactly at any step "
            "size.</p><h2>Limits</h2><p>Input bound: " + bound + ". Beyond it double "
            "precision cannot represent the element's smallest slip distance to 1e-6 of its "
            "strength; such inputs are refused with a logged error (also the min/max of u in "
            "the model description). For any accepted input |F| stays within the gross-slip "
            "force (mu N) exactly. A step size must be &gt; 0.</p><h2>Energy</h2><p>The work "
            "of the input displacement equals W + stored_energy at constant N: the outputs "
            "close an importer's energy balance.</p><h2>FMU state</h2><p>Get/Set/Serialize/"
            "Deserialize in every mode; a state carries mode, time and history; a serialized "
            "state is refused unless its checksum and physical invariants hold.</p>"
            "<table><tr><th>name</th><th>causality</th><th>unit</th>"
            f"<th>description</th></tr>{rows}</table></body></html>\n")


def _zip_dir(root: Path) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in sorted(root.rglob("*")):
            if path.is_file():
                zf.write(path, path.relative_to(root).as_posix())
    return buf.getvalue()


def package_fmu(out: str | os.PathLike, fmi_version: int, model: str,
                iface: fmu_xml.Interface, resources: dict, description: str = "",
                documentation: str = "", bounds: dict | None = None,
                compiler: str | None = None) -> Path:
    """Write a co-simulation FMU of ``model`` behind the FMI layer (atomically), for a
    model whose start values are in its table (rules none / zero / one / value).

    Parameters
    ----------
    out : path                 the ``.fmu`` file
    fmi_version : {2, 3}
    model : str                a key of :data:`MODELS`
    iface : fmu_xml.Interface  its variable table (its header is generated into sources/)
    resources : dict           file name -> text, written under ``resources/``
    description, documentation : str
        Model description text; ``documentation/index.html``.
    bounds : dict              input bounds by name (min/max in the model description)
    compiler : str, optional   C compiler (default ``$CC`` or ``cc``)

    Raises
    ------
    RuntimeError
        The compiler failed.
    """
    _check_version(fmi_version)
    with tempfile.TemporaryDirectory(prefix="damper_fmu_") as tmp:
        root = Path(tmp) / "fmu"
        names = _copy_sources(root / "sources", fmi_version, model, iface)
        (root / "resources").mkdir()
        for name, text in resources.items():
            (root / "resources" / name).write_text(text)
        if documentation:
            (root / "documentation").mkdir()
            (root / "documentation" / "index.html").write_text(documentation)
        text = fmu_xml.render_model_description(fmi_version, 0.0, names, description,
                                                iface=iface, bounds=bounds or {})
        (root / "modelDescription.xml").write_text(text)
        if fmi_version == 3:
            (root / "sources" / "buildDescription.xml").write_text(
                fmu_xml.render_build_description(names, iface))
        binary = root / "binaries" / PLATFORM[fmi_version] / f"{iface.model_identifier}.so"
        compile_binary(root / "sources", names, binary, compiler)
        path = atomic_write(out, _zip_dir(root))
    return path


def build_fmu(u, T, n_ref: float, out: str | os.PathLike, fmi_version: int = 2,
              fit: str = "reject", model: str = "iwan", description: str = "",
              compiler: str | None = None, curve_json: str | None = None,
              tail: str = "slope") -> Path:
    """Write a co-simulation FMU of the friction element for one contact.

    Parameters
    ----------
    u, T : array_like, shape (m,)
        Virgin curve [m], [N].
    n_ref : float
        Normal load of the curve [N]: start of the input ``N`` and parameter ``N_ref``.
    out : path
        The ``.fmu`` file (written atomically).
    fmi_version : {2, 3}
    fit : {"reject", "concave"}
        Handling of a non-concave table (see :func:`check_curve`).
    model : {"iwan", "passthrough"}
        ``"passthrough"`` (F = u) is the benchmark's baseline, same wrapper.
    description : str
        Text for the model description (e.g. the curve's source).
    compiler : str, optional
        C compiler (default ``$CC`` or ``cc``).
    curve_json : str, optional
        Text of the source curve file, kept as ``resources/curve.json`` for
        provenance (the binary reads ``resources/curve.txt``).
    tail : {"slope", "flat"}
        Beyond u[-1] (the curve file's ``tail``): ``"flat"`` writes the flat tail of
        :func:`fmu_src.element.flat_tail` into ``resources/curve.txt``, so the FMU
        stays at T[-1] past the end (gross slip), as ``IwanElement.from_curve(...,
        tail="flat")``; ``"slope"`` continues the last slope.

    Returns
    -------
    Path of the written FMU.
    """
    _check_version(fmi_version)
    u, T = check_curve(u, T, n_ref, fit, tail)
    if tail == "flat":
        from fmu_src.element import flat_tail

        u, T = flat_tail(u, T)
    u_bound = float("inf")
    if model == "iwan":
        from fmu_src.element import IwanElement

        u_bound = input_bound(IwanElement.from_curve(u, T, float(n_ref), fit=fit))
    with tempfile.TemporaryDirectory(prefix="damper_fmu_") as tmp:
        root = Path(tmp) / "fmu"
        names = _copy_sources(root / "sources", fmi_version, model)
        (root / "resources").mkdir()
        (root / "resources" / "curve.txt").write_text(curve_resource_text(u, T, n_ref, fit))
        if curve_json is not None:
            (root / "resources" / "curve.json").write_text(curve_json)
        (root / "documentation").mkdir()
        (root / "documentation" / "index.html").write_text(_documentation(u_bound))
        text = fmu_xml.render_model_description(fmi_version, n_ref, names, description,
                                                u_bound if model == "iwan" else None)
        (root / "modelDescription.xml").write_text(text)
        if fmi_version == 3:
            (root / "sources" / "buildDescription.xml").write_text(
                fmu_xml.render_build_description(names))
        binary = root / "binaries" / PLATFORM[fmi_version] / f"{fmu_xml.MODEL_IDENTIFIER}.so"
        compile_binary(root / "sources", names, binary, compiler)
        path = atomic_write(out, _zip_dir(root))
    return path


#: The generated variable headers, one per interface.
HEADERS = {FMI_DIR / i.header: i for i in (fmu_xml.DAMPER, fmu_xml.POINT)}


def header_is_current() -> bool:
    """Whether the committed variable headers equal the generated texts."""
    return all(path.read_text() == fmu_xml.render_vr_header(i) for path, i in HEADERS.items())


def main(argv: list[str] | None = None) -> int:
    """``python -m fmu_src.fmu_build --write-header | --check-header``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--write-header", action="store_true",
                       help="regenerate " + ", ".join(p.name for p in HEADERS)
                       + " from the variable tables")
    group.add_argument("--check-header", action="store_true",
                       help="exit 1 if the committed header is out of date")
    args = parser.parse_args(argv)
    if args.write_header:
        for path, iface in HEADERS.items():
            atomic_write(path, fmu_xml.render_vr_header(iface))
        return 0
    if header_is_current():
        return 0
    print("a variable header is out of date: run python -m fmu_src.fmu_build --write-header",
          file=sys.stderr)
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
