"""Many contact elements evaluated together (e.g. the contacts of a mistuned ring).

:func:`evaluate_many` gives the :meth:`~.contact.ContactElement.evaluate` of many
elements with the same m; one-tangent contacts (m = 2) go through
:class:`LineContacts`: the sampling, the normal law (C1), the projection of the forces
and the dashpots (C3) are one numpy pass over all of them, their friction loops (C2)
one C call (``iwan_periodic_jac_many`` with the Jacobian, ``iwan_periodic_many``
without). A caller that evaluates the same contacts many times (a Newton iteration)
keeps one :class:`LineContacts` and passes it as the elements: their constants (k_n,
p_0, s_0, the C pointers, the full-contact normal blocks, the dashpots' operators) are
then read once. Symbols and laws as in :mod:`.contact`.
"""
from __future__ import annotations

import numpy as np

from .contact import TERMS_MIN_WORK, ContactElement, normal_law
from .fourier import FourierBasis


class LineContacts:
    """One-tangent contacts (m = 2, with friction) on one basis, their constants read once.

    A sequence of its elements (``len``, iteration, indexing), so it can stand for
    them wherever a list of elements is expected. The elements' parameters (k_n,
    preload, slip_ref, beta_c, the friction law, max_periods, tol) are read here: build
    a new one after changing any of them.

    Parameters
    ----------
    elements : sequence of n_e ContactElement, each ``m == 2`` with a friction element
    basis : FourierBasis
    """

    def __init__(self, elements, basis: FourierBasis):
        from fmu_src.element_batch import PeriodicBatch

        self.elements, self.basis = list(elements), basis
        if not self.elements or not all(is_line_contact(el) for el in self.elements):
            raise ValueError("LineContacts needs one-tangent contact elements with friction")
        els = self.elements
        self.kn = np.array([el.k_n for el in els])
        self._kn, self._p0 = self.kn[:, None], np.array([el.preload for el in els])[:, None]
        self._s0 = np.array([el.slip_ref for el in els])[:, None]
        self._march = {(el.max_periods, el.tol) for el in els}
        # one C call needs one closure rule; else each element's own path (jac or not)
        self.one_call = len(self._march) == 1
        self._batch = PeriodicBatch([el.friction for el in els],
                                    [el._cached(basis, "EN") for el in els])
        self._knn = None
        self._ops = None
        if any(el.beta_c != 0.0 for el in els):
            nb = basis.nb
            self._ops = np.array([el._damping_operator(basis) if el.beta_c != 0.0
                                  else np.zeros((2 * nb, 2 * nb)) for el in els])

    def __len__(self) -> int:
        return len(self.elements)

    def __iter__(self):
        return iter(self.elements)

    def __getitem__(self, i):
        return self.elements[i]

    def evaluate(self, U, omega: float, jac: bool = True):
        """:func:`evaluate_many` of these contacts: U (n_e, n_b, 2) -> (F, dF, dF_domega)."""
        basis, els = self.basis, self.elements
        n_e, nb = U.shape[:2]
        E, D = basis.E, basis.D
        pl = U[:, :, 1] @ E.T                                   # (n_e, n_t) penetration
        f = np.empty((n_e, basis.n_t, 2))
        p, on, f[:, :, 1] = normal_law(self._kn, self._p0, pl)
        dF = np.zeros((n_e, 2 * nb, 2 * nb)) if jac else None
        if self.one_call:
            s = U[:, :, 0] @ E.T                                # (n_e, n_t) slip
            (mp, tol), = self._march
            if jac:
                Ft, dFs, dFp, _ = self._batch.jac(s - self._s0, E, self._kn * p, mp, tol)
                dF[:, 0::2, 0::2], dF[:, 0::2, 1::2] = D @ dFs, D @ dFp
            else:
                Ft = self._batch.loops(s - self._s0, self._kn * p, mp, tol)[0]
            f[:, :, 0] = Ft
        if jac:
            dF[:, 1::2, 1::2] = self._normal_blocks(on)          # dN/dU_p (C1)
        if not self.one_call:  # each element's own friction path, into its rows of f and dF
            for i, el in enumerate(els):
                el._evaluate_line(U[i], basis, p[i], f[i], dF[i] if jac else None)
        F = D @ f                                                # (n_e, n_b, 2)
        dw = None
        if self._ops is not None:
            dw = (self._ops @ U.reshape(n_e, 2 * nb, 1))[:, :, 0]
            F += omega * dw.reshape(n_e, nb, 2)
            if jac:
                dF += omega * self._ops
        return F, dF, dw

    def _normal_blocks(self, on):
        """dN/dU_p harmonics D diag(k_n on) E of each element (n_e, n_b, n_b): the full
        contact block (each element's cached one) where an element is in contact
        throughout, else from the weights' Fourier coefficients
        (:meth:`.FourierBasis.weighted`, one FFT for all: the product of
        :meth:`.ContactElement._normal_block` to round-off, at a fraction of its flops)."""
        basis = self.basis
        full = on.all(axis=1)
        out = np.empty((len(self.elements), basis.nb, basis.nb))
        if full.any():
            if self._knn is None:
                ones = np.ones(basis.n_t, dtype=bool)
                self._knn = np.array([el._cached(basis, "Knn", ones) for el in self.elements])
            out[full] = self._knn[full]
        part = ~full
        if part.any():
            out[part] = basis.weighted(self._kn[part] * on[part])
        return out


def is_line_contact(el) -> bool:
    """Whether ``el`` is a one-tangent contact element with friction (what
    :class:`LineContacts` takes)."""
    return isinstance(el, ContactElement) and el.m == 2 and el.friction is not None


def evaluate_many(elements, U, basis: FourierBasis, omega: float, jac: bool = True):
    """:meth:`~.contact.ContactElement.evaluate` of many elements with the same m, batched.

    One-tangent contacts go through :class:`LineContacts` (module docstring; ``elements``
    may be one, made on ``basis``, whose constants are then reused). A one-tangent
    contact whose Jacobian the single path would project from sparse terms
    (:data:`~.contact.TERMS_MIN_WORK`), a two-tangent or normal-only one, or an element
    that is no ContactElement is evaluated by its own ``evaluate``. Same numbers as the
    single path to round-off (the batched products sum in another order).

    Parameters
    ----------
    elements : sequence of n_e ForceElement, each with ``m`` local coordinates, or a
        :class:`LineContacts`
    U : (n_e, n_b, m) array   local harmonics of each element
    basis : FourierBasis
    omega : float             [rad/s]
    jac : bool

    Returns
    -------
    F : (n_e, n_b, m) array            harmonics of the local forces [N]
    dF : (n_e, n_b m, n_b m) or None   dF/dU (rows/cols c m + j), with ``jac``
    dF_domega : (n_e, n_b m) or None   dF/domega, None when no element has one
    """
    U = np.asarray(U, dtype=float)
    n_e, nb = U.shape[0], basis.nb
    terms = jac and nb * nb * basis.n_t >= TERMS_MIN_WORK
    lines = elements if isinstance(elements, LineContacts) and elements.basis is basis else None
    if lines is None and not terms and all(is_line_contact(el) for el in elements):
        lines = LineContacts(elements, basis)
    if lines is None or terms:
        res = [el.evaluate(u, basis, omega, jac) for el, u in zip(elements, U)]
        dws = [r.dF_domega for r in res]
        dw = None
        if any(v is not None for v in dws):
            dw = np.array([np.zeros(U[0].size) if v is None else v for v in dws])
        return (np.array([r.F for r in res]), np.array([r.dF for r in res]) if jac else None, dw)
    return lines.evaluate(U.reshape(n_e, nb, 2), float(omega), jac)
