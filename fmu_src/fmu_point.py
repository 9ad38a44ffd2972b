"""Package the 3D contact point as an FMI 2.0 or 3.0 co-simulation FMU.

The contact-point FMU (``fmu_src/fmi/model_point.c`` on ``fmu_src/core/contact_point.h``)
holds the virgin curve (``resources/curve.txt``, as the 1D FMU) and the normal law
(``resources/normal.txt``: the table N(p), a normal approach curve or the penalty table
(0, 0), (1 m, k_n), and the start penetration), the C sources and a Linux binary
``binaries/<platform>/contact_point.so``. Its variables are :data:`fmu_xml.POINT`.

Both tables are checked by building the contact point through
:mod:`fmu_src.contact_point` (the FMU's own C code): a curve or a normal law the FMU
would refuse is refused here (``ValueError``) and nothing is written.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from contact_core.fileio import atomic_write
from fmu_src import fmu_build, fmu_xml

#: Model hooks of the contact point (fmu_build.MODELS).
MODEL = "point"


def normal_resource_text(p, N, p_start: float) -> str:
    """Text of ``resources/normal.txt``, read by ``scan_normal`` in fmu_instance.c."""
    lines = ["damper-normal 1", f"p_start {float(p_start)!r}", f"points {len(p)}"]
    lines += [f"{float(a)!r} {float(b)!r}" for a, b in zip(p, N)]
    return "\n".join(lines) + "\n"


def contact_point(u, T, n_ref: float, p, N, fit: str = "reject", tail: str = "slope"):
    """The :class:`~fmu_src.contact_point.ContactPoint` of the tables (validates them)."""
    from fmu_src.contact_point import ContactPoint
    from fmu_src.element import IwanElement

    u, T = fmu_build.check_curve(u, T, n_ref, fit, tail)
    return ContactPoint(IwanElement.from_curve(u, T, float(n_ref), fit=fit, tail=tail), p, N)


def _documentation(u_bound: float, p_start: float, N_start: float) -> str:
    rows = "".join(f"<tr><td>{v.name}</td><td>{v.causality}</td><td>{v.unit}</td>"
                   f"<td>{v.description}</td></tr>" for v in fmu_xml.POINT_VARIABLES)
    bound = ("any finite value" if not u_bound < float("inf")
             else f"|u_x|, |u_y| &lt;= {u_bound!r} m")
    return ("<html><body><h1>damper contact point</h1><p>3D contact point: a 2D Masing/Iwan "
            "friction element (each slider a 2D Jenkins element with a circular slip limit "
            "scaled by the normal load; the isotropic virgin curve resources/curve.txt) and the "
            "normal law N(p) of resources/normal.txt (N = 0 for p &lt;= 0: lift-off). Inputs "
            "are straight lines between communication points (FMI 2: with the input "
            "derivatives), which the element follows exactly at any step size. Outputs follow "
            "the current inputs (direct feedthrough); the history is committed in doStep only."
            f"</p><p>Start: p = {p_start!r} m, where N = {N_start!r} N.</p><h2>Tangent</h2><p>"
            "K_ab = dF_a/dq_b (q = u_x, u_y, p) is the exact derivative of the outputs at the "
            "current inputs reached from the last communication point; at that point itself, "
            "the tangent for continued motion. The FMI directional derivatives of F_x, F_y, N "
            "give the same numbers (and the dashpots c_t, c_n for v_x, v_y, v_n).</p>"
            "<h2>Limits</h2><p>Input bound: " + bound + " (also the min/max of u_x, u_y); "
            "beyond it double precision cannot represent the element's smallest slip distance "
            "to 1e-6 of its strength. |p| is bounded where the normal spring's stored energy "
            "reaches 1e300 J (beyond, the outputs would overflow). A step size must be &gt; 0 "
            "and the step's end t + h finite.</p><h2>Energy</h2><p>The "
            "work of u_x, u_y, p equals W + stored_energy (dashpots aside). The slip limits "
            "follow the elastic N(p): the dashpots add force, not friction.</p>"
            "<table><tr><th>name</th><th>causality</th><th>unit</th>"
            f"<th>description</th></tr>{rows}</table></body></html>\n")


def build_point_fmu(u, T, n_ref: float, p, N, out: str | os.PathLike, fmi_version: int = 2,
                    N_start: float | None = None, fit: str = "reject", tail: str = "slope",
                    description: str = "", compiler: str | None = None,
                    resources: dict | None = None) -> Path:
    """Write a co-simulation FMU of a 3D contact point.

    Parameters
    ----------
    u, T : array_like, shape (m,)
        Virgin curve [m], [N] at the normal load ``n_ref`` [N].
    p, N : array_like, shape (k,)
        Normal law [m], [N]: from (0, 0), both strictly increasing.
    out : path
        The ``.fmu`` file (written atomically).
    fmi_version : {2, 3}
    N_start : float, optional
        Normal load at the start [N] (start value of p: the penetration where N(p) =
        N_start); default ``n_ref``.
    fit, tail : str
        As :func:`fmu_src.fmu_build.build_fmu`.
    description : str
    compiler : str, optional
    resources : dict, optional
        Further files for ``resources/`` (name -> text), e.g. the source curve files.

    Returns
    -------
    Path of the written FMU.
    """
    fmu_build._check_version(fmi_version)
    if tail == "flat":
        from fmu_src.element import flat_tail

        u, T = flat_tail(*fmu_build.check_curve(u, T, n_ref, fit, tail))
        tail = "slope"  # the table now ends flat
    point = contact_point(u, T, n_ref, p, N, fit, tail)
    p, N = point.table
    N_start = float(n_ref) if N_start is None else float(N_start)
    p_start = point.penetration(N_start)
    start = point.eval(point.initial_state(p_start), [0.0, 0.0, p_start])
    if not (np.all(np.isfinite(start.f)) and np.isfinite(start.E) and np.all(np.isfinite(start.K))):
        raise ValueError(f"the start at N = {N_start:g} N (p = {p_start:g} m) overflows the "
                         "contact point's outputs (stored energy): a smaller --preload or a "
                         "stiffer normal law")
    bound = fmu_build.input_bound(point.tangential)
    iface = fmu_xml.POINT
    with tempfile.TemporaryDirectory(prefix="damper_point_") as tmp:
        root = Path(tmp) / "fmu"
        names = fmu_build._copy_sources(root / "sources", fmi_version, MODEL)
        res = root / "resources"
        res.mkdir()
        (res / "curve.txt").write_text(fmu_build.curve_resource_text(u, T, n_ref, fit))
        (res / "normal.txt").write_text(normal_resource_text(p, N, p_start))
        for name, text in (resources or {}).items():
            (res / name).write_text(text)
        (root / "documentation").mkdir()
        (root / "documentation" / "index.html").write_text(_documentation(bound, p_start, N_start))
        text = fmu_xml.render_model_description(
            fmi_version, n_ref, names, description, iface=iface,
            bounds={"u_x": bound, "u_y": bound}, starts={"normal_p": p_start})
        (root / "modelDescription.xml").write_text(text)
        if fmi_version == 3:
            (root / "sources" / "buildDescription.xml").write_text(
                fmu_xml.render_build_description(names, iface))
        binary = root / "binaries" / fmu_build.PLATFORM[fmi_version] / f"{iface.model_identifier}.so"
        fmu_build.compile_binary(root / "sources", names, binary, compiler)
        path = atomic_write(out, fmu_build._zip_dir(root))
    return path


def penalty_table(k_n: float) -> tuple[np.ndarray, np.ndarray]:
    """The penalty law N = k_n max(p, 0) as a table: (0, 0), (1 m, k_n)."""
    if not (np.isfinite(k_n) and k_n > 0):
        raise ValueError(f"--k-n must be finite and > 0, got {k_n!r}")
    return np.array([0.0, 1.0]), np.array([0.0, float(k_n)])
