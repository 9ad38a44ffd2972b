"""Data contract between the FE condensation and the contact solves.

The FE stage (``contact_core.condense.condense``) reduces two elastic bodies to
the normal (and optionally tangential) *compliance* of their potential contact
nodes; the normal solve (``contact_core.normal``) and the tangential solve work
on these plain arrays only.

Symbols (SI units):

n      number of modelled contact nodes (a quarter, half or full part by symmetry)
r      number of rigid DOFs of the distant faces (1: approach; 2: approach, rotation)
f      (n,) compressive nodal normal forces of the modelled part [N]
q      (r,) rigid DOFs: q[0] the approach delta [m], q[1] the rotation theta [rad]
h      (n,) initial normal gap [m]
C      (n, n) combined normal compliance [m/N]

Gap at the solution (thesis Appendix A.1)::

    g = h - rigid @ q + Czz @ f >= 0,   f >= 0,   g * f = 0

``Czz`` is the flexibility form of the thesis's reduced stiffness: with the
distant faces held, ``Czz = Ktilde_zz^-1`` where ``Ktilde_zz`` is eq. A.10/A.11
(the z block of the Guyan-reduced contact stiffness with the tangential contact
DOFs condensed out, i.e. left free and unloaded).  We build it directly as the
z-z block of the contact compliance, so no stiffness inverse is ever formed.
Likewise ``Cxx = Ktilde_x^-1`` of eqs A.27-A.28 (x block, normal DOFs free).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class ContactGrid:
    """The modelled potential-contact nodes (coincident on both faces).

    Attributes
    ----------
    x, y : ndarray, shape (n,)
        Node positions in the contact plane [m]; the contact centre is the
        origin, a cylinder's axis and a flat face's long side run along y.
    area : ndarray, shape (n,)
        Tributary area of each node inside the modelled part [m^2] (a node on a
        symmetry plane owns only its half inside the part).
    mult : ndarray, shape (n,)
        Weight of the node's modelled share in full-model totals:
        ``sum(mult * f)`` is the full-model force and ``sum(mult * area)`` the
        full-model area. With symmetry boundary conditions the modelled part
        carries 1/4 (quarter) or 1/2 (half) of every load, including at nodes
        on a symmetry plane (their other half lies in the image part), so
        ``mult`` is 4 for every node of a quarter model, 2 for a half model and
        1 for a full model. ``copies`` counts the distinct nodes instead.
    h : ndarray, shape (n,)
        Initial normal gap from the geometry [m] (>= 0, zero at the first
        touching point).
    copies : ndarray of int, shape (n,), optional
        Number of distinct nodes of the full model the node stands for (its
        symmetry images: 4, 2 or 1 in a quarter model); for node counts only.
    """

    x: np.ndarray
    y: np.ndarray
    area: np.ndarray
    mult: np.ndarray
    h: np.ndarray
    copies: np.ndarray | None = None

    @property
    def n(self) -> int:
        """Number of modelled contact nodes."""
        return int(self.x.size)


@dataclass(frozen=True)
class CondensedContact:
    """Condensed compliance of a pair of bodies on their contact nodes.

    Attributes
    ----------
    grid : ContactGrid
        The contact nodes.
    Czz : ndarray, shape (n, n)
        Combined normal compliance of both bodies [m/N]: the closing of the two
        surfaces at node i per unit compressive nodal force at node j of the
        modelled part (its symmetry images loaded alike), distant faces held.
        Equal to the inverse of the thesis's reduced stiffness (eq. A.10).
    rigid : ndarray, shape (n, r)
        Normal displacement (closing) of contact node i per unit rigid DOF of the
        distant faces: column 0 the approach delta (all ones), column 1 (flat
        face only) the rotation theta about the y axis (closing = theta * x).
    Czz_bodies : tuple of ndarray
        ``(C1, C2)``, each (n, n): per-body normal compliances (C1 the curved
        body, C2 the plane), ``Czz = C1 + C2``.
    Cxx : ndarray, shape (n, n), or None
        Combined tangential (x) compliance [m/N] with the symmetry conditions of
        an x load (u_x even in x), or None if not requested: relative x
        displacement of the surfaces at i per unit opposite x forces at j.
    Cxx_bodies : tuple of ndarray or None
        ``(C1, C2)`` tangential compliances, or None.
    Cyy, Cyy_bodies : ndarray (n, n) and tuple, or None
        The same for the second tangential direction y (symmetry conditions of a
        y load, u_y even in y), or None if not requested.
    meta : dict
        Geometry, materials, grid, symmetry, mesh sizes, timings per stage
        [s], cache key and hit.
    probe_x : ndarray, shape (p,), optional
        x [m] of free surface nodes of body 1 on the row y = 0 beyond the zone.
    probe_C1 : ndarray, shape (p, n), optional
        Their elastic normal displacement (away from the plane) per unit
        contact force: body 1's compression outside the contact (thesis 2.2.5).
    """

    grid: ContactGrid
    Czz: np.ndarray
    rigid: np.ndarray
    Czz_bodies: tuple
    Cxx: np.ndarray | None = None
    Cxx_bodies: tuple | None = None
    meta: dict = field(default_factory=dict)
    probe_x: np.ndarray | None = None
    probe_C1: np.ndarray | None = None
    Cyy: np.ndarray | None = None
    Cyy_bodies: tuple | None = None

    @property
    def n(self) -> int:
        """Number of modelled contact nodes."""
        return self.grid.n
