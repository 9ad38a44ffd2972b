"""The UPD sector with contact surfaces instead of contact points.

The damper's two faces (the cylinder line on blade j, the flat on blade j+1) become
contact surfaces (:mod:`harmonic_balance.surface`, planar variant: slip along the
face's tangent, 2 DOFs per node): each surface adds its node DOFs w to the sector,
a linear element for the two bodies' condensed stiffness between the nodes and the
rigid inputs, and one ContactElement per node.

Rigid inputs from the sector's contact kinematics (:class:`~.sector.Sector`, rows of
penetration p and slip s per point; the only copy of the geometry):

* cylinder: approach = p and tangential = s of the ``left`` point;
* flat: approach and tangential = the mean of the rows of its end points ``right1``
  and ``right2`` (the face centre), rotation = theta_d (the platform does not rotate):
  a node at x along the face's tangent from the centre closes by p_c + theta_d x for
  either face angle (n . (z x t) = -1 on both sides), which is the flat's rigid map
  (:meth:`contact_core.bodies.FlatFace.rigid`); its rows on blade j+1's platform
  enter through ``Q_next`` and the phase phi, as for the point model.

Dashpots (``dashpots``): ``"bodies"`` puts beta_c times the surface's stiffness on
the linear element (the point model's beta_c k of its stuck contact, here the bodies'
series stiffness: they act on the bodies' deformation only, not on a node's slip);
``"inputs"`` puts beta_c times the surface's condensed stuck stiffness on its rigid
inputs (:func:`input_dashpots`: the whole relative motion of the faces, slip included),
the convention of :class:`CondensedSurfaceSectorHB`, so that a node-DOF model and its
ring time integration are the condensed model's. The node contacts have none (their
penalty is a numerical device, not a physical stiffness).

Symbols as in :mod:`harmonic_balance.surface` and :mod:`.hb`.
"""
from __future__ import annotations

import numpy as np

from ..contact import ContactElement, frictionless_statics
from ..forces import LinearElement
from ..kinematics import Kinematics
from ..linear import LinearModel
from ..model import Model
from ..residual import FullResidual
from .hb import SectorHB, coupling_element, loads, sector_basis
from .sector import Sector

#: Face names and the sector points whose rows give their inputs.
FACES = {"left": ("left",), "flat": ("right1", "right2")}
#: Where the bodies' dashpots act (:class:`SurfaceSectorHB`'s ``dashpots``).
DASHPOTS = ("bodies", "inputs")


def face_inputs(sector: Sector, face: str):
    """Rows (r, n_dof) on blade j and (r, n_right) on blade j+1 of a face's rigid inputs.

    Order as in the surface's ``inputs``: approach, [rotation,] tangential_x.
    """
    if sector.rows_per_point != 2:
        raise ValueError("contact surfaces need the planar UPD sector (platform points [u, v]); "
                         "this blade has axial platform DOFs: use --contacts toml or geometry")
    n, names = sector.n_dof, [c.name for c in sector.points]
    idx = [names.index(p) for p in FACES[face]]
    p = np.mean([sector.Q[2 * i] for i in idx], axis=0)
    s = np.mean([sector.Q[2 * i + 1] for i in idx], axis=0)
    rows = [p] + ([np.eye(n + 2)[n - 1]] if face == "flat" else []) + [s]
    G = np.array(rows)
    return G[:, :n], G[:, n:]


def surface_elements(surface, offset: int, G, G_next, right, phi: float, beta_c: float, name: str,
                     C_inputs=None):
    """The surface's linear element (stiffness and dashpots) and node contacts in a sector model.

    Parameters
    ----------
    surface : harmonic_balance.surface.Surface
        Planar (``tangents == ("x",)``).
    offset : int
        First model DOF of the surface's w.
    G : ndarray (r, n_dof)
        Rigid inputs from the sector's DOFs (:func:`face_inputs`).
    G_next : ndarray (r, n_right)
        From blade j+1's platform point (``right`` DOFs); zeros: no neighbour.
    right : sequence of int
        blade j+1's platform DOFs in the sector numbering.
    phi : float
        Interblade phase [rad].
    beta_c : float
        Dashpots beta_c K of the surface [s] (0: none on the bodies).
    name : str
    C_inputs : ndarray (r, r), optional
        Dashpots on the rigid inputs [N s/m] (:func:`input_dashpots`).
    """
    n_w = surface.n_w
    used = np.flatnonzero(np.any(G != 0.0, axis=0))
    cyclic = bool(np.any(G_next != 0.0))
    if cyclic:
        used = np.union1d(used, right)
    r = G.shape[0]
    Q = np.zeros((n_w + r, n_w + used.size))
    Q[:n_w, :n_w] = np.eye(n_w)
    Q[n_w:, n_w:] = G[:, used]
    dofs = np.r_[offset + np.arange(n_w), used]
    Qn = None
    if cyclic:
        Gn = np.zeros_like(G)
        Gn[:, right] = G_next
        Qn = np.zeros_like(Q)
        Qn[n_w:, n_w:] = Gn[:, used]
    kin = Kinematics(dofs, Q, Q_next=Qn, phase=phi if cyclic else 0.0)
    els = [LinearElement(kin, surface.K, beta_c * surface.K if beta_c else None, name=f"{name} bodies")]
    if C_inputs is not None:     # dashpots on the rigid inputs alone (rows n_w.. of Q)
        r = G.shape[0]
        kin_q = Kinematics(dofs, Q[n_w:], Q_next=None if Qn is None else Qn[n_w:],
                           phase=phi if cyclic else 0.0)
        els.append(LinearElement(kin_q, np.zeros((r, r)), C_inputs, name=f"{name} dashpots"))
    els += node_contacts(surface, offset, name)
    return els


def input_dashpots(surface, beta_c: float) -> np.ndarray:
    """beta_c times the surface's condensed stiffness on its rigid inputs with every node
    closed and stuck, (r, r) [N s/m] (:meth:`.surface_condensed.CondensedSurface.stuck_stiffness`)."""
    from ..surface_condensed import CondensedSurface

    r = surface.K.shape[0] - surface.n_w
    cs = CondensedSurface(surface, None, np.zeros(r), np.zeros(surface.n_w), np.zeros(surface.n))
    return beta_c * cs.stuck_stiffness()


def node_contacts(surface, offset: int, name: str) -> list:
    """The surface's node ContactElements on model DOFs offset ... offset + d n - 1."""
    els = []
    for i, el in enumerate(surface.elements):
        node = Kinematics(offset + np.arange(surface.d * i, surface.d * (i + 1)), np.eye(surface.d))
        contact = type(el)(node, el.k_n, el.friction, preload=el.preload, name=f"{name} node {i}")
        els.append(contact)
    return els


def linear_part(surface, offset: int, G, n_model: int) -> np.ndarray:
    """T^T K T (n_model, n_model) of a surface without a neighbour: [w; q] = T x, exact in
    every harmonic (no phase), so it joins the linear structure."""
    T = np.zeros((surface.n_dof, n_model))
    T[:surface.n_w, offset:offset + surface.n_w] = np.eye(surface.n_w)
    T[surface.n_w:, :G.shape[1]] = G
    return T.T @ surface.K @ T


class SurfaceSectorHB(SectorHB):
    """HB residual of the UPD sector with the damper's faces as contact surfaces.

    Parameters
    ----------
    sector : Sector
    surfaces : dict {"left": Surface, "flat": Surface}
        Planar surfaces of the cylinder and the flat (:func:`build_surfaces`).
    H, cf, f0, mu, n_t
        As :class:`~.hb.SectorHB` (mu is the surfaces' own).
    dashpots : {"bodies", "inputs"}
        Where the bodies' damping acts (module docstring): on their deformation, or on
        the faces' rigid inputs as in :class:`CondensedSurfaceSectorHB`.
    """

    def __init__(self, sector: Sector, surfaces: dict, H: int = 7, cf=None, f0=None, mu=None,
                 n_t: int = 0, dashpots: str = "bodies"):
        for face in FACES:
            if surfaces[face].tangents != ("x",):
                raise ValueError(f"the {face} surface must be planar (tangents ('x',))")
        if dashpots not in DASHPOTS:
            raise ValueError(f"dashpots must be one of {DASHPOTS}, not {dashpots!r}")
        self.surfaces, self.dashpots = surfaces, dashpots
        super().__init__(sector, H, cf, f0, mu, n_t)

    def with_harmonics(self, H: int, n_t: int = 0) -> SurfaceSectorHB:
        """The same sector, surfaces and loads with harmonics 0..H (``n_t`` AFT samples)."""
        return SurfaceSectorHB(self.sector, self.surfaces, H, cf=self.cf, f0=self.f0, mu=self.mu,
                               n_t=n_t, dashpots=self.dashpots)

    def _build_model(self) -> Model:
        sec = self.sector
        n = sec.n_dof
        n_w = sum(s.n_w for s in self.surfaces.values())
        pad = [np.zeros((n + n_w, n + n_w)) for _ in range(3)]
        for P, A in zip(pad, (sec.M, sec.C_struct(0.0), sec.K_struct(0.0))):
            P[:n, :n] = A
        els = [e for e in (coupling_element(sec),) if e is not None]
        offset = n
        on_inputs = self.dashpots == "inputs" and sec.beta_c
        for face, surf in self.surfaces.items():
            G, G_next = face_inputs(sec, face)
            beta_bodies = 0.0 if on_inputs else sec.beta_c
            C_q = input_dashpots(surf, sec.beta_c) if on_inputs else None
            if np.any(G_next != 0.0):   # the flat: its inputs use blade j+1 (phase phi)
                els += surface_elements(surf, offset, G, G_next, list(sec.blade.right), sec.cfg.phi,
                                        beta_bodies, face, C_q)
            else:                       # the cylinder: linear structure (cheaper, exact)
                Ks = linear_part(surf, offset, G, n + n_w)
                pad[2] += Ks
                pad[1] += beta_bodies * Ks
                if C_q is not None:
                    pad[1][:n, :n] += G.T @ C_q @ G
                els += node_contacts(surf, offset, face)
            offset += surf.n_w
        f_static, f_eo = np.zeros(n + n_w), np.zeros(n + n_w, dtype=complex)
        f_static[sec.y_d], f_eo[sec.forced] = self.cf, self.f0
        return Model(LinearModel(M=pad[0], C=pad[1], K=pad[2]), els, {0: f_static, 1: f_eo}, sec.response)

    def stuck_guess(self, omega: float) -> np.ndarray:
        """Prestress mean + the linear response with every node stuck (a Newton start).

        One Newton step from the prestress state without vibration: there every node in
        contact is stuck, so the Jacobian is the stuck linear system (surfaces included)
        and the step is its response to the EO force.
        """
        x0 = self.static_guess()
        R, J, _ = self.residual(x0, omega, True)
        return x0 - np.linalg.solve(J, R)

    def _eo_forcing(self) -> np.ndarray:
        f = np.zeros(self.ndof, dtype=complex)
        f[self.sector.forced] = self.f0
        return f


class CondensedSurfaceSectorHB(SectorHB):
    """The sector with each surface condensed onto its rigid inputs
    (:class:`~harmonic_balance.surface_condensed.CondensedSurface`): the unknowns are the
    sector's DOFs alone, the nodes' response is marched in time inside each evaluation.

    The prestress (the nodes' frictionless statics and slips) is that of
    :class:`SurfaceSectorHB` on the same surfaces. The bodies' dashpots act on the rigid
    inputs as beta_c times the surface's condensed stuck stiffness (the point model's
    beta_c k of its stuck contact).

    Parameters as :class:`SurfaceSectorHB`.
    """

    #: Where the bodies' dashpots act (:data:`DASHPOTS`): here always on the rigid inputs.
    dashpots = "inputs"

    def __init__(self, sector: Sector, surfaces: dict, H: int = 7, cf=None, f0=None, mu=None,
                 n_t: int = 0):
        for face in FACES:
            if surfaces[face].tangents != ("x",):
                raise ValueError(f"the {face} surface must be planar (tangents ('x',))")
        self.surfaces, self.sector, self.H = surfaces, sector, int(H)
        self.cf, self.f0, self.mu = loads(sector.cfg, cf, f0, mu)
        # the node-DOF model's frictionless statics (no residual built: only its elements)
        nodes_model = SurfaceSectorHB._build_model(self)
        self._x_nodes, _ = frictionless_statics(nodes_model, apply=True)
        self._nodes = [e for e in nodes_model.elements if isinstance(e, ContactElement)]
        self.basis = sector_basis(sector, self.H, n_t)
        self.model = self._build_model()
        self.x_static = self._x_nodes[:sector.n_dof].copy()
        self.contacts = []
        self.residual = FullResidual(self.model, self.basis)
        self.nb, self.ndof = self.basis.nb, self.model.n
        self.size = self.residual.size
        self.evaluations = 0

    def with_harmonics(self, H: int, n_t: int = 0) -> CondensedSurfaceSectorHB:
        """The same sector, surfaces and loads with harmonics 0..H (``n_t`` AFT samples)."""
        return CondensedSurfaceSectorHB(self.sector, self.surfaces, H, cf=self.cf, f0=self.f0,
                                        mu=self.mu, n_t=n_t)

    def _build_model(self) -> Model:
        from ..surface_condensed import CondensedSurface

        sec, x_nodes, nodes = self.sector, self._x_nodes, self._nodes
        n = sec.n_dof
        els = [e for e in (coupling_element(sec),) if e is not None]
        offset, k = n, 0
        for face, surf in self.surfaces.items():
            G, G_next = face_inputs(sec, face)
            used = np.flatnonzero(np.any(G != 0.0, axis=0))
            cyclic = bool(np.any(G_next != 0.0))
            Qn = None
            if cyclic:
                right = list(sec.blade.right)
                used = np.union1d(used, right)
                Gn = np.zeros_like(G)
                Gn[:, right] = G_next
                Qn = Gn[:, used]
            kin = Kinematics(used, G[:, used], Q_next=Qn, phase=sec.cfg.phi if cyclic else 0.0)
            slips = [el.slip_ref for el in nodes[k:k + surf.n]]
            xs = x_nodes[list(kin.dofs)]
            q_static = (kin.Q + (kin.Q_next if cyclic else 0.0)) @ xs   # h = 0: the neighbour's is the sector's
            cs = CondensedSurface(surf, kin, q_static, x_nodes[offset:offset + surf.n_w], slips,
                                  name=face)
            if sec.beta_c:
                cs.C = sec.beta_c * cs.stuck_stiffness()
            els.append(cs)
            offset += surf.n_w
            k += surf.n
        f_static, f_eo = np.zeros(n), np.zeros(n, dtype=complex)
        f_static[sec.y_d], f_eo[sec.forced] = self.cf, self.f0
        lin = LinearModel(M=sec.M, C=sec.C_struct(0.0), K=sec.K_struct(0.0))
        return Model(lin, els, {0: f_static, 1: f_eo}, sec.response)
