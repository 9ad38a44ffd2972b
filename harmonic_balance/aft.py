"""Alternating frequency-time (AFT) evaluation of the friction elements (or exact).

One friction link joins DOF ``a`` to DOF ``b`` (or to the ground); its relative
displacement is ``u = x_a - x_b`` and its force ``F(u)`` enters the internal force
vector (left-hand side of the equation of motion) as ``+F`` at ``a`` and ``-F`` at ``b``.

For harmonics ``U`` (n_b,) of ``u`` the AFT is (symbols in :mod:`fourier`)::

    u = E U  (n_t samples)  ->  F(t), dF/dU  (C core, one call)  ->  F_h = D F,
    dF_h/dU = D (dF/dU)

The C core returns dF/dU exactly, including the dependence of each sticking slider
on the sample where it last stuck (its reversal point), so the Jacobian is exact for
the sampled loop (not a tangent-stiffness approximation).

Exact links
-----------
A link with ``exact=True`` skips the sampling: the C core locates the extrema of u(theta)
(a trigonometric polynomial), runs the loop between them as piecewise-linear branches
and integrates F(theta) in closed form (``IwanElement.periodic_fourier``): no sampling
error and no kinks where a stick episode starts or ends between samples. The default of
forced-response curves for every Iwan link (``frf.exact_links``); the sampled AFT stays
for elements without the exact path and on request (``compute_frf(aft="sampled")``).

Zeroth-harmonic convention for a fully stuck element
----------------------------------------------------
A loop that never slips over the period has no memory of where the sliders stuck:
any constant offset of the force is a periodic solution, so the mean force (the
zeroth harmonic) is not unique. We fix it physically, as the C core's periodic loop
does: a fully stuck element (no energy dissipated over the cycle) is taken to have
stuck since its virgin state at the contact's reference position ``u = 0`` (the damper
was pressed in without a tangential preload), so it acts as its initial linear spring,
``F = k_0 u``, as long as that stays within the slip limits; where a static load would
carry it past them, each slider is shifted by the least amount that keeps it within
them (the C core's loop and exact Jacobian are kept then). With no static load (mean
displacement zero) this joins continuously to the slipping loops, whose mean force is
unique. It only matters when harmonic 0 is retained. A structure started from rest may
settle at another mean (:mod:`steady_state` checks which).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .forces import ForceElement, LocalForce
from .fourier import FourierBasis
from .kinematics import Kinematics


@dataclass
class FrictionLink(ForceElement):
    """A friction element between two DOFs, or a DOF and the ground.

    A :class:`~.forces.ForceElement` on ``Kinematics.link(dof_a, dof_b)`` (m = 1) at
    the element's reference normal load.

    Parameters
    ----------
    element : object
        Has ``periodic_jac(u, Eu) -> (F, dFdX, dFdXN, W_cycle)`` (``fmu_src.element.IwanElement``).
    dof_a : int
        DOF where the force acts with + sign (u = x_a - x_b).
    dof_b : int or None
        Second DOF, or None for the ground.
    name : str
        Label used in messages.
    exact : bool
        True: the force harmonics are the exact Fourier coefficients of the loop (the C
        core's ``periodic_fourier``: no AFT sampling, :func:`aft_link`; the default of
        ``frf.compute_frf``, :func:`frf.exact_links`).
    """

    element: object
    dof_a: int
    dof_b: int | None = None
    name: str = ""
    exact: bool = False
    _k0: float | None = field(default=None, repr=False)

    @property
    def k0(self) -> float:
        """Initial (fully stuck) stiffness of the element [N/m]."""
        if self._k0 is None:
            self._k0 = initial_stiffness(self.element)
        return self._k0

    @property
    def dofs(self) -> tuple[int, ...]:
        return (self.dof_a,) if self.dof_b is None else (self.dof_a, self.dof_b)

    @property
    def kinematics(self) -> Kinematics:
        """``q = x_a - x_b`` (built on use: a link joining a DOF to itself is refused by Model)."""
        return Kinematics.link(self.dof_a, self.dof_b)

    @property
    def m(self) -> int:
        return 1

    def evaluate(self, U, basis: FourierBasis, omega: float, jac: bool = True) -> LocalForce:
        """:func:`aft_link` on U (n_b, 1) (without ``jac``: the loop alone, no Jacobian)."""
        U = np.asarray(U, dtype=float).reshape(basis.nb)
        Fh, dFh, W, F = aft_link(self, U, basis, jac)
        return _LinkForce(Fh[:, None], dFh, W, None if F is None else F[:, None], basis.E, U)

    def stuck_stiffness(self) -> np.ndarray:
        return np.array([[self.k0]])

    def stepper(self):
        """One C-element step per call on the carried (virgin) state."""
        el = self.element
        state = el.initial_state()

        class _Link:
            def force(self, q):
                return np.array([el.step(state, q[0]).F])

        return _Link()


class _LinkForce(LocalForce):
    """:class:`~.forces.LocalForce` of a link whose samples ``q`` = E U are formed when first
    read: a Newton iteration reads only F and dF, and E U costs O(n_t n_b) a call (at
    H = 31 on 1024 samples as much as the exact link's own evaluation)."""

    def __init__(self, F, dF, W, f, E, U):
        self.F, self.dF, self.dF_domega, self.W, self.W_viscous, self.f = F, dF, None, W, 0.0, f
        self._E, self._U, self._q = E, U, None

    @property
    def q(self) -> np.ndarray:
        if self._q is None:
            self._q = (self._E @ self._U)[:, None]
        return self._q


def initial_stiffness(element) -> float:
    """Stuck stiffness k_0 [N/m] of an Iwan element: its slider springs plus the residual one."""
    k, k_res = getattr(element, "k", None), getattr(element, "k_res", None)
    if k is None or k_res is None:
        raise TypeError(f"{type(element).__name__} has no slider stiffnesses k and k_res")
    return float(np.sum(k) + k_res)


def aft_link(link: FrictionLink, U: np.ndarray, basis: FourierBasis, jac: bool = True):
    """Harmonics of one link's force and their exact Jacobian.

    Parameters
    ----------
    link : FrictionLink
    U : (n_b,) array
        Harmonics of the relative displacement u = x_a - x_b [m].
    basis : FourierBasis
    jac : bool
        False: the loop alone (``periodic``, no Jacobian; dFh is None), e.g. the
        residual differences of a parameter continuation.

    Returns
    -------
    Fh : (n_b,) array      harmonics of the force [N]
    dFh : (n_b, n_b) array dFh / dU [N/m], or None without ``jac``
    W : float              energy dissipated per cycle by the (sampled) loop [J]
    F : (n_t,) array       force samples [N] (None for an exact link's Newton step)

    An ``exact`` link takes its harmonics from the C core's ``periodic_fourier``: the
    extrema of u located exactly, the loop between them piecewise linear, integrated in
    closed form, so there is no sampling error and no kink where a stick episode starts
    or ends between samples (on a 1e6 k contact the sampled loop needed 8192 samples and
    its kinks cost 5.4 evaluations per FRF point; exact: 512-sample scan, 3.6 per point).
    Its samples (plots, energy) are the sampled loop's; the stuck test reads its harmonics.
    """
    el = link.element
    stuck_test = basis.harmonics[0] == 0
    exact = link.exact and hasattr(el, "periodic_fourier")
    if exact:
        Fh, dFh, W, n_ext = el.periodic_fourier(basis.harmonics, U, basis.n_t)
        # n_ext odd, or none for a varying u: the scan lost an extremum (the C core says
        # so instead of a wrong number); this evaluation falls back to the sampled loop
        exact = n_ext % 2 == 0 and (n_ext >= 2 or np.ptp(basis.E @ U) == 0.0)
    if exact:
        # the samples u = E U (O(n_t n_b)) only where they are returned: no jac, a stuck loop
        if n_ext == 0:   # u constant: the stuck line (the C core returns zeros there)
            return link.k0 * U, link.k0 * np.eye(basis.nb) if jac else None, 0.0, link.k0 * (basis.E @ U)
        if stuck_test and W <= 0.0 and _stuck_harmonics(Fh, U, link.k0):
            # Fully stuck: the virgin-state convention of the module docstring
            return link.k0 * U, link.k0 * np.eye(basis.nb) if jac else None, float(W), \
                link.k0 * (basis.E @ U)
        F = None if jac else el.periodic(basis.E @ U).F
        return Fh, dFh if jac else None, float(W), F
    u = basis.E @ U
    if not jac and hasattr(el, "periodic"):
        loop = el.periodic(u)
        F, dFh, W = loop.F, None, loop.W_cycle
    elif not hasattr(el, "periodic_jac_rows"):   # e.g. the cubic spring: dense dF
        F, dF, _, W = el.periodic_jac(u, basis.E)
        dFh = _project_rows(basis.D, np.asarray(dF, dtype=float)) if jac else None
    else:
        # Only the samples where a slider sticks depend on U (a slipping slider carries
        # +-f_s): the C core returns those rows alone (on a stiff contact in gross slip a
        # few per cent of them), so D dF costs O(stuck samples x n_b), not O(n_t x n_b).
        F, rows, dFr, _, W = el.periodic_jac_rows(u, basis.E)
        dFh = basis.D[:, rows] @ dFr
    if stuck_test and W <= 0.0 and _stuck(F, u, link.k0):
        # Stuck since the virgin state, unshifted (module docstring): the linear spring.
        F = link.k0 * u
        return basis.D @ F, link.k0 * _projector(basis) if jac else None, float(W), F
    return basis.D @ F, dFh, float(W), F


def _projector(basis: FourierBasis) -> np.ndarray:
    """D E (n_b, n_b), the identity to round-off, kept per basis: the stuck line's
    Jacobian, whose product cost O(n_t n_b^2) per call (at H = 31, a millisecond)."""
    cache = basis.__dict__.setdefault("_projector_cache", [])
    if not cache:
        cache.append(basis.D @ basis.E)
    return cache[0]


def _project_rows(D, dF):
    """``D @ dF`` over the samples where dF has a non-zero row only (dense dF from an
    element without :meth:`periodic_jac_rows`, e.g. the cubic spring).

    Zero rows add nothing; the row test by squares (twice as fast as ``any``) drops only
    rows below ~1e-154, whose terms are below double precision anyway.
    """
    rows = np.flatnonzero(np.einsum("ij,ij->i", dF, dF))
    if rows.size > 0.5 * dF.shape[0]:
        return D @ dF
    return D[:, rows] @ dF[rows]


#: Relative round-off allowance when deciding that a loop is a straight stuck line.
STUCK_RTOL = 1e-12


def _stuck_harmonics(Fh, U, k0) -> bool:
    """:func:`_stuck` on an exact loop's harmonics: F = k0 u when every harmonic of
    F - k0 u vanishes, the mean included (a stuck line shifted by a static load past the
    slip limits is the C core's loop, kept), to STUCK_RTOL of the loop's size (no samples)."""
    dev = np.abs(Fh - k0 * U).max()
    return bool(dev <= STUCK_RTOL * (k0 * np.abs(U).max() + np.abs(Fh).max() + 1e-300))


def _stuck(F, u, k0) -> bool:
    """True when the loop is the virgin stuck line F = k0 u (no slip anywhere, no shift).

    W = 0 alone is not enough: a slider of zero strength slips freely without
    dissipating (the free limit, F = 0). A stuck line shifted to stay within the slip
    limits (F = k0 u - s, s != 0: a static load past them) is the C core's loop, kept.
    """
    dev = np.abs(F - k0 * u).max()
    return bool(dev <= STUCK_RTOL * (k0 * np.abs(u).max() + np.abs(F).max() + 1e-300))
