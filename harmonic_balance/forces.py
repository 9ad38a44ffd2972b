"""Force elements: local laws evaluated on their own kinematics, with exact Jacobians.

A force element owns a :class:`~.kinematics.Kinematics` (which DOFs it touches, Q from
DOFs to its ``m`` local displacements q, T back, an optional cyclic neighbour) and a
local law ``f(q(theta), dq/dtheta)`` over one period. The harmonic-balance residual
(:mod:`.residual`) only does::

    U = Q_b x                   (local harmonics, (n_b, m))
    F, dF/dU, dF/domega = element.evaluate(U, basis, omega)   (AFT or closed form)
    F_nl = T_b F,  dF_nl/dx = T_b (dF/dU) Q_b,  dF_nl/domega = T_b dF/domega

so a new law only implements :meth:`ForceElement.evaluate` (and, for time
integration, :meth:`ForceElement.stepper`). Harmonics are flattened coefficient-major
(coefficient c of local coordinate j at ``c * m + j``, as in :mod:`.fourier`). Local
forces are internal forces (left-hand side of ``M x'' + C x' + K x + f_nl = f_ext``),
conjugate to q.

Elements here: :class:`LinearElement` (springs and dashpots on any kinematics, e.g.
a cyclic rim coupling ``k_c (u_j - u_(j+1))``); :class:`~.aft.FrictionLink` (Iwan
element on ``x_a - x_b`` at constant normal load); :class:`~.contact.ContactElement`
(penalty normal with lift-off + friction following N + optional dashpots).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .fourier import FourierBasis
from .kinematics import Kinematics


@dataclass
class LocalForce:
    """Result of one element evaluation over a period.

    Attributes
    ----------
    F : (n_b, m) array          harmonics of the local forces [N]
    dF : (n_b m, n_b m) array or None
        dF/dU on flattened coefficient-major vectors [N/m] (None when not requested)
    dF_domega : (n_b m,) array or None
        d F / d omega at fixed U [N s] (None: rate-independent, zero)
    W : float                   energy dissipated per cycle by the element [J]
    W_viscous : float           the part of W done by the element's linear dashpots [J]
    q : (n_t, m) array or None  local displacements over the period (AFT samples) [m]
    f : (n_t, m) array or None  local forces over the period [N]
    """

    F: np.ndarray
    dF: np.ndarray | None
    dF_domega: np.ndarray | None = None
    W: float = 0.0
    W_viscous: float = 0.0
    q: np.ndarray | None = None
    f: np.ndarray | None = None


class ForceElement:
    """Base class of force elements (see the module docstring).

    Subclasses set ``self.kinematics`` and ``self.name`` and implement
    :meth:`evaluate`; the other methods have defaults for rate-independent,
    unloaded-at-rest elements.
    """

    kinematics: Kinematics
    name: str = ""

    @property
    def dofs(self) -> tuple[int, ...]:
        """Structure DOFs the element touches."""
        return self.kinematics.dofs

    @property
    def m(self) -> int:
        """Number of local displacements."""
        return self.kinematics.m

    def evaluate(self, U: np.ndarray, basis: FourierBasis, omega: float,
                 jac: bool = True) -> LocalForce:
        """Local force harmonics of local displacement harmonics U (n_b, m)."""
        raise NotImplementedError

    def stuck_stiffness(self) -> np.ndarray:
        """Local stiffness (m, m) [N/m] of the element fully stuck / in contact.

        Used for start guesses and the time-integration step bound.
        """
        raise NotImplementedError

    def local_damping(self) -> np.ndarray | None:
        """Linear viscous part (m, m) [N s/m] of the law (in :meth:`evaluate`), or None."""
        return None

    def static_force(self) -> np.ndarray:
        """Local force (m,) at q = 0 [N] (a preload; zero by default)."""
        return np.zeros(self.m)

    def stepper(self):
        """Time-domain law for :mod:`harmonic_balance.timeint`: an object with ``force(q) -> f`` (m,).

        Each call advances the element's history to the local displacement q (m,)
        and returns the rate-independent local force; the linear viscous part
        (:meth:`local_damping`) is added to the structure's C by the integrator.
        """
        raise NotImplementedError(f"{type(self).__name__} has no time-domain law")


def viscous_work(C: np.ndarray, U: np.ndarray, basis: FourierBasis, omega: float) -> float:
    """Energy [J] dissipated per cycle by dashpots C (m, m) on local harmonics U (n_b, m).

    For q = a cos(h theta) + b sin(h theta): ``pi h^2 omega (a.C a + b.C b)``; summed
    over the coefficient rows (the mean, h = 0, does no work).
    """
    quad = np.einsum("ij,jk,ik->i", U, C, U)
    return float(np.pi * omega * (basis.order.astype(float) ** 2) @ quad)


def harmonic_work(U: np.ndarray, F: np.ndarray, basis: FourierBasis) -> float:
    """Work per cycle [J] of local forces F on local displacements U (both (n_b, m) harmonics).

    ``oint f . dq = pi sum_h h (F_a . b - F_b . a)`` for q = a cos + b sin, f = F_a cos +
    F_b sin (harmonic h). At an HB solution the excitation's work equals the linear
    damping's plus every element's harmonic work (to the residual), which makes it the
    consistent dissipation for energy balances; ``LocalForce.W`` is the work of the
    sampled loop (differs by the AFT sampling).
    """
    w = 0.0
    for h in basis.harmonics:
        if h == 0:
            continue
        ic, isn = basis.index(h)
        w += np.pi * h * (F[ic] @ U[isn] - F[isn] @ U[ic])
    return float(w)


def _damping_terms(C: np.ndarray, U: np.ndarray, basis: FourierBasis, omega: float, op=None):
    """Viscous force harmonics omega (D_theta (x) C) U, its Jacobian and d/domega
    (``op``: D_theta (x) C when the caller keeps it)."""
    op = np.kron(basis.dtheta, C) if op is None else op
    dw = op @ U.ravel()
    return omega * dw, omega * op, dw


class LinearElement(ForceElement):
    """Linear springs and dashpots on local displacements: f = K q + C dq/dt.

    Exact in harmonics (no time samples): ``F = (I (x) K + omega D_theta (x) C) U``.
    With cyclic kinematics it gives the per-harmonic structural coupling K(h phi),
    e.g. ``Kinematics([r], [[1]], Q_next=[[-1]], phase=phi)`` and ``K = [[k_c]]``
    adds ``2 k_c (1 - cos h phi)`` to DOF r's harmonic-h stiffness.

    Parameters
    ----------
    kinematics : Kinematics
    K : array_like (m, m)      local stiffness [N/m]
    C : array_like (m, m), optional  local viscous damping [N s/m]
    name : str
    """

    def __init__(self, kinematics: Kinematics, K, C=None, name: str = ""):
        m = kinematics.m
        self.kinematics, self.name = kinematics, name
        self.K = np.asarray(K, dtype=float).reshape(m, m)
        self.C = None if C is None else np.asarray(C, dtype=float).reshape(m, m)

    def evaluate(self, U, basis, omega, jac=True) -> LocalForce:
        U = np.asarray(U, dtype=float).reshape(basis.nb, self.m)
        F = U @ self.K.T
        dF = self._operators(basis)[0] if jac else None
        dw, W = None, 0.0
        if self.C is not None:
            Fc, dFc, dw = _damping_terms(self.C, U, basis, omega, self._operators(basis)[1])
            F = F + Fc.reshape(basis.nb, self.m)
            if jac:
                dF = dF + dFc
            W = viscous_work(self.C, U, basis, omega)
        return LocalForce(F, dF, dw, W, W)

    def _operators(self, basis):
        """(I (x) K, D_theta (x) C or None), (n_b m, n_b m) each, kept per basis and
        matrices (the same numbers as built at every call)."""
        key = (basis.harmonics, self.K.tobytes(), None if self.C is None else self.C.tobytes())
        if getattr(self, "_ops", (None,))[0] != key:
            self._ops = (key, (np.kron(np.eye(basis.nb), self.K),
                               None if self.C is None else np.kron(basis.dtheta, self.C)))
        return self._ops[1]

    def stuck_stiffness(self) -> np.ndarray:
        return self.K

    def local_damping(self):
        return self.C

    def stepper(self):
        K = self.K

        class _Linear:
            def force(self, q):
                return K @ q

        return _Linear()
