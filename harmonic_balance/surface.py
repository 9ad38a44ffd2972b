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
    w       (3 n,) relative displacements of the node pairs, node-major
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

Contact at node i (one ContactElement on [w_ix, w_iy, w_iz])::

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
#: Names of the rigid inputs q, by position (the rotation only on a flat face).
INPUTS_FLAT = ("approach", "rotation", "tangential_x", "tangential_y")
INPUTS = ("approach", "tangential_x", "tangential_y")


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
        The condensed pair (needs Czz, Cxx and Cyy).
    K : ndarray, shape (3 n + r, 3 n + r)
        Stiffness on x = [w; q] [N/m, N, N m] (S1).
    elements : list of ContactElement
        One per node, on DOFs (3 i, 3 i + 1, 3 i + 2), weighted by m_i (S2, S3).
    inputs : tuple of str
        Names of the r rigid inputs, DOFs 3 n ... 3 n + r - 1.
    mu : float
        Friction coefficient.
    penalty : float
        Penalty factor (module docstring).
    """

    contact: object
    K: np.ndarray
    elements: list
    inputs: tuple
    mu: float
    penalty: float

    @property
    def n(self) -> int:
        """Number of surface nodes."""
        return self.contact.n

    @property
    def n_dof(self) -> int:
        """Number of DOFs, 3 n + r."""
        return self.K.shape[0]

    def input_dof(self, name: str) -> int:
        """DOF index of a rigid input by name (``inputs``)."""
        if name not in self.inputs:
            raise ValueError(f"this surface has no input {name!r}; it has {list(self.inputs)}")
        return 3 * self.n + self.inputs.index(name)

    def normal_forces(self, x: np.ndarray) -> np.ndarray:
        """Nodal compressive forces f (n,) of the modelled part at DOFs x [N] (S2 / m_i)."""
        p = x[2:3 * self.n:3] - self.contact.grid.h
        return np.array([el.k_n for el in self.elements]) / self.contact.grid.mult * np.maximum(p, 0.0)


def rigid_map(cc) -> np.ndarray:
    """R (3 n, r): relative node displacement per unit rigid input (node-major rows)."""
    n, rz = cc.n, cc.rigid.shape[1]
    R = np.zeros((3 * n, rz + 2))
    R[2::3, :rz] = cc.rigid          # approach (and rotation): the closing of the gap
    R[0::3, rz] = 1.0                # tangential x
    R[1::3, rz + 1] = 1.0            # tangential y
    return R


def node_stiffness(cc) -> np.ndarray:
    """A = blockdiag_d(W C_d^-1) on w, node-major, shape (3 n, 3 n) [N/m] (S1)."""
    blocks = (cc.Cxx, cc.Cyy, cc.Czz)
    if any(C is None for C in blocks):
        raise ValueError("a contact surface needs the compliances in z, x and y "
                         "(condense with directions ('z', 'x', 'y'))")
    n, W = cc.n, np.asarray(cc.grid.mult, float)
    A = np.zeros((3 * n, 3 * n))
    for d, C in enumerate(blocks):
        Kd = W[:, None] * np.linalg.inv(C)
        A[d::3, d::3] = 0.5 * (Kd + Kd.T)   # symmetric by reciprocity; drop round-off
    return A


def build(cc, mu: float, penalty: float = PENALTY, beta_c: float = 0.0) -> Surface:
    """The surface model piece of a condensed pair.

    Parameters
    ----------
    cc : CondensedContact
        Condensed with directions ("z", "x", "y").
    mu : float
        Friction coefficient (>= 0).
    penalty : float
        Contact penalty relative to each node's own body stiffness (> 1).
    beta_c : float
        Contact damping [s] of every node (ContactElement C3).

    Returns
    -------
    Surface
    """
    if not (np.isfinite(mu) and mu >= 0):
        raise ValueError(f"friction coefficient mu must be finite and >= 0, got {mu!r}")
    if not (np.isfinite(penalty) and penalty > 1):
        raise ValueError(f"penalty must be finite and > 1, got {penalty!r}")
    A = node_stiffness(cc)
    R = rigid_map(cc)
    AR = A @ R
    K = np.block([[A, -AR], [-AR.T, R.T @ AR]])
    W = np.asarray(cc.grid.mult, float)
    k_n = penalty / np.diag(cc.Czz)
    k_t = penalty / np.minimum(np.diag(cc.Cxx), np.diag(cc.Cyy))  # one isotropic slider
    elements = []
    for i in range(cc.n):
        kin = Kinematics([3 * i, 3 * i + 1, 3 * i + 2], np.eye(3))
        elements.append(ContactElement.jenkins(kin, W[i] * k_n[i], W[i] * k_t[i], mu,
                                               preload=-float(cc.grid.h[i]), beta_c=beta_c,
                                               name=f"surface node {i}"))
    inputs = INPUTS_FLAT if cc.rigid.shape[1] == 2 else INPUTS
    return Surface(cc, 0.5 * (K + K.T), elements, inputs, float(mu), float(penalty))
