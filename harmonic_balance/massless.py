"""Quasi-static equilibrium of massless DOFs carrying contacts, one time step at a time.

A contact surface (:mod:`.surface`) adds DOFs without mass: the relative
displacements w of its node pairs (and rigid inputs held by a force only). In the
time domain they are algebraic unknowns of a DAE (index 1: their equilibrium fixes
them given the DOFs with mass); each time step solves, for every history h of a
batch (the frequencies of a curve)::

    A_h w + f_c(w) = r_h                                                  (E1)

with A_h the massless rows' linear operator (stiffness, plus the damping of an
implicit velocity, :mod:`.timeint_surface`), r_h the loads from the DOFs with mass
and the forcing, and f_c the node contacts (:class:`~.contact.ContactElement`, C1,
C2) reached from the committed friction states along the straight path in one step.
This is one increment of the incremental plasticity problem (return mapping: trial
states from the committed ones, committed only when the step's equilibrium is met;
Simo & Hughes, *Computational Inelasticity*, 1998, ch. 1-2), solved by Newton on the
contacts' consistent tangent as :mod:`.surface_static` does for one load step.

The friction forces come from the C core (``IwanElement.step_batch`` on copies of
the committed states: the trial; the copy of the converged iterate is committed).
Node elements whose stiffnesses are one law's times a factor c (sliders c k_j with
the same strengths fs_j, c k_res: the surface's Jenkins nodes, c the ratio of their
k_t) share one C call: their slip radii fs_j N / (c k_j N_ref) are the reference's
at N / c, so F_c(u, N) = c F_1(u, N / c), with the same slider positions z.

Newton's tangent is the slope of each node's trial map s -> F_t at its N (one-sided
differences of three trials, one C call: with N changing along the step's straight path, the
element's own tangent, for continued motion, differs from it where a slider slipped
inside the step; at a kink, the slope of the side the node moves to) in s and k_n
(closed) or 0 (open) in p; the term dF_t/dN k_n (a
slipping node's force following its closing) is left out. The Newton
still settles in a finite number of iterations on a surface: the normal rows of (E1)
do not depend on the slips (the bodies' compliances are uncoupled between
directions, :func:`.surface.node_stiffness`, the contact core's own assumption),
so the normal set settles with its exact tangent and the tangential rows then with
theirs. A backtracking line search on |r| keeps a node at a threshold from cycling.

The massless DOFs fall apart into independent blocks (each face of each sector: a
face's nodes couple through its bodies' stiffness only, the rigid inputs belong to
the DOFs with mass; x and z are uncoupled): the connected components of the pattern
of A and the contacts' rows, each solved on its own (dense, batched over histories).
With one history and a :class:`FactorCache` a block's factors are kept by contact
state; a large block, whose contacts add to its diagonal only (a node coordinate per
row), is solved by low-rank (Woodbury) updates of a few kept inverses instead of a new
factorization per contact state (:meth:`FactorCache.solve_diagonal`).

With one history and a FactorCache (the condensed surface's march) the whole step is one
C call (:meth:`MasslessContacts.compile`, :mod:`.massless_c`: the same operations in
``fmu_src/core/march_step.c``); the numpy code here serves batched histories (the time
integration) and is the compiled step's reference.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import lu_factor
from scipy.linalg.lapack import dgetrf, dgetrs
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from .contact import ContactElement

#: Newton stops when max |residual| is below this fraction of the history's force
#: scale (largest of |r|, |f_c|). The laws are piecewise linear, but a node exactly at a
#: kink of its trial map at the solution (incipient slip) leaves Newton converging
#: linearly (UPD ring: ~6 % per iteration below 1e-7 of the load); 1e-7 is far below
#: the comparisons the time integration serves (1e-2 .. 1e-4).
RESIDUAL_RTOL = 1e-7
#: Newton iterations in one step before the step counts as failed (RuntimeError); a caller
#: that can split the step (the condensed surface's march) gives up early and splits.
MAX_NEWTON = 40
#: The same for a caller that cannot split its step (the time integration, whose step is
#: fixed): where the nodes' Newton converges only linearly at a kink it needs more. The
#: UPD-24 ring with the dashpots on the faces' inputs (no damping on the nodes), CF 600 N,
#: 476.46 Hz, failed a step at 40; at 400 it settled in 141 periods.
MAX_NEWTON_UNSPLIT = 400
#: Bracket doublings and regula-falsi steps of the line search, and the share of the
#: potential's initial slope at which its minimum along the step counts as found.
MAX_BRACKET, MAX_SECTION, SECTION_RTOL = 20, 30, 0.1
#: Passes of the Newton step that settle the side of the nodes at a kink.
MAX_SIDES = 4
#: Forward-difference step of the trial map's slope, relative to the slip plus a slip radius.
#: A node nearer its kink than the step gets a chord between the two sides' slopes: where
#: it really sticks over Newton's (much shorter) step, each iteration then removes only the
#: share of the residual that chord leaves, and Newton converges linearly. At 1e-7 that
#: held steps of the UPD-24 condensed march (CF 120 N, 466.03 Hz, H 7, 256 samples, 5 nodes
#: per side) at |r| ~ 1e-3 N for 30-150 iterations at 1-2 % each (63 of 1098 node solves
#: over 50 evaluations, 30 failed and split; 9022 evaluations in one march); at 1e-9, 3 of
#: 1038 and 3422 evaluations, the HB solution's amplitude equal to 2e-9
#: (examples/surface_march_resolution.py measures the march's cost).
FD_REL = 1e-9
#: Relative tolerance of the homogeneity test that lets two node elements share a call.
SAME_LAW_RTOL = 1e-12
#: Significant digits of a node's Newton slope (relative to its stuck slope) kept in the
#: key of a cached factorization: the slope comes from a difference of the trial map whose
#: round-off is ~2e-7 of it (eps |F| / (k ds), k ds >= FD_REL mu N), so the same
#: stick/slip state gives the same key; the rounded slope is the one used, 5e-7 from the
#: difference: Newton's contraction per iteration on a settled set, far inside its tolerance.
SLOPE_DIGITS = 6
#: Blocks of at least this many DOFs whose contacts add to the diagonal only are solved
#: by diagonal updates of kept inverses (:meth:`FactorCache.solve_diagonal`). On UPD-24
#: the blocks of 63 DOFs (5 nodes per side) cost the same either way within ~10 %, and
#: the cached factors keep a fresh solve's bits; those of 168-714 DOFs (10 and 20 nodes
#: per side) are several times cheaper updated.
DIAGONAL_UPDATE_MIN = 100
#: Inverses kept per block as references of the diagonal updates, and the share of a
#: block's entries beyond which an operator is inverted as a new reference instead of
#: updated (the update's small system then costs a sizable part of an inversion).
MAX_REFERENCES, REFERENCE_SHARE = 4, 0.25
#: Bytes of LU factors kept by a :class:`FactorCache` (least recently used dropped first):
#: 2 x 20 nodes per side gives blocks of ~700 DOFs, 4 MB a factor.
FACTOR_CACHE_BYTES = 256 * 2 ** 20
#: The constants the compiled step (:mod:`.massless_c`) reads, handed to it by name.
_STEP_PARAMS = ("FD_REL", "RESIDUAL_RTOL", "SECTION_RTOL", "SLOPE_DIGITS", "MAX_SIDES", "MAX_BRACKET",
                "MAX_SECTION", "DIAGONAL_UPDATE_MIN", "MAX_REFERENCES", "REFERENCE_SHARE")


class FactorCache:
    """LU factors of dense blocks keyed by the contact state that makes them.

    A march over a period meets the same settled sets again and again (every stick phase
    has one operator; the second period repeats the first's sets), so a factorization is
    reused instead of recomputed; the key is the block and the bytes of the contact
    stiffnesses added to its fixed operator. The owner keeps one cache per fixed
    operator A (a key does not name A). The compiled step (:mod:`.massless_c`) keeps its
    factors and its large blocks' reference inverses here too (attributes ``compiled``,
    ``compiled_sensitivity``, ``compiled_refs``; the inverses also under ``_inv["compiled"]``).

    Parameters
    ----------
    max_bytes : int
        Bytes of factors kept; the least recently used are dropped beyond it.
    """

    def __init__(self, max_bytes: int = FACTOR_CACHE_BYTES):
        self.max_bytes, self.bytes, self._lu, self._inv, self._count = int(max_bytes), 0, {}, {}, 0

    def solve(self, key, build, rhs: np.ndarray) -> np.ndarray:
        """J^{-1} rhs, (m,) or (m, k), with J = build() (m, m) factorized once per ``key``
        (hashable); rhs (m,) or (m, k)."""
        lu = self._lu.pop(key, None)
        if lu is None:
            # LAPACK directly (the getrf and getrs that lu_factor and lu_solve call, the same
            # bits): their wrappers' checks cost more than the solve of a small block
            J = build()
            lu, piv, info = dgetrf(J)
            lu = (lu, piv) if info == 0 else lu_factor(J, check_finite=False)  # its warning
            self.bytes += lu[0].nbytes
            while self.bytes > self.max_bytes and self._lu:
                self.bytes -= self._lu.pop(next(iter(self._lu)))[0].nbytes
        self._lu[key] = lu                           # most recent last (dict order)
        return dgetrs(lu[0], lu[1], rhs)[0]

    def solve_diagonal(self, block, key, A, d, rhs) -> np.ndarray:
        """(A + diag(d))^{-1} rhs, (m,) or (m, k), for a block (hashable ``block``, fixed A
        (m, m)) whose operators differ from each other on the diagonal alone (contact
        stiffnesses on node coordinates), by the Woodbury identity on the inverse of a
        reference A + diag(d_r) met before: with e the entries where d differs from d_r,
        D = diag(d - d_r)[e], Z = (A + diag(d_r))^{-1}[:, e],

            x = x_0 - Z (I + D Z[e])^{-1} D x_0[e],   x_0 = (A + diag(d_r))^{-1} rhs

        whose small matrix is factorized once per ``key`` (which must fix d). The reference
        is the block's kept one (up to MAX_REFERENCES) closest to d; where even that one
        differs in more than REFERENCE_SHARE of the entries (a phase of gross slip or
        lift-off), A + diag(d) becomes a new reference. A block of m unknowns with n_e
        changed entries costs O(m^2 + n_e^3) instead of a new O(m^3) factorization; the
        result is the direct solve's to round-off."""
        refs = self._inv.setdefault(block, {})
        best, e = None, None
        for r, (d_r, _) in refs.items():
            e_r = np.flatnonzero(d != d_r)
            if e is None or e_r.size < e.size:
                best, e = r, e_r
        if best is None or e.size > REFERENCE_SHARE * d.size:
            best, e = self._count, np.zeros(0, int)
            self._count += 1
            refs[best] = (d.copy(), np.linalg.inv(A + np.diag(d)))
            if len(refs) > MAX_REFERENCES:
                refs.pop(next(iter(refs)))
        d_r, inv = refs.pop(best)
        refs[best] = (d_r, inv)                        # most recent last (dict order)
        x0 = inv @ rhs
        if e.size == 0:
            return x0
        delta = d[e] - d_r[e]
        Z = inv[:, e]
        y = self.solve((best,) + key, lambda: np.eye(e.size) + delta[:, None] * Z[e],
                       delta.reshape((-1,) + (1,) * (rhs.ndim - 1)) * x0[e])
        return x0 - Z @ y


def _diagonal_entries(Qs: np.ndarray, Qp: np.ndarray):
    """(rows, columns, Q^2) of the nonzeros of a block's Q_s and Q_p, or None unless each
    row has at most one (Q^T diag(k) Q diagonal)."""
    out = []
    for Q in (Qs, Qp):
        if np.any(np.count_nonzero(Q, axis=1) > 1):
            return None
        rows, cols = np.nonzero(Q)
        out.append((rows, cols, Q[rows, cols] ** 2))
    return out


def _same_law(ref, f) -> float | None:
    """Factor c with f's sliders c k_j, fs_j and c k_res (ref's k_j, fs_j, k_res; same N_ref, scale)."""
    if f.n_sliders != ref.n_sliders or f.N_ref != ref.N_ref or f.scale != ref.scale:
        return None
    c = float(f.k[0] / ref.k[0])
    same = (np.allclose(f.k, c * np.asarray(ref.k), rtol=SAME_LAW_RTOL, atol=0.0)
            and np.allclose(f.fs, ref.fs, rtol=SAME_LAW_RTOL, atol=0.0)
            and np.isclose(f.k_res, c * ref.k_res, rtol=SAME_LAW_RTOL, atol=0.0))
    return c if same else None


class Rows:
    """Products with the contact rows Q (n_c, n_b) of the massless DOFs, per history.

    A node contact's row has one entry (its node coordinate), and a DOF belongs to one
    contact of a kind, so Q X is a gather and Q^T Y a scatter: far cheaper than a sparse
    product's dispatch for the small blocks of a march, with the same bits (one product
    per entry, no sum). Other patterns take sparse products.

    Parameters
    ----------
    Q : ndarray (n_c, n_b)
    """

    def __init__(self, Q: np.ndarray):
        Q = np.asarray(Q, float)
        self.n_b = Q.shape[1]
        self.csr = csr_matrix(Q)
        self.csrT = self.csr.T.tocsr()
        self.nz = np.flatnonzero(np.any(Q != 0, axis=1))
        self.col = np.argmax(Q != 0, axis=1)[self.nz]
        self.val = Q[self.nz, self.col]
        self.gather = (np.all(np.count_nonzero(Q, axis=1) <= 1)
                       and np.unique(self.col).size == self.col.size)
        self.n_c = Q.shape[0]

    def rows(self, X: np.ndarray) -> np.ndarray:
        """Q X per history: X (n_h, n_b, ...) -> (n_h, n_c, ...)."""
        return self._product(X, self.csr, self.n_c, self.col, self.nz)

    def cols(self, Y: np.ndarray) -> np.ndarray:
        """Q^T Y per history: Y (n_h, n_c, ...) -> (n_h, n_b, ...)."""
        return self._product(Y, self.csrT, self.n_b, self.nz, self.col)

    def _product(self, X, sparse, n_out: int, src, dst) -> np.ndarray:
        """out[:, dst] = X[:, src] * val (the one entry of each row), else the sparse product."""
        if not self.gather:
            return np.stack([sparse @ x for x in X])
        out = np.zeros((X.shape[0], n_out) + X.shape[2:])
        out[:, dst] = X[:, src] * self.val.reshape((-1,) + (1,) * (X.ndim - 2))
        return out


class MasslessContacts:
    """The node contacts of the massless DOFs with ``n_h`` independent histories.

    Parameters
    ----------
    elements : list of ContactElement
        Each with one slip direction (m = 2) or normal only (m = 1), on DOFs in ``dofs``.
    dofs : array_like of int, shape (n_b,)
        The model DOFs of the massless set, in the order of w.
    n_h : int
        Number of histories (e.g. frequencies) advanced together.
    pattern : ndarray (n_b, n_b) of bool, optional
        Nonzeros of the linear operators A that :meth:`solve` will get (default: full).
    """

    def __init__(self, elements, dofs, n_h: int, pattern=None):
        dofs = [int(d) for d in dofs]
        where = {d: i for i, d in enumerate(dofs)}
        n_b, n_c = len(dofs), len(elements)
        self.n_b, self.n_h = n_b, int(n_h)
        self.Qs, self.Qp = np.zeros((n_c, n_b)), np.zeros((n_c, n_b))
        self.kn = np.array([el.k_n for el in elements], float)
        self.p0 = np.array([el.preload for el in elements], float)
        self.s0 = np.zeros(n_c)
        groups = []   # [reference element, contact indices, factors]
        for i, el in enumerate(elements):
            if not isinstance(el, ContactElement) or el.m == 3:
                raise ValueError("the massless DOFs take contacts with one slip direction (planar "
                                 "surfaces, tangents ('x',)) or normal only")
            kin = el.kinematics
            if any(d not in where for d in kin.dofs) or kin.cyclic:
                raise ValueError(f"contact {el.name!r} must act on massless DOFs only")
            cols = [where[d] for d in kin.dofs]
            self.Qp[i, cols] = kin.Q[-1]
            if el.m == 2:
                self.Qs[i, cols] = kin.Q[0]
                self.s0[i] = el.slip_ref
                for g in groups:
                    c = _same_law(g[0], el.friction)
                    if c is not None:
                        g[1].append(i)
                        g[2].append(c)
                        break
                else:
                    groups.append([el.friction, [i], [1.0]])
        self.groups = [(ref, np.array(idx), np.array(c)) for ref, idx, c in groups]
        # each law's slip radius per unit load, sum fs / (N_ref sum k) (the scale of the
        # trial map's difference step)
        self._radius = [(np.sum(ref.fs), ref.N_ref * np.sum(ref.k)) for ref, _, _ in self.groups]
        self.kt_stuck = np.ones(n_c)                 # the slope scale of SLOPE_DIGITS
        for ref, idx, c in self.groups:
            self.kt_stuck[idx] = c * (np.sum(ref.k) + ref.k_res)
        #: a FactorCache for one history (n_h = 1) with the same A in every solve, or None
        self.factors = None
        #: the compiled step (:meth:`compile`), or None: the numpy path
        self.compiled = None
        self._blocks(np.ones((n_b, n_b), bool) if pattern is None else np.asarray(pattern, bool))
        # the products on all DOFs (a contact touches a few DOFs)
        self.rows_s, self.rows_p = Rows(self.Qs), Rows(self.Qp)
        self.states = []
        for ref, idx, c in self.groups:
            N0 = np.where(self.p0[idx] > 0, self.kn[idx] * self.p0[idx], ref.N_ref) / c
            self.states.append(ref.initial_states(self.n_h * idx.size, np.tile(N0, self.n_h)))

    def _blocks(self, pattern) -> None:
        """Independent blocks: DOFs, their contacts and those contacts' rows on them."""
        P = pattern | (self.Qs.T @ self.Qs != 0) | (self.Qp.T @ self.Qp != 0)
        k, label = connected_components(csr_matrix(P | P.T), directed=False)
        self.blocks = []
        for b in range(k):
            dofs = np.flatnonzero(label == b)
            c = np.flatnonzero(np.any(self.Qs[:, dofs] != 0, axis=1)
                               | np.any(self.Qp[:, dofs] != 0, axis=1))
            self.blocks.append((dofs, c, self.Qs[np.ix_(c, dofs)], self.Qp[np.ix_(c, dofs)]))
        self._diagonal = [_diagonal_entries(Qs, Qp) for _, _, Qs, Qp in self.blocks]

    def block_diagonal(self, b: int, kt: np.ndarray, kp: np.ndarray):
        """The contacts' part of block b's operator, Q_s^T diag(kt) Q_s + Q_p^T diag(kp) Q_p,
        as its diagonal (m_b,) when it is diagonal and the block has at least
        DIAGONAL_UPDATE_MIN DOFs, else None; kt, kp (n_c,) of the block's contacts."""
        entries = self._diagonal[b]
        if entries is None or self.blocks[b][0].size < DIAGONAL_UPDATE_MIN:
            return None
        (rs, cs, qs2), (rp, cp, qp2) = entries
        d = np.zeros(self.blocks[b][0].size)
        np.add.at(d, cs, kt[rs] * qs2)
        np.add.at(d, cp, kp[rp] * qp2)
        return d

    @staticmethod
    def _add_tangent(J, Q, k):
        """J += Q^T diag(k) Q for every history (J (n, m, m), Q (c, m), k (n, c)); a row of Q
        with one entry (a node coordinate) adds to the diagonal only."""
        if np.all(np.count_nonzero(Q, axis=1) <= 1):
            col = np.argmax(Q != 0, axis=1)
            np.add.at(J, (slice(None), col, col), k * Q[np.arange(len(col)), col] ** 2)
            return J
        return J + (Q.T * k[:, None, :]) @ Q

    def split(self, A: np.ndarray) -> list:
        """The blocks of a linear operator A (n_b, n_b) or (n_h, n_b, n_b), for :meth:`solve`."""
        A = np.asarray(A)
        return [np.broadcast_to(A[..., dofs[:, None], dofs], (self.n_h, dofs.size, dofs.size)).copy()
                for dofs, *_ in self.blocks]

    def stuck_stiffness(self) -> np.ndarray:
        """(n_b, n_b) [N/m]: every contact closed and stuck."""
        kt = np.zeros(len(self.kn))
        for ref, idx, c in self.groups:
            kt[idx] = c * (np.sum(ref.k) + ref.k_res)
        return self.Qs.T @ (kt[:, None] * self.Qs) + self.Qp.T @ (self.kn[:, None] * self.Qp)

    def stuck_offset(self) -> np.ndarray:
        """f_c(0) of the stuck linearisation, (n_b,) [N]: k_n p_0 and -k_t s_0."""
        kt = np.zeros(len(self.kn))
        for ref, idx, c in self.groups:
            kt[idx] = c * (np.sum(ref.k) + ref.k_res)
        return self.Qp.T @ (self.kn * self.p0) - self.Qs.T @ (kt * self.s0)

    def compile(self, A: list) -> bool:
        """Solve each step of one history in one C call (:mod:`.massless_c`, the same
        numbers as this module's numpy path) where it applies: n_h = 1, a
        :attr:`factors` cache set, blocks below DIAGONAL_UPDATE_MIN DOFs; A the blocks
        (:meth:`split`) every :meth:`solve` will get. Returns whether it applies."""
        from .massless_c import CompiledStep

        self.compiled = None
        if self.factors is not None and CompiledStep.fits(self, A):
            params = {name: globals()[name] for name in _STEP_PARAMS}   # as monkeypatched, if so
            self.compiled = CompiledStep(self, A, self.factors, params)
        return self.compiled is not None

    def evaluate(self, w: np.ndarray):
        """Trial forces from the committed states.

        Parameters
        ----------
        w : ndarray, shape (n_h, n_b)

        Returns
        -------
        fc : ndarray (n_h, n_b) [N]
        tangent : (kt, kp, kt_minus), each (n_h, n_c) [N/m]: slider stiffness for an
            increasing slip, normal stiffness, slider stiffness for a decreasing slip
            (the one-sided slopes of the trial map, module docstring)
        trial : list of state buffers (the states at w, to :meth:`commit`)
        """
        P = self.rows_p.rows(w) + self.p0             # (n_h, n_c) penetration
        on = P > 0.0
        N = self.kn * np.where(on, P, 0.0)
        S = self.rows_s.rows(w) - self.s0
        Ft, kt, ktm, trial = np.zeros_like(P), np.zeros_like(P), np.zeros_like(P), []
        for (ref, idx, c), st, radius in zip(self.groups, self.states, self._radius):
            s, n1 = S[:, idx].ravel(), ((self.kn[idx] * P[:, idx]) / c).ravel()
            # the trial map's slope dF/ds at this N by a forward difference (exact on the
            # piecewise-linear map away from a kink within ds): with N changing along the
            # step's straight path the element's own tangent (for continued motion) is not it
            ds = FD_REL * (np.abs(s) + np.abs(n1) * radius[0] / radius[1] + 1e-300)
            # the trial at s, s + ds and s - ds from copies of the committed states in one
            # C call (each state steps alone: the bits of three calls); unclamped k_n p:
            # the C core treats N <= 0 as lift-off (as ContactElement)
            n = s.size
            raw = st.view(np.uint8)                   # bytes: no field promotion
            three = np.concatenate((raw, raw, raw)).view(st.dtype)
            F = ref.step_batch(three, np.concatenate((s, s + ds, s - ds)), np.concatenate((n1, n1, n1)))[0]
            F1, F2, F0 = F[:n], F[n:2 * n], F[2 * n:]
            Ft[:, idx] = c * F1.reshape(self.n_h, -1)
            kt[:, idx] = c * ((F2 - F1) / ds).reshape(self.n_h, -1)
            ktm[:, idx] = c * ((F1 - F0) / ds).reshape(self.n_h, -1)
            trial.append(three[:n].copy())
        fc = self.rows_s.cols(Ft) + self.rows_p.cols(N)
        return fc, (kt, self.kn * on, ktm), trial

    def commit(self, trial) -> None:
        """Accept the trial states (those of the converged step)."""
        self.states = trial

    def dissipated(self) -> np.ndarray:
        """Cumulative friction work of each history, (n_h,) [J]."""
        W = np.zeros(self.n_h)
        for (_, _, c), st in zip(self.groups, self.states):
            W += (st["w_diss"].reshape(self.n_h, -1) * c).sum(axis=1)
        return W

    def keep(self, idx) -> None:
        """Continue only the histories ``idx``."""
        idx = np.asarray(idx, int)
        self.states = [np.ascontiguousarray(st.reshape(self.n_h, -1)[idx].ravel())
                       for st in self.states]
        self.n_h = idx.size

    def solve(self, A: list, rhs: np.ndarray, guess: np.ndarray, max_iter: int = MAX_NEWTON) -> np.ndarray:
        """Solve (E1) for every history and commit the states there.

        Parameters
        ----------
        A : list of ndarray (n_h, m_k, m_k)
            The blocks of A (:meth:`split`).
        rhs : ndarray (n_h, n_b) [N]
        guess : ndarray (n_h, n_b) [m]
        max_iter : int
            Newton iterations before the step counts as failed.

        Returns
        -------
        w : ndarray (n_h, n_b)

        Raises
        ------
        RuntimeError
            Newton did not settle in ``max_iter`` iterations.
        """
        if self.compiled is not None:             # the same step in one C call
            w, self.states = self.compiled.solve(self.states, rhs, guess, max_iter)
            return w
        w = guess.copy()
        fc, tan, trial = self.evaluate(w)
        r = self._residual(A, w, fc, rhs)
        for _ in range(max_iter):
            scale = np.maximum(np.abs(rhs).max(axis=1), np.abs(fc).max(axis=1))
            todo = np.abs(r).max(axis=1) > RESIDUAL_RTOL * np.maximum(scale, 1e-300)
            if not todo.any():
                self.commit(trial)
                return w
            dx = self._newton_step(A, r, tan, todo)
            w, r, fc, tan, trial = self._line_search(A, rhs, w, r, fc, tan, trial, dx, todo)
        raise RuntimeError("the contact surface nodes found no equilibrium in a time step: "
                           "raise the steps per period, or check that the surface stays in contact")

    def _newton_step(self, A, r, tan, todo):
        """dx of every history in ``todo``: each node's slope taken on the side it moves to.

        A node at a kink of its trial map (slope k on one side, 0 on the other) gets the
        slope of the side its step points to; a step that reverses a node's side is solved
        again with the other slope (a few passes settle the sides)."""
        dx = np.zeros_like(r)
        side = np.ones((self.n_h, len(self.kn)), bool)           # True: increasing slip
        for _ in range(MAX_SIDES):
            kt = np.where(side, tan[0], tan[2])
            if self.factors is not None and self.n_h == 1:
                self._cached_step(A, r, kt, tan[1], dx)
            else:
                self._dense_step(A, r, kt, tan[1], todo, dx)
            ds = self.rows_s.rows(dx)
            kink = tan[0] != tan[2]
            new = np.where(ds != 0.0, ds > 0.0, side)
            if not np.any(kink & (new != side)):
                break
            side = np.where(kink, new, side)
        return dx

    def _dense_step(self, A, r, kt, kp, todo, dx):
        """dx of the histories in ``todo``, every block factorized afresh (batched)."""
        for Ak, (dofs, c, Qs, Qp) in zip(A, self.blocks):
            J = self._add_tangent(self._add_tangent(Ak[todo], Qs, kt[todo][:, c]), Qp, kp[todo][:, c])
            dx[np.ix_(todo, dofs)] = np.linalg.solve(J, -r[np.ix_(todo, dofs)][..., None])[..., 0]

    def _cached_step(self, A, r, kt, kp, dx):
        """dx of the one history with each block's factors from ``self.factors`` (slopes
        rounded to SLOPE_DIGITS, so that a repeated contact state finds its factors)."""
        for b, (Ak, (dofs, c, Qs, Qp)) in enumerate(zip(A, self.blocks)):
            ks = self.kt_stuck[c]
            kr = np.round(kt[0, c] / ks, SLOPE_DIGITS)
            kp_c = kp[0, c]

            def build(Ak=Ak, Qs=Qs, Qp=Qp, kr=kr, ks=ks, kp_c=kp_c):
                return self._add_tangent(self._add_tangent(Ak[:1].copy(), Qs, (kr * ks)[None]),
                                         Qp, kp_c[None])[0]
            key = ("newton", b, kr.tobytes(), kp_c.tobytes())
            d = self.block_diagonal(b, kr * ks, kp_c)
            if d is None:
                dx[0, dofs] = self.factors.solve(key, build, -r[0, dofs])
            else:
                dx[0, dofs] = self.factors.solve_diagonal(("block", b), key, Ak[0], d, -r[0, dofs])

    def _residual(self, A, w, fc, rhs):
        r = fc - rhs
        for Ak, (dofs, *_) in zip(A, self.blocks):
            r[:, dofs] += (Ak @ w[:, dofs, None])[..., 0]
        return r

    def _line_search(self, A, rhs, w, r, fc, tan, trial, dx, todo):
        """The step along dx per history (module docstring); returns the accepted iterate.

        The full step unless it overshoots the minimum along dx; else the zero of g(alpha) = dx . r(w + alpha dx),
        the slope of the step's incremental potential along dx, increasing in alpha (the
        potential is convex: A symmetric positive, each node's trial map monotone), by
        regula falsi (Illinois) on a bracket: a descent step even across the kinks where a
        step on |r| stalls."""
        def at(alpha, rows):
            wt = w + alpha[:, None] * dx
            fct, tant, trt = self.evaluate(wt)
            rt = self._residual(A, wt, fct, rhs)
            return wt, rt, fct, tant, trt, np.einsum("hi,hi->h", dx, rt)

        def take(ok, got):
            wt, rt, fct, tant, trt, _ = got
            w[ok], r[ok], fc[ok] = wt[ok], rt[ok], fct[ok]
            for t, tt in zip(tan, tant):
                t[ok] = tt[ok]
            for st, stt in zip(trial, trt):
                m = st.size // self.n_h
                st.reshape(self.n_h, m)[ok] = stt.reshape(self.n_h, m)[ok]

        g0 = np.einsum("hi,hi->h", dx, r)
        full = at(np.where(todo, 1.0, 0.0), todo)
        ok = todo & (full[5] <= SECTION_RTOL * np.abs(g0))   # no overshoot of the minimum
        pending = todo & ~ok
        lo, glo = np.zeros(self.n_h), g0.copy()
        hi, ghi = np.ones(self.n_h), full[5].copy()
        for _ in range(MAX_BRACKET):                 # bracket the zero of g
            grow = pending & (ghi < 0)
            if not grow.any():
                break
            lo[grow], glo[grow], hi[grow] = hi[grow], ghi[grow], 2 * hi[grow]
            ghi[grow] = at(np.where(grow, hi, 0.0), grow)[5][grow]
        take(ok, full)
        side = np.zeros(self.n_h, int)
        for _ in range(MAX_SECTION):                 # Illinois regula falsi on [lo, hi]
            if not pending.any():
                break
            a = np.where(pending, lo - glo * (hi - lo) / np.where(ghi != glo, ghi - glo, 1.0), 0.0)
            got = at(a, pending)
            g = got[5]
            done = pending & (np.abs(g) <= SECTION_RTOL * np.abs(g0))
            take(done, got)
            pending &= ~done
            up = pending & (g > 0)
            dn = pending & ~(g > 0)
            hi[up], ghi[up] = a[up], g[up]
            lo[dn], glo[dn] = a[dn], g[dn]
            glo[up & (side == 1)] *= 0.5
            ghi[dn & (side == -1)] *= 0.5
            side = np.where(up, 1, np.where(dn, -1, side))
        if pending.any():
            take(pending, at(np.where(pending, lo, 0.0), pending))
        return w, r, fc, tan, trial
