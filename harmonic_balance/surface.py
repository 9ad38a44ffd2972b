"""Contact surface: two condensed FE faces as many 3D contact points.

A :class:`~contact_core.condensed.CondensedContact` holds the combined compliance of
two elastic bodies on their coincident potential-contact nodes, distant faces held
(thesis Appendix A.1.2-A.1.5, Guyan reduction; ``Czz``, ``Cxx``, ``Cyy``). Here
each node pair becomes a 3D contact point (:class:`~.contact.ContactElement`:
penalty normal with lift-off, 2D Coulomb friction following N) and the bodies
between the nodes a dense linear super-element, the node-to-node formulation on a
condensed interface of Petrov & Ewins (2003) and Firrone, Zucca & Gola (2011).

Symbols (SI units)::

    n       surface nodes (the modelled part of the grid: quarter, half or full)
    m_i     full-model weight of node i (``grid.mult``); W = diag(m)
    C_d     (n, n) combined compliance in direction d = x, y, z [m/N]
    K_d     = C_d^-1, the stiffness of both bodies on the surface nodes [N/m]
    d       DOFs per node: 3 (slips x, y and the closing), 2 in a planar model
    w       (d n,) relative displacements of the node pairs, node-major
            [w_0x, w_0y, w_0z, w_1x, ...]: tangential displacement of body 1
            over body 2 (x, y) and the closing of the gap (z) [m]
    q       (r,) rigid relative motion of the distant faces: approach [m],
            rotation about y [rad] (flat face only), tangential x, y [m]
    R_d     (n, r) relative displacement of the nodes in d per unit q (rigid map)
    h       (n,) initial normal gap [m]

Elasticity (the flexibility between the nodes; full-model energy)::

    V = 1/2 sum_d (R_d q - w_d)^T W K_d (R_d q - w_d)                    (S1)

so the model's stiffness on x = [w; q] is [[A, -A R], [-R^T A, R^T A R]] with
A = blockdiag_d(W K_d) (symmetric: W C_d is, by reciprocity). Its forces are the
nodal contact forces f = K_d (R_d q - w_d) (eq. A.23 in flexibility form: the
closing w = R q - C f) and, on q, the full-model resultants R^T W f.

Contact at node i (one ContactElement on [w_ix, w_iy, w_iz]; [w_ix, w_iz] planar)::

    N_i = m_i k_n,i max(w_iz - h_i, 0)                                   (S2)
    f_t,i = 2D Jenkins slider, stiffness m_i k_t,i, slip force mu N_i      (S3)

The penalties are ``penalty`` times the node's own stiffness 1 / C_d,ii, so the
contact adds a compliance of 1 / penalty of each node's own to the bodies'; as
penalty -> inf, (S1)-(S3) tend to the contact core's normal (Signorini) and
tangential (Amontons-Coulomb) solves on the same compliances (thesis A.1, A.2).
Slip therefore starts where the traction first reaches mu p (the edges of a
cylinder or a flat face) and spreads inwards, as in the stick/slip solve.

The compliances carry the symmetry conditions of the condensation (quarter model:
loads even in x and y; flat face: even in y): the surface represents the motions
with that symmetry (approach, tangential x and y, and for the flat face the
rocking about y).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contact import ContactElement
from .kinematics import Kinematics

#: Contact penalty relative to each node's own body stiffness 1 / C_ii: the
#: contact adds 1 / PENALTY of the node's own compliance (measured: k_t and the
#: loop energy within 0.1 % of the contact core's exact solve at 1e4, see
#: tests/hb/test_surface.py; the dense solves lose about log10(PENALTY) digits).
PENALTY = 1e4
#: Bounds of the contact grid nodes per side a surface accepts (the spec's grid):
#: fewer than MIN cannot carry a stick/slip pattern (contact_core.tangential_run),
#: more than MAX makes the dense node stiffness (3 n)^2 too large for the dynamics.
MIN_NODES, MAX_NODES = 5, 41


def check_nodes(nodes_per_side: int) -> int:
    """The node count per side of a surface, or ValueError naming the bound."""
    if isinstance(nodes_per_side, bool) or not isinstance(nodes_per_side, (int, np.integer)) \
            or not MIN_NODES <= nodes_per_side <= MAX_NODES:
        raise ValueError(f"surface nodes per side must be an integer in [{MIN_NODES}, {MAX_NODES}], "
                         f"got {nodes_per_side!r}: use --surface-nodes between those")
    return int(nodes_per_side)


@dataclass(frozen=True)
class Surface:
    """The contact surface as a model piece (module docstring).

    Attributes
    ----------
    contact : CondensedContact
        The condensed pair.
    K : ndarray, shape (d n + r, d n + r)
        Stiffness on x = [w; q] [N/m, N, N m] (S1).
    elements : list of ContactElement
        One per node, on DOFs (d i, ..., d i + d - 1), weighted by m_i (S2, S3).
    inputs : tuple of str
        Names of the r rigid inputs, DOFs d n ... d n + r - 1.
    tangents : tuple of str
        The slip directions kept: ("x", "y") (d = 3), or ("x",) (d = 2: a planar model).
    mu : float
        Friction coefficient.
    penalty : float
        Penalty factor (module docstring).
    """

    contact: object
    K: np.ndarray
    elements: list
    inputs: tuple
    tangents: tuple
    mu: float
    penalty: float

    @property
    def n(self) -> int:
        """Number of surface nodes."""
        return self.contact.n

    @property
    def d(self) -> int:
        """DOFs per node: the slips, then the closing."""
        return len(self.tangents) + 1

    @property
    def n_w(self) -> int:
        """Number of node DOFs, d n."""
        return self.d * self.n

    @property
    def n_dof(self) -> int:
        """Number of DOFs, d n + r."""
        return self.K.shape[0]

    def input_dof(self, name: str) -> int:
        """DOF index of a rigid input by name (``inputs``)."""
        if name not in self.inputs:
            raise ValueError(f"this surface has no input {name!r}; it has {list(self.inputs)}")
        return self.n_w + self.inputs.index(name)

    @property
    def zone_edge(self) -> np.ndarray:
        """Mask (n,) of nodes on the outer edge of the potential contact zone (a cylinder's
        edge across its axis; none on a flat face, whose zone is the face): a load there
        means the contact would reach beyond the modelled zone."""
        from contact_core import bodies

        body = self.contact.meta.get("spec", {}).get("body")
        edge = None if body is None else bodies.get(body).zone_edge(self.contact.grid)
        return np.zeros(self.n, bool) if edge is None else np.asarray(edge, bool)

    def normal_forces(self, x: np.ndarray) -> np.ndarray:
        """Nodal compressive forces f (n,) of the modelled part at DOFs x [N] (S2 / m_i)."""
        p = x[self.d - 1:self.n_w:self.d] - self.contact.grid.h
        return np.array([el.k_n for el in self.elements]) / self.contact.grid.mult * np.maximum(p, 0.0)


def _check_tangents(tangents) -> tuple:
    tangents = tuple(tangents)
    if tangents not in (("x", "y"), ("x",)):
        raise ValueError(f"tangents must be ('x', 'y') or ('x',), got {tangents!r}")
    return tangents


def rigid_map(cc, tangents=("x", "y")) -> np.ndarray:
    """R (d n, r): relative node displacement per unit rigid input (node-major rows)."""
    tangents = _check_tangents(tangents)
    d, n, rz = len(tangents) + 1, cc.n, cc.rigid.shape[1]
    R = np.zeros((d * n, rz + len(tangents)))
    R[d - 1::d, :rz] = cc.rigid          # approach (and rotation): the closing of the gap
    for k in range(len(tangents)):
        R[k::d, rz + k] = 1.0            # tangential translations
    return R


def node_stiffness(cc, tangents=("x", "y")) -> np.ndarray:
    """A = blockdiag_d(W C_d^-1) on w, node-major, shape (d n, d n) [N/m] (S1)."""
    tangents = _check_tangents(tangents)
    blocks = [cc.Cxx, cc.Cyy][:len(tangents)] + [cc.Czz]
    if any(C is None for C in blocks):
        need = ", ".join(("z",) + tangents)
        raise ValueError(f"a contact surface needs the compliances in {need} "
                         f"(condense with directions {('z',) + tangents})")
    d, n, W = len(blocks), cc.n, np.asarray(cc.grid.mult, float)
    A = np.zeros((d * n, d * n))
    for k, C in enumerate(blocks):
        Kd = W[:, None] * np.linalg.inv(C)
        A[k::d, k::d] = 0.5 * (Kd + Kd.T)   # symmetric by reciprocity; drop round-off
    return A


def build(cc, mu: float, penalty: float = PENALTY, beta_c: float = 0.0,
          tangents=("x", "y")) -> Surface:
    """The surface model piece of a condensed pair.

    Parameters
    ----------
    cc : CondensedContact
        Condensed with directions ("z", "x", "y") (("z", "x") for tangents ("x",)).
    mu : float
        Friction coefficient (>= 0).
    penalty : float
        Contact penalty relative to each node's own body stiffness (> 1).
    beta_c : float
        Contact damping [s] of every node (ContactElement C3).
    tangents : ("x", "y") or ("x",)
        Slip directions kept: both (3D contact points, 2D Coulomb friction) or x only
        (a planar model: 2 DOFs per node, 1D Coulomb friction).

    Returns
    -------
    Surface
    """
    if not (np.isfinite(mu) and mu >= 0):
        raise ValueError(f"friction coefficient mu must be finite and >= 0, got {mu!r}")
    if not (np.isfinite(penalty) and penalty > 1):
        raise ValueError(f"penalty must be finite and > 1, got {penalty!r}")
    tangents = _check_tangents(tangents)
    A = node_stiffness(cc, tangents)
    R = rigid_map(cc, tangents)
    AR = A @ R
    K = np.block([[A, -AR], [-AR.T, R.T @ AR]])
    W = np.asarray(cc.grid.mult, float)
    k_n = penalty / np.diag(cc.Czz)
    diag_t = np.diag(cc.Cxx) if tangents == ("x",) else np.minimum(np.diag(cc.Cxx), np.diag(cc.Cyy))
    k_t = penalty / diag_t                       # one isotropic slider per node
    d, elements = len(tangents) + 1, []
    for i in range(cc.n):
        kin = Kinematics(list(range(d * i, d * i + d)), np.eye(d))
        elements.append(ContactElement.jenkins(kin, W[i] * k_n[i], W[i] * k_t[i], mu,
                                               preload=-float(cc.grid.h[i]), beta_c=beta_c,
                                               name=f"surface node {i}"))
    rot = ("rotation",) if cc.rigid.shape[1] == 2 else ()
    inputs = ("approach",) + rot + tuple(f"tangential_{t}" for t in tangents)
    return Surface(cc, 0.5 * (K + K.T), elements, inputs, tangents, float(mu), float(penalty))
