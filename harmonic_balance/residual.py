"""Harmonic-balance residuals R(x, omega) with exact Jacobians.

Full residual (all n DOFs; unknowns X (n_b, n), flattened as in :mod:`fourier`)::

    R = A(omega) X + F_nl(X) - F_ext,
    A(omega) = I (x) K - omega^2 diag(h^2) (x) M + omega D_theta (x) C

where ``D_theta`` is d/dtheta in coefficient space (so omega D_theta X are the velocity
harmonics) and ``(x)`` the Kronecker product. F_nl = T F(Q X) comes from the force
elements (:mod:`forces`: each maps its local harmonics Q X to force harmonics, by AFT
or in closed form); rate-independent elements do not depend on omega, dashpots in
elements add their omega-derivative ``dF_nl/domega``, so
``dR/domega = (-2 omega diag(h^2) (x) M + D_theta (x) C) X + dF_nl/domega``.

Condensed residual (unknowns: the harmonics of the m DOFs the force elements touch,
set J)::

    R = X_J - G_JJ(omega) F_ext - ... = X_J - X_lin,J(omega) + G_JJ(omega) F_nl,J(X_J)

with the receptance G of the linear part per harmonic (:mod:`linear`), so the
unknowns and the cost do not grow with the size of the linear model (modal G).
Both return ``R (N,), dR/dx (N, N), dR/domega (N,)``.
"""
from __future__ import annotations

import copy

import numpy as np

from .fourier import FourierBasis
from .model import Model


class _Residual:
    """Shared assembly of the force elements (:mod:`.forces`) on a set of 'active' DOFs.

    Element e has harmonic operators Q_e (n_b m_e, size), T_e (size, n_b m_e) from its
    kinematics; they are stacked element by element into Q (sum n_b m_e, size) and
    T (size, sum n_b m_e), so U = Q x and F_nl = T F.
    The Jacobian dF_nl/dx = sum_e T_e (dF_e/dU_e) Q_e is assembled element by element
    on the unknowns the element touches (rows ``r_e``: its DOFs in every harmonic):
    ``T_e[r_e] dF_e Q_e[:, r_e]`` by products over the local index, O(n_b^2) per
    element, added into the (size, size) matrix, instead of dense products of the whole
    (size, sum n_b m_e) operators, O(n_b^3 n m) (at H = 31 on a 5-DOF chain with three
    links, 80 % of a curve's time; :class:`_LocalMap`); a link (one local displacement,
    no neighbour) adds dF_e times (T Q)_ij straight into the strided view of each of its
    DOF pairs (i, j). When every element is conservative, Q is T's transpose (a view).
    """

    def __init__(self, model: Model, basis: FourierBasis, dofs):
        self.model, self.basis = model, basis
        self.dofs = np.asarray(dofs, dtype=int)
        self.m = self.dofs.size
        self.size = basis.nb * self.m
        self.Fext = model.forcing_coeffs(basis)  # (nb, n)
        self.elements = list(model.elements)
        ops = [el.kinematics.operators(basis, self.dofs) for el in self.elements]
        self._slices, start = [], 0
        for Qe, _ in ops:
            self._slices.append(slice(start, start + Qe.shape[0]))
            start += Qe.shape[0]
        self._T = np.zeros((self.size, start))
        for sl, (_, Te) in zip(self._slices, ops):
            self._T[:, sl] = Te
        if all(el.kinematics.conservative for el in self.elements):
            self._Q = self._T.T
        else:
            self._Q = np.zeros((start, self.size))
            for sl, (Qe, _) in zip(self._slices, ops):
                self._Q[sl] = Qe
        self._ops = ops
        self._local_maps()
        self._static = np.concatenate(
            [np.tile(el.static_force(), basis.nb) * _mean_mask(basis, el.m)
             for el in self.elements]) if self.elements else np.zeros(0)

    def _local_maps(self):
        """Each element's :class:`_LocalMap`; those without a direct path grouped by the rows
        they act on (the blocks of a group are summed before the one scatter into the
        Jacobian)."""
        pos = {int(d): i for i, d in enumerate(self.dofs)}
        maps = [_LocalMap(el.kinematics, self.basis, [pos[d] for d in el.kinematics.dofs], self.m)
                for el in self.elements]
        groups = {}
        for k, lm in enumerate(maps):
            if lm.pairs is None:
                groups.setdefault(lm.rows.tobytes(), (lm.rows, []))[1].append(k)
        self._local = maps
        # each group's block enters the Jacobian through flat indices into it: one 1-D
        # gather-add-scatter (UPD-24 at H = 21: 0.10 ms against 0.25 ms by np.ix_ or by
        # strided views of its runs of DOFs)
        self._groups = [((rows[:, None] * self.size + rows[None, :]).ravel(), ks)
                        for rows, ks in groups.values()]

    def _assemble(self, res) -> np.ndarray:
        """dF_nl/dx (size, size) = sum_e T_e dF_e Q_e, element by element on its rows."""
        dF = np.zeros((self.size, self.size))
        nb = self.basis.nb
        J4 = dF.reshape(nb, self.m, nb, self.m)
        for lm, r in zip(self._local, res):
            if lm.pairs is not None:
                lm.add_direct(J4, r.dF)
        flat = dF.reshape(-1)
        for idx, ks in self._groups:
            B = self._local[ks[0]].block(res[ks[0]].dF)
            for k in ks[1:]:
                B += self._local[k].block(res[k].dF)
            flat[idx] += B.ravel()
        return dF

    def with_elements(self, model: Model):
        """This residual for ``model``, which differs from ``self.model`` only in its
        friction links' elements (same links on the same DOFs, same linear part and
        forcing), sharing every operator: a parameter continuation over slip strength or
        contact stiffness (:mod:`parameter`) then costs no rebuild per parameter value.

        Raises
        ------
        ValueError when ``model`` has another structure (build a new residual then).
        """
        from .aft import FrictionLink

        old, new = self.model, model
        same = (new.linear is old.linear and new.forcing == old.forcing
                and len(new.elements) == len(self.elements))
        for a, b in zip(self.elements, new.elements) if same else ():
            same = a is b or (type(a) is type(b) is FrictionLink and a.dofs == b.dofs)
            if not same:
                break
        if not same:
            raise ValueError("with_elements: the model differs in more than its links' elements")
        out = copy.copy(self)
        out.model, out.elements, out._last, out._pending = new, list(new.elements), None, None
        return out

    def evaluate(self, x: np.ndarray, omega: float | None = None, jac: bool = True):
        """Every element's :class:`~.forces.LocalForce` at unknowns x (size,)."""
        U = self._Q @ x
        nb = self.basis.nb
        w = 0.0 if omega is None else float(omega)
        return [el.evaluate(U[sl].reshape(nb, el.m), self.basis, w, jac)
                for el, sl in zip(self.elements, self._slices)]

    def nonlinear(self, x: np.ndarray, jac: bool = True, omega: float | None = None,
                  energies: bool = True):
        """Element forces (size,) on the active DOFs, Jacobian, energies per element.

        ``omega`` is needed by elements with dashpots (None counts as 0); the
        derivative of the forces with respect to omega is left in ``self.dF_domega``.
        ``energies=False`` returns None for the energies: the residual's own calls,
        where reading them would make lazy elements (ContactElement) compute their
        dissipated work on every Newton step.
        """
        pending, self._pending = getattr(self, "_pending", None), None
        if jac and pending is not None and pending[1] == omega and np.array_equal(pending[0], x):
            res = pending[2]   # evaluated by value() at this point: only the assembly is left
        else:
            res = self.evaluate(x, omega, jac)
        if jac:   # kept for element_action at the same point (no second evaluation)
            self._last = (x.copy(), omega, res)
        Fnl = self._forces(res)
        dF = self._assemble(res) if jac else None
        dw = [r.dF_domega for r in res]
        self.dF_domega = None
        if any(d is not None for d in dw):
            dw = np.concatenate([np.zeros(sl.stop - sl.start) if d is None else d
                                 for sl, d in zip(self._slices, dw)])
            self.dF_domega = self._T @ dw
        return Fnl, dF, ([r.W for r in res] if energies else None)

    def _forces(self, res) -> np.ndarray:
        """F_nl (size,) = T F from the elements' results."""
        Fh = np.concatenate([r.F.ravel() for r in res]) if res else np.zeros(0)
        return self._T @ Fh

    def _value_forces(self, x: np.ndarray, omega: float) -> np.ndarray:
        """F_nl (size,) for :meth:`value`: the elements evaluated with their Jacobians
        and kept, so that a call of the residual at the same (x, omega) right after
        (a line search accepting its trial point) only assembles them."""
        res = self.evaluate(x, omega, True)
        self._pending = (x.copy(), omega, res)
        return self._forces(res)

    def element_action(self, x: np.ndarray, omega: float, select) -> np.ndarray:
        """Residual change (size,) along the selected elements' own displacement:
        ``dR/dF_nl T_s dF_s/dU_s U_s`` summed over the elements e with ``select(e)``,
        at x: the Jacobians of the residual's last evaluation when it was at this
        (x, omega), else one evaluation of those elements. The derivative of R with
        respect to a parameter that scales the selected elements' input (e.g. a contact
        stiffness factor, :class:`parameter.StiffnessScale`)."""
        U = self._Q @ x
        nb = self.basis.nb
        last = getattr(self, "_last", None)
        same = last is not None and last[1] == omega and np.array_equal(last[0], x)
        v = np.zeros(self.size)
        for k, (el, sl) in enumerate(zip(self.elements, self._slices)):
            if select(el):
                r = last[2][k] if same else el.evaluate(U[sl].reshape(nb, el.m), self.basis,
                                                          float(omega), True)
                v += self._T[:, sl] @ (r.dF @ U[sl])
        return self.force_to_residual(v, omega)

    def link_samples(self, x: np.ndarray, omega: float | None = None):
        """Per element: first local displacement, its force over one period (n_t,) each, and W;
        the samples are None for an element evaluated without them (a LinearElement's
        harmonics are exact, it has no AFT samples)."""
        return [(None if r.q is None else r.q[:, 0], None if r.f is None else r.f[:, 0], r.W)
                for r in self.evaluate(x, omega, jac=False)]

    def stuck_operator(self) -> np.ndarray:
        """Stiffness (size, size) of every element stuck (``stuck_stiffness``), element by element."""
        Kst = np.zeros((self.size, self.size))
        eye = np.eye(self.basis.nb)
        for el, (Qe, Te) in zip(self.elements, self._ops):
            Kst += Te @ np.kron(eye, el.stuck_stiffness()) @ Qe
        return Kst

    def viscous_operator(self) -> np.ndarray:
        """Elements' linear dashpots on the unknowns, V (size, size) [N s/m].

        ``sum_e T_e (I (x) C_e) Q_e`` with C_e = ``local_damping()``: the elements' viscous
        forces are ``omega (D_theta (x) I) V x`` (already in the residual); a method that
        needs the dashpots apart from the rate-independent forces (Hill's method: velocity
        ``(omega D_theta + lambda) x``) adds ``lambda V``.
        """
        V = np.zeros((self.size, self.size))
        eye = np.eye(self.basis.nb)
        for el, (Qe, Te) in zip(self.elements, self._ops):
            C = el.local_damping()
            if C is not None:
                V += Te @ np.kron(eye, C) @ Qe
        return V

    def static_load(self) -> np.ndarray:
        """Element forces (size,) at x = 0 (preloads), zero for unloaded elements."""
        return self._T @ self._static if np.any(self._static) else np.zeros(self.size)


class _LocalMap:
    """An element's ``T_e dF_e Q_e`` on its own unknowns: its d DOFs in every harmonic.

    With Q_e = I (x) Q + P (x) Q_next and T_e = I (x) T + P^T (x) T_next
    (:meth:`.kinematics.Kinematics.operators`; P the neighbour's phase, a rotation by
    h phi of each harmonic's (cos, sin) pair), the block is formed by products over the
    local index (m, d) and 2 x 2 rotations over the harmonics: O(n_b^2 m d) flops.

    Parameters
    ----------
    kin : Kinematics
    basis : FourierBasis
    pos : sequence of int (d,)   positions of ``kin.dofs`` in the residual's DOF set
    n_dofs : int                 size of that DOF set

    Attributes
    ----------
    rows : (n_b d,) int   the unknowns (coefficient-major) the block acts on
    """

    def __init__(self, kin, basis: FourierBasis, pos, n_dofs: int):
        nb = basis.nb
        self.rows = (np.arange(nb)[:, None] * n_dofs + np.asarray(pos)[None, :]).ravel()
        self.Q, self.T, self.Qn, self.Tn = kin.Q, kin.T, kin.Q_next, kin.T_next
        # one local displacement, no neighbour (a friction link): the block is dF times
        # (T Q)[i, j] on DOF pair (i, j), added in place by add_direct
        self.pairs = None
        if not kin.cyclic and kin.m == 1:
            TQ = kin.T @ kin.Q
            self.pairs = [(pi, pj, float(TQ[i, j])) for i, pi in enumerate(pos)
                          for j, pj in enumerate(pos) if TQ[i, j] != 0.0]
        if kin.cyclic:
            # harmonic h > 0 holds the coefficient pair (cos, sin) at (c, c + 1): the
            # pairs are every other coefficient from the first non-mean one
            first = 1 if basis.harmonics[0] == 0 else 0
            self._cos, self._sin = slice(first, None, 2), slice(first + 1, None, 2)
            hphi = np.array([h for h in basis.harmonics if h > 0], dtype=float) * kin.phase
            self._c, self._s = np.cos(hphi), np.sin(hphi)
            self._rot = self._rotation(nb, kin.m)

    def _rotation(self, nb: int, m: int):
        """The phase P on a coefficient-major axis of n_b m entries (coefficient c, local j
        at c m + j) as gathers: ``(P^T z)[r] = wa[r] z[ia[r]] + wb[r] z[ib[r]]`` (the cos
        entry of harmonic h takes c_h cos - s_h sin, the sin entry s_h cos + c_h sin, the
        mean itself), so that it runs on contiguous rows and columns."""
        ia, ib = np.arange(nb), np.arange(nb)
        wa, wb = np.ones(nb), np.zeros(nb)
        ic, isn = np.arange(nb)[self._cos], np.arange(nb)[self._sin]
        ib[ic], wa[ic], wb[ic] = isn, self._c, -self._s
        ia[isn], wa[isn], wb[isn] = ic, self._s, self._c
        j = np.arange(m)
        return ((ia[:, None] * m + j).ravel(), (ib[:, None] * m + j).ravel(),
                np.repeat(wa, m), np.repeat(wb, m))

    def add_direct(self, J4: np.ndarray, dF: np.ndarray) -> None:
        """J += T_e dF Q_e for a map with ``pairs``, on J viewed as (n_b, n_dofs, n_b, n_dofs):
        n_b^2 adds per DOF pair, no block formed and no index arrays."""
        for pi, pj, c in self.pairs:
            if c == 1.0:
                J4[:, pi, :, pj] += dF
            elif c == -1.0:
                J4[:, pi, :, pj] -= dF
            else:
                J4[:, pi, :, pj] += c * dF

    def block(self, dF: np.ndarray) -> np.ndarray:
        """T_e dF Q_e on ``rows``: (n_b d, n_b d) from dF (n_b m, n_b m).

        With a neighbour, dF (I (x) Q + P (x) Q_next) = dF (I (x) Q) + (dF (P (x) I)) (I (x)
        Q_next) and T_e Y = (I (x) T) Y + (I (x) T_next) (P^T (x) I) Y: the phase acts on
        the m-sized local index, by gathers of whole columns and rows (:meth:`_rotation`),
        and the products over the local index are matrix products, the left ones batched
        over the row harmonics so that B comes out in its final layout."""
        m, d = self.Q.shape
        nb = dF.shape[0] // m
        Y = dF.reshape(-1, m) @ self.Q                                      # dF (I (x) Q)
        if self.Qn is not None:
            ia, ib, wa, wb = self._rot
            Y += (dF[:, ia] * wa + dF[:, ib] * wb).reshape(-1, m) @ self.Qn
        Y = Y.reshape(nb, m, nb * d)
        B = np.matmul(self.T, Y)
        if self.Tn is not None:
            Y2 = Y.reshape(nb * m, nb * d)
            B += np.matmul(self.Tn, (Y2[ia] * wa[:, None] + Y2[ib] * wb[:, None]).reshape(nb, m, nb * d))
        return B.reshape(nb * d, nb * d)


def _mean_mask(basis: FourierBasis, m: int) -> np.ndarray:
    """(n_b m,) mask of the zeroth-harmonic rows (a static force lives only there)."""
    return np.repeat((basis.order == 0).astype(float), m)


class FullResidual(_Residual):
    """HB residual on all DOFs of a matrix model (see module docstring)."""

    def __init__(self, model: Model, basis: FourierBasis):
        lin = model.linear
        if lin.K is None:
            raise ValueError("the full residual needs M, C, K matrices (use the condensed one)")
        super().__init__(model, basis, np.arange(model.n))
        self._h2 = basis.order.astype(float) ** 2
        # harmonic pairs (cos row, sin row, h): D_theta's only entries, +h and -h
        pairs = [(*basis.index(h), h) for h in basis.harmonics if h > 0]
        self._pairs = tuple(np.array([p[j] for p in pairs], dtype=int if j < 2 else float)
                            for j in range(3))
        self._f = self.Fext.ravel()
        # the dense operators of the module docstring (_K, _M, _C: Hill's method, tests),
        # formed when first read, in a dict that copies (with_elements) share; the
        # residual itself applies them per harmonic (_linear_terms)
        self._dense = {}

    @property
    def _K(self) -> np.ndarray:
        return self._dense_operator("K", lambda: np.kron(np.eye(self.basis.nb), self.model.linear.K))

    @property
    def _M(self) -> np.ndarray:
        return self._dense_operator("M", lambda: np.kron(np.diag(self._h2), self.model.linear.M))

    @property
    def _C(self) -> np.ndarray:
        return self._dense_operator("C", lambda: np.kron(self.basis.dtheta, self.model.linear.C))

    def _dense_operator(self, name: str, build) -> np.ndarray:
        """The (size, size) operator ``name`` (K, M, C of the module docstring), built once."""
        if name not in self._dense:
            self._dense[name] = build()
        return self._dense[name]

    def _linear_terms(self, X: np.ndarray, omega: float):
        """A(omega) x and dA/domega x on the harmonics X (n_b, n), per harmonic:
        ``K X_c - omega^2 c^2 M X_c + omega C (D_theta X)_c`` (O(n_b n^2), no (size, size)
        matrix)."""
        lin = self.model.linear
        V = np.zeros_like(X)   # D_theta X: the velocity harmonics over omega
        ic, isn, h = self._pairs
        V[ic], V[isn] = h[:, None] * X[isn], -h[:, None] * X[ic]
        MX, CV = (self._h2[:, None] * X) @ lin.M, V @ lin.C   # M, C symmetric
        return (X @ lin.K - omega**2 * MX + omega * CV).ravel(), (-2.0 * omega * MX + CV).ravel()

    def _add_dynamic_stiffness(self, J: np.ndarray, omega: float) -> np.ndarray:
        """J + A(omega) in place: A is block-diagonal in the harmonics (the (cos, sin)
        pair of harmonic h couples through omega h C), so only its n_b + 2 H blocks
        (n, n) are added."""
        lin, nb, n = self.model.linear, self.basis.nb, self.m
        J4 = J.reshape(nb, n, nb, n)
        k = np.arange(nb)
        J4[k, :, k, :] += lin.K - omega**2 * self._h2[:, None, None] * lin.M
        ic, isn, h = self._pairs
        Ch = omega * h[:, None, None] * lin.C
        J4[ic, :, isn, :] += Ch
        J4[isn, :, ic, :] -= Ch
        return J

    def __call__(self, x: np.ndarray, omega: float, jac: bool = True):
        Ax, Rw = self._linear_terms(x.reshape(self.basis.nb, self.m), omega)
        Fnl, dF, _ = self.nonlinear(x, jac, omega, energies=False)
        R = Ax + Fnl - self._f
        if not jac:
            return R
        J = self._add_dynamic_stiffness(dF, omega)
        return R, J, Rw if self.dF_domega is None else Rw + self.dF_domega

    def value(self, x: np.ndarray, omega: float) -> np.ndarray:
        """R (size,) alone, the same numbers as ``self(x, omega)[0]``, without assembling the
        Jacobian: a line search's trial point, most of which are rejected (measured on
        chain5 at H = 15: 3812 of 6438 trials)."""
        Ax, _ = self._linear_terms(x.reshape(self.basis.nb, self.m), omega)
        return Ax + self._value_forces(x, omega) - self._f

    def force_to_residual(self, v: np.ndarray, omega: float) -> np.ndarray:
        """dR/dF_nl v: the full residual carries the element forces as they are."""
        return v

    def dof_couplings(self) -> set:
        """Pairs (i, j) of DOFs whose harmonics the Jacobian couples: the nonzeros of K, M,
        C and every element's DOFs among themselves (its neighbour's too, when cyclic)."""
        lin = self.model.linear
        A = sum(np.abs(np.asarray(B.todense() if hasattr(B, "todense") else B))
                for B in (lin.K, lin.M, lin.C) if B is not None)
        pairs = {(int(i), int(j)) for i, j in zip(*np.nonzero(A))}
        for el in self.elements:
            d = [int(k) for k in el.kinematics.dofs]
            pairs.update((a, b) for a in d for b in d)
        return pairs

    def linear_guess(self, omega: float) -> np.ndarray:
        """Solution with every link replaced by its stuck spring k_0."""
        A = self._add_dynamic_stiffness(self.stuck_operator(), omega)
        return np.linalg.solve(A, self._f - self.static_load())

    def displacements(self, x: np.ndarray, omega: float) -> np.ndarray:
        """Harmonics of all DOFs (n_b, n)."""
        return x.reshape(self.basis.nb, self.m)


class CondensedResidual(_Residual):
    """HB residual condensed onto the friction DOFs through the receptance."""

    def __init__(self, model: Model, basis: FourierBasis):
        dofs = sorted({d for el in model.elements for d in el.dofs})
        if not dofs:
            raise ValueError("the condensed residual needs at least one force element")
        super().__init__(model, basis, dofs)
        self._cache = (None, None)

    def _real_block(self, rows, cols, omega: float, deriv: bool):
        """Receptance on real coefficient pairs, (n_b len(rows), n_b len(cols)), + d/domega."""
        lin, b = self.model.linear, self.basis
        nr, nc = len(rows), len(cols)
        h = np.asarray(b.harmonics)
        gs, dgs = lin.receptances(h * omega, rows, cols, deriv)
        ic, isn, k = self._pair_index()
        shape = (b.nb * nr, b.nb * nc)
        out = []
        for val in (gs, None if dgs is None else h[:, None, None] * dgs):
            if val is None:
                out.append(None)
                continue
            # a = Re G f_a + Im G f_b,  b = Re G f_b - Im G f_a  (linear.py), per harmonic:
            # the 2 x 2 block [[Re, Im], [-Im, Re]] on its (cos, sin) pair, Re alone at h = 0
            G = np.zeros((b.nb, nr, b.nb, nc))
            G[ic, :, ic, :] = val.real
            G[isn, :, ic[k], :] = -val.imag[k]
            G[ic[k], :, isn, :] = val.imag[k]
            G[isn, :, isn, :] = val.real[k]
            out.append(G.reshape(shape))
        return out[0], out[1]

    def _pair_index(self):
        """Coefficient indices of the retained harmonics: cos (K,), sin (K',) and the
        positions (K',) of the harmonics that have a sine (all but h = 0)."""
        if not hasattr(self, "_pairs"):
            b = self.basis
            idx = [b.index(h) for h in b.harmonics]
            k = np.array([j for j, (_, s) in enumerate(idx) if s is not None], dtype=int)
            self._pairs = (np.array([c for c, _ in idx], dtype=int),
                           np.array([s for _, s in idx if s is not None], dtype=int), k)
        return self._pairs

    def _linear_response(self, rows, omega: float, deriv: bool):
        """Response (n_b, len(rows)) of the linear part to F_ext, and d/domega."""
        b, lin = self.basis, self.model.linear
        X = np.zeros((b.nb, len(rows)))
        dX = np.zeros_like(X)
        for h, f in self.model.forcing.items():
            ic, isn = b.index(h)
            U, dU = lin.response(h * omega, rows, f, deriv)
            X[ic] = U.real
            if deriv:
                dX[ic] = h * dU.real
            if isn is not None:
                X[isn] = -U.imag
                if deriv:
                    dX[isn] = -h * dU.imag
        return X, dX

    def _operators(self, omega: float):
        if self._cache[0] != omega:
            G, dG = self._real_block(self.dofs, self.dofs, omega, True)
            X, dX = self._linear_response(self.dofs, omega, True)
            self._cache = (omega, (G, dG, X.ravel(), dX.ravel()))
        return self._cache[1]

    def __call__(self, x: np.ndarray, omega: float, jac: bool = True):
        G, dG, Xl, dXl = self._operators(omega)
        Fnl, dF, _ = self.nonlinear(x, jac, omega, energies=False)
        R = x - Xl + G @ Fnl
        if not jac:
            return R
        Rw = -dXl + dG @ Fnl
        return R, np.eye(self.size) + G @ dF, Rw if self.dF_domega is None else Rw + G @ self.dF_domega

    def value(self, x: np.ndarray, omega: float) -> np.ndarray:
        """R (size,) alone, as :meth:`FullResidual.value`."""
        G, _, Xl, _ = self._operators(omega)
        return x - Xl + G @ self._value_forces(x, omega)

    def force_to_residual(self, v: np.ndarray, omega: float) -> np.ndarray:
        """dR/dF_nl v = G(omega) v (R = x - X_lin + G F_nl)."""
        return self._operators(omega)[0] @ v

    def linear_guess(self, omega: float) -> np.ndarray:
        """Solution with every link replaced by its stuck spring k_0."""
        G, _, Xl, _ = self._operators(omega)
        return np.linalg.solve(np.eye(self.size) + G @ self.stuck_operator(),
                               Xl - G @ self.static_load())

    def displacements(self, x: np.ndarray, omega: float, rows=None) -> np.ndarray:
        """Harmonics (n_b, len(rows)) of any DOFs, recovered through the receptance."""
        rows = np.arange(self.model.n) if rows is None else np.asarray(rows)
        Fnl, _, _ = self.nonlinear(x, jac=False, omega=omega, energies=False)
        G, _ = self._real_block(rows, self.dofs, omega, False)
        X, _ = self._linear_response(rows, omega, False)
        return X - (G @ Fnl).reshape(self.basis.nb, len(rows))


def make_residual(model: Model, basis: FourierBasis, condensed: bool | None = None):
    """Pick the residual: condensed when the model is modal-only or larger than the link DOFs."""
    if condensed is None:
        m = len({d for el in model.elements for d in el.dofs})
        condensed = model.linear.K is None or (0 < m < model.n)
    return CondensedResidual(model, basis) if condensed else FullResidual(model, basis)


def energy_per_cycle(model: Model, basis: FourierBasis, X: np.ndarray, omega: float) -> dict:
    """Work per cycle [J] of the excitation and the viscous damping, from harmonics X (n_b, n).

    For x = a cos(h theta) + b sin(h theta) over one period 2 pi / omega:
    excitation work  pi h (f_a . b - f_b . a);  viscous  pi h^2 omega (a.C a + b.C b).
    Needs the C matrix (matrix models).
    """
    F = model.forcing_coeffs(basis)
    C = model.linear.C
    w_ext = w_visc = 0.0
    for h in basis.harmonics:
        if h == 0:
            continue
        ic, isn = basis.index(h)
        a, b = X[ic], X[isn]
        w_ext += np.pi * h * (F[ic] @ b - F[isn] @ a)
        if C is not None:
            w_visc += np.pi * h**2 * omega * (a @ C @ a + b @ C @ b)
    return {"W_ext": float(w_ext), "W_visc": float(w_visc) if C is not None else None}
