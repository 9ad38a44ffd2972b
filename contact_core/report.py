"""Derived results of a normal contact state: areas, radii, pressures, stiffness.

Symbols as in ``contact_core.normal``; p = f / area the nodal pressure [Pa].
Contact size estimators (each body kind adds its own, ``contact_core.bodies``):

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

from . import bodies
from .condensed import CondensedContact
from .normal import NormalSolution, resultants, tangent


def summarize(cc: CondensedContact, sol: NormalSolution, body) -> dict:
    """Scalar results of a solved state (full-model values, SI units).

    ``body`` is a body kind or its name (``contact_core.bodies``); it adds its
    contact-size estimators (radius, half-widths) to the generic scalars.
    """
    kind = bodies.get(body)
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
        "zone_edge_in_contact": bool(_zone_edge_hit(cc, P, kind)),
    }
    if cc.rigid.shape[1] > 1:
        out["rotation"] = float(sol.q[1])
        out["moment"] = float(res[1])
        out["eccentricity"] = float(res[1] / res[0]) if res[0] > 0 else 0.0
    kind.summarize_size(out, cc, sol, p, float(np.min(np.diff(np.unique(g.x)))))
    return out


def _zone_edge_hit(cc: CondensedContact, P: np.ndarray, kind: bodies.Body) -> bool:
    """True if a node on the outer edge of the potential zone is in contact."""
    edge = kind.zone_edge(cc.grid)
    return bool(edge is not None and np.any(P & edge))


def maps(cc: CondensedContact, sol: NormalSolution) -> dict:
    """Per-node arrays of the modelled part: x, y [m], pressure [Pa], gap [m], contact."""
    g = cc.grid
    return {"x": g.x, "y": g.y, "pressure": sol.f / g.area, "gap": sol.g,
            "contact": sol.active.astype(int)}
