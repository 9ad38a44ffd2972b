"""Derived results of a normal contact state: areas, radii, pressures, stiffness.

Symbols as in ``contact_core.normal``; p = f / area the nodal pressure [Pa].
Contact size estimators:

* ``contact_radius`` (sphere): the radius a of the Hertz-form pressure
  p^2 = c (a^2 - r^2) fitted (least squares) to the nodal pressures of the
  contact nodes; it interpolates the edge between grid nodes, where the area of
  the active nodes (``contact_radius_area`` = sqrt(A / pi)) jumps by whole cells.
  With too few contact nodes for the fit the area radius is reported
  (``contact_size_method``).
* ``contact_halfwidth`` (cylinder, mid-length): the same fit p^2 = c (b^2 - x^2)
  on the row y = 0; ``contact_halfwidth_end``: the outer edge (last contact node
  plus half a cell) of the row at the cylinder's end y = L/2, where the pressure
  is not elliptical (edge effect).
"""
from __future__ import annotations

import numpy as np

from .condensed import CondensedContact
from .normal import NormalSolution, resultants, tangent

#: A contact narrower than this many grid spacings (radius or half-width) is
#: flagged ``under_resolved``: its size and peak pressure are then rough.
MIN_NODES_ACROSS = 3
#: Distance (in contact radii / half-widths) where the thesis measures a body's
#: compression outside the contact (section 2.2.5: "3b").
FAR_PROBE = 3.0


def _fit_edge(u: np.ndarray, p: np.ndarray) -> float:
    """Edge a of p^2 = c (a^2 - u^2) fitted to points (u, p), or nan if < 2 points."""
    if u.size < 2 or np.ptp(u**2) == 0:
        return float("nan")
    slope, icept = np.polyfit(u**2, p**2, 1)
    return float(np.sqrt(icept / -slope)) if slope < 0 < icept else float("nan")


def _row_extent(u: np.ndarray, active: np.ndarray, spacing: float) -> float:
    """Outer edge of the contact on a grid row: last active |u| plus half a cell."""
    return float(np.max(np.abs(u[active])) + 0.5 * spacing) if active.any() else 0.0


def summarize(cc: CondensedContact, sol: NormalSolution, body: str) -> dict:
    """Scalar results and maps of a solved state (full-model values, SI units)."""
    g, P = cc.grid, sol.active
    p = sol.f / g.area
    res = resultants(cc, sol.f)
    area = float(np.sum(g.mult * g.area * P))
    T = tangent(cc, P)
    u1 = cc.Czz_bodies[0] @ sol.f
    # the first touching point (least gap, nearest the centre) of the contact
    i0 = int(np.lexsort((np.hypot(g.x, g.y), g.h + 1e30 * ~P))[0])
    out = {
        "force": float(res[0]),
        "approach": float(sol.q[0]),
        "contact_area": area,
        "p_max": float(p.max()),
        "p_mean": float(res[0] / area) if area > 0 else 0.0,
        "k_n": float(T[0, 0]),
        "iterations": int(sol.iterations),
        "newton_steps": int(sol.newton),
        "n_contact_nodes": int(np.sum(g.copies * P)) if g.copies is not None else int(P.sum()),
        "body1_share": float(u1[i0] / sol.q[0]) if sol.q[0] > 0 else 0.0,
        "max_penetration": float(max(0.0, -sol.g.min())),
        "min_force": float(sol.f.min()),
        "zone_edge_in_contact": bool(_zone_edge_hit(cc, P, body)),
    }
    if cc.rigid.shape[1] > 1:
        out["rotation"] = float(sol.q[1])
        out["moment"] = float(res[1])
        out["eccentricity"] = float(res[1] / res[0]) if res[0] > 0 else 0.0
    s = float(np.min(np.diff(np.unique(g.x))))
    if body == "sphere":
        r = np.hypot(g.x, g.y)
        out["contact_radius_area"] = float(np.sqrt(area / np.pi))
        fit = _fit_edge(r[P], p[P])
        out["contact_radius"] = fit if np.isfinite(fit) else out["contact_radius_area"]
        out["contact_size_method"] = "pressure fit" if np.isfinite(fit) else "area"
        out["under_resolved"] = bool(out["contact_radius"] < MIN_NODES_ACROSS * s)
        _share_far(out, cc, sol, out["contact_radius"])
    elif body == "cylinder":
        mid = np.abs(g.y) <= 1e-9 * s
        end = np.abs(g.y - g.y.max()) <= 1e-9 * s
        out["contact_halfwidth_mid_extent"] = _row_extent(g.x[mid], P[mid], s)
        fit = _fit_edge(g.x[mid & P], p[mid & P])
        out["contact_halfwidth"] = fit if np.isfinite(fit) else out["contact_halfwidth_mid_extent"]
        out["contact_size_method"] = "pressure fit" if np.isfinite(fit) else "extent"
        out["under_resolved"] = bool(out["contact_halfwidth"] < MIN_NODES_ACROSS * s)
        out["contact_halfwidth_end"] = _row_extent(g.x[end], P[end], s)
        _share_far(out, cc, sol, out["contact_halfwidth"])
        out["p_mid_max"] = float(p[mid].max())
        out["p_end_max"] = float(p[end].max())
    return out


def _share_far(out: dict, cc: CondensedContact, sol: NormalSolution, size: float) -> None:
    """Body 1's compression outside the contact, u_1o / delta at x ~ 3 b (thesis 2.2.5).

    u_1o is the elastic displacement of body 1's free surface at the probe
    nearest x = FAR_PROBE * size (accepted within 2.5-4 sizes); it excludes
    the local indentation that ``body1_share`` (at the centre) includes.
    """
    if cc.probe_x is None or cc.probe_x.size == 0 or sol.q[0] <= 0:
        return
    i = int(np.argmin(np.abs(cc.probe_x - FAR_PROBE * size)))
    if 2.5 * size <= cc.probe_x[i] <= 4.0 * size:
        out["body1_share_far"] = float(cc.probe_C1[i] @ sol.f / sol.q[0])
        out["body1_share_far_at"] = float(cc.probe_x[i])


def _zone_edge_hit(cc: CondensedContact, P: np.ndarray, body: str) -> bool:
    """True if a node on the outer x edge (sphere: x or y edge) of the zone is in contact."""
    if body == "flat":
        return False
    g = cc.grid
    edge = np.isclose(g.x, g.x.max())
    if body == "sphere":
        edge |= np.isclose(g.y, g.y.max())
    return bool(np.any(P & edge))


def maps(cc: CondensedContact, sol: NormalSolution) -> dict:
    """Per-node arrays of the modelled part: x, y [m], pressure [Pa], gap [m], contact."""
    g = cc.grid
    return {"x": g.x, "y": g.y, "pressure": sol.f / g.area, "gap": sol.g,
            "contact": sol.active.astype(int)}
