"""Kinematics of a force element: structure DOFs -> local displacements -> forces back.

A force element (:mod:`.forces`) sees ``m`` local displacements ``q`` (e.g. the
relative displacement of a friction link, or the slip and penetration of a contact
point) that are linear in the structure's DOFs::

    q(theta) = Q x_S(theta) + Q_next x_S(theta + phi)                     (K1)

``x_S`` are the DOFs listed in ``dofs`` (columns of Q); ``Q_next`` acts on the same
DOFs of the *neighbour* sector of a cyclic structure (blade j+1 of blade j), whose
harmonic-h coefficients are ``exp(i h phi)`` times the sector's (h = 0: no phase), i.e.
its time history is the sector's advanced by ``phi``. The element's local force ``f``
(conjugate to q: virtual work ``f . dq``; internal force, the sign of the left-hand
side ``K x + f_nl = f_ext``) acts back on the structure as::

    f_S = T f + R(-phi) T_next f                                          (K2)

where ``R(-phi)`` multiplies harmonic h by ``exp(-i h phi)``: the force that the
element of sector j exerts on blade j+1 is, by cyclic symmetry, the force that the
element of sector j - 1 exerts on blade j, shifted back by one sector. With
``T = Q^T`` and ``T_next = Q_next^T`` (the defaults) the coupling is conservative and
the Jacobian of a potential force stays symmetric (Hermitian per harmonic).

In the real cos/sin basis of :mod:`.fourier` (``U_h = a_h - i b_h``), multiplying by
``exp(i h phi)`` is the rotation (:func:`phase_operator`)::

    [a']   [ cos h phi   sin h phi] [a]
    [b'] = [-sin h phi   cos h phi] [b]

so (K1), (K2) become real matrices on the flattened coefficient vectors (coefficient
c of local coordinate j at ``c * m + j``, as for DOFs):
``Q_b = I (x) Q + P(phi) (x) Q_next`` and ``T_b = I (x) T + P(phi)^T (x) T_next``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .fourier import FourierBasis


def phase_operator(basis: FourierBasis, phi: float) -> np.ndarray:
    """Real (n_b, n_b) matrix of ``U_h -> exp(i h phi) U_h`` on the basis coefficients.

    Its transpose is the inverse (``exp(-i h phi)``); the zeroth harmonic is unchanged.
    """
    P = np.zeros((basis.nb, basis.nb))
    for h in basis.harmonics:
        ic, isn = basis.index(h)
        if isn is None:
            P[ic, ic] = 1.0
            continue
        c, s = np.cos(h * phi), np.sin(h * phi)
        P[ic, ic], P[ic, isn], P[isn, ic], P[isn, isn] = c, s, -s, c
    return P


def _matrix(A, rows: int | None, cols: int, name: str) -> np.ndarray:
    A = np.atleast_2d(np.asarray(A, dtype=float))
    if A.ndim != 2 or A.shape[1] != cols or (rows is not None and A.shape[0] != rows):
        want = f"({rows if rows is not None else 'm'}, {cols})"
        raise ValueError(f"{name} must have shape {want}, got {A.shape}")
    if not np.all(np.isfinite(A)):
        raise ValueError(f"{name} has non-finite entries")
    return A


@dataclass(frozen=True, init=False)
class Kinematics:
    """Linear map from structure DOFs to an element's local displacements, and back.

    Parameters
    ----------
    dofs : sequence of int, length d
        Structure DOFs (0-based) the element touches; the columns of Q, Q_next and
        the rows of T, T_next refer to them in this order.
    Q : array_like, shape (m, d)
        Local displacements from the sector's own DOFs (K1). A 1-D array is one row.
    T : array_like, shape (d, m), optional
        Local forces back onto the sector's DOFs (K2); default ``Q.T``.
    Q_next : array_like, shape (m, d), optional
        Local displacements from the neighbour sector's copy of ``dofs`` (cyclic
        symmetry; requires ``phase``). Default none.
    T_next : array_like, shape (d, m), optional
        Forces on the neighbour's DOFs, brought back with ``exp(-i h phi)``; default
        ``Q_next.T``.
    phase : float
        Interblade phase phi [rad] of the neighbour: its harmonic-h coefficients are
        ``exp(i h phi)`` times the sector's (phi = 2 pi EO / N_b).

    Attributes
    ----------
    m : int          number of local displacements
    conservative : bool  T = Q^T and T_next = Q_next^T
    """

    dofs: tuple
    Q: np.ndarray
    T: np.ndarray
    Q_next: np.ndarray | None
    T_next: np.ndarray | None
    phase: float

    def __init__(self, dofs, Q, T=None, Q_next=None, T_next=None, phase: float = 0.0):
        dofs = tuple(int(d) for d in np.atleast_1d(dofs))
        if not dofs or len(set(dofs)) != len(dofs) or min(dofs) < 0:
            raise ValueError(f"kinematics needs distinct non-negative DOFs, got {list(dofs)}")
        d = len(dofs)
        Q = _matrix(Q, None, d, "Q")
        m = Q.shape[0]
        T = Q.T.copy() if T is None else _matrix(T, d, m, "T")
        if Q_next is None:
            if T_next is not None:
                raise ValueError("T_next given without Q_next")
        else:
            Q_next = _matrix(Q_next, m, d, "Q_next")
            T_next = Q_next.T.copy() if T_next is None else _matrix(T_next, d, m, "T_next")
        if not np.isfinite(phase):
            raise ValueError(f"phase must be finite, got {phase}")
        for k, v in (("dofs", dofs), ("Q", Q), ("T", T), ("Q_next", Q_next),
                     ("T_next", T_next), ("phase", float(phase))):
            object.__setattr__(self, k, v)

    # ------------------------------------------------------------ constructors
    @classmethod
    def link(cls, dof_a: int, dof_b: int | None = None) -> Kinematics:
        """Relative displacement ``q = x_a - x_b`` (x_b = 0 for the ground), m = 1."""
        if dof_b is None:
            return cls([dof_a], [[1.0]])
        return cls([dof_a, dof_b], [[1.0, -1.0]])

    @classmethod
    def contact(cls, dofs, normal, tangents, delta, delta_next=None,
                phase: float = 0.0) -> Kinematics:
        """Contact point: local q = [t_1 . Delta, ..., -n . Delta] (slips, then penetration).

        Parameters
        ----------
        dofs : sequence of int, length d
        normal : array_like, shape (k,)
            Unit normal n of the contact in a k-dimensional frame (k = 2 or 3), pointing
            from body 2 into body 1 (the direction of the normal force on body 1).
        tangents : array_like, shape (n_t, k) or (k,)
            Unit tangent(s), orthogonal to n; the slip ``s_i = t_i . Delta``; shape
            (0, k) for a normal-only contact.
        delta : array_like, shape (k, d)
            Relative displacement ``Delta = x_point,1 - x_point,2`` of the contact point
            from the sector's DOFs (body 1 minus body 2).
        delta_next : array_like, shape (k, d), optional
            Part of Delta from the neighbour sector's DOFs (e.g. ``-P`` for a platform
            point P on blade j + 1); needs ``phase``.
        phase : float
            Interblade phase phi [rad].

        Returns
        -------
        Kinematics with m = n_t + 1 and the penetration ``p = -n . Delta`` last, so the
        local force is [f_t1, ..., N] with the internal force on body 1
        ``sum_i f_ti t_i - N n`` (the normal force on body 1 is ``+N n``).
        """
        n = np.asarray(normal, dtype=float).reshape(-1)
        t = np.atleast_2d(np.asarray(tangents, dtype=float))
        if t.shape[1] != n.size or abs(np.linalg.norm(n) - 1.0) > 1e-12:
            raise ValueError("normal must be a unit vector and tangents (n_t, k) with its k")
        if t.size and (np.abs(t @ n).max() > 1e-12
                       or np.abs(np.linalg.norm(t, axis=1) - 1.0).max() > 1e-12):
            raise ValueError("tangents must be unit vectors orthogonal to the normal")
        L = np.vstack([t, -n])  # (m, k): local coordinates of Delta
        d = len(np.atleast_1d(dofs))
        Q = L @ _matrix(delta, n.size, d, "delta")
        Qn = None if delta_next is None else L @ _matrix(delta_next, n.size, d, "delta_next")
        return cls(dofs, Q, Q_next=Qn, phase=phase)

    # ------------------------------------------------------------ properties
    @property
    def m(self) -> int:
        return self.Q.shape[0]

    @property
    def cyclic(self) -> bool:
        return self.Q_next is not None

    @property
    def conservative(self) -> bool:
        same = np.array_equal(self.T, self.Q.T)
        return same and (self.Q_next is None or np.array_equal(self.T_next, self.Q_next.T))

    # ------------------------------------------------------------ operators
    def operators(self, basis: FourierBasis, dofs=None):
        """Real harmonic operators on flattened coefficient vectors.

        Parameters
        ----------
        basis : FourierBasis
        dofs : sequence of int, optional
            DOF set of the unknown vector (default ``self.dofs``); must contain
            ``self.dofs``. Unknowns ordered coefficient-major (c * len(dofs) + i).

        Returns
        -------
        Qb : (n_b m, n_b len(dofs)) array   local harmonics = Qb @ x
        Tb : (n_b len(dofs), n_b m) array   DOF force harmonics = Tb @ local forces
        """
        dofs = self.dofs if dofs is None else tuple(int(d) for d in dofs)
        pos = {d: i for i, d in enumerate(dofs)}
        try:
            cols = [pos[d] for d in self.dofs]
        except KeyError as err:
            raise ValueError(f"DOF {err.args[0]} of the element is not in the DOF set") from None
        Qs = np.zeros((self.m, len(dofs)))
        Ts = np.zeros((len(dofs), self.m))
        Qs[:, cols], Ts[cols, :] = self.Q, self.T
        eye = np.eye(basis.nb)
        Qb, Tb = np.kron(eye, Qs), np.kron(eye, Ts)
        if self.cyclic:
            P = phase_operator(basis, self.phase)
            Qn = np.zeros_like(Qs)
            Tn = np.zeros_like(Ts)
            Qn[:, cols], Tn[cols, :] = self.Q_next, self.T_next
            Qb += np.kron(P, Qn)
            Tb += np.kron(P.T, Tn)
        return Qb, Tb

    def local(self, x: np.ndarray) -> np.ndarray:
        """Local displacements (m,) at one instant from all DOFs x (n,) (non-cyclic only)."""
        if self.cyclic:
            raise ValueError("a cyclic element has no single-instant map (needs the neighbour)")
        return self.Q @ np.asarray(x)[list(self.dofs)]

    def scatter(self, f: np.ndarray, n: int) -> np.ndarray:
        """Structure force (n,) of local forces f (m,) at one instant (non-cyclic only)."""
        if self.cyclic:
            raise ValueError("a cyclic element has no single-instant map (needs the neighbour)")
        out = np.zeros(n)
        out[list(self.dofs)] = self.T @ f
        return out
