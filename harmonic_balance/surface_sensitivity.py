"""Forward sensitivities of a quasi-static march of massless contacts (exact Jacobian).

A :class:`~.massless.MasslessContacts` march solves at every step, from the committed
friction states z_0 (slider positions) and u_c,0 (the residual spring's rest point),

    A w_1 + f_c(w_1; z_0, u_c,0) = A R q_1                                  (M1)

and commits z_1, u_c,1. Each step's end is a settled set: every node open, closed
and stuck, or closed and at its slip bound (per slider of its Iwan law), and on that
set (M1) and the state update are linear in (w_1, q_1, z_0, u_c,0) (the C core's exact
straight-path step, :mod:`fmu_src.core.iwan`). By the implicit function theorem on it,
with ``d`` the derivative along any direction of the inputs q (here the n_b r
harmonics of q)::

    J dw_1 = A R dq_1 - Q_s^T c G                                          (M2)
    J = A + Q_s^T diag(c K_t) Q_s + Q_s^T diag(K_N k_n) Q_p + Q_p^T diag(k_n [P > 0]) Q_p

with, per node i of a law with sliders (k_j, fs_j) and residual spring k_res, and each
slider's end state written dz_1,j = a_j ds_1 + b_j dn_1 + g_j (s the node's slip, n its
normal load in the law's units, n = k_n P / c)::

    stuck:                 a = 0,    b = 0,                  g = dz_0,j
    at the slip bound:     a = 1,    b = -sigma_j r_j,       g = 0        (z = s - sigma r n)
    stuck from re-contact: a = t_c,  b = (s_1 - s_0) dt_c/dn_1,
                           g = (1 - t_c) ds_0 + (s_1 - s_0) dt_c/dn_0 dn_0   (z = u_c = s(t_c))

(r_j = scale fs_j / (N_ref k_j) the slip radius per unit load, sigma_j the sign of the
slider's force, t_c = n_0 / (n_0 - n_1) where the normal load crosses zero inside the
step) and u_c alike (a = b = 0, g = du_c,0 unless re-contact), so that::

    K_t = sum_j k_j (1 - a_j) + k_res (1 - a_c),  K_N = -sum_j k_j b_j - k_res b_c,
    G = -sum_j k_j g_j - k_res g_c                  (all 0 for a node open at the step's end)

the consistent tangent of the return mapping, its friction states' sensitivities carried
from step to step (Simo & Hughes, *Computational Inelasticity*, 1998, ch. 3). The
normal rows do not depend on the slips, so (M2) is block-triangular in the march's
independent blocks: the normal blocks first, then the tangential ones with the Coulomb
coupling of the solved normals on their right-hand side.

At a kink (a node exactly at a stick/slip, lift-off or re-contact switch at a step's
end) this is the derivative of the side the C core's step ended on.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .massless import MasslessContacts


class MarchSensitivity:
    """d(w, z, u_c)/d(direction) along the committed steps of a march (module docstring).

    Parameters
    ----------
    nodes : MasslessContacts
        The march's node contacts (their ``states`` are the committed ones).
    A : ndarray (n_w, n_w)
        The bodies' node stiffness [N/m].
    AR : ndarray (n_w, r)
        A R [N/m, N/rad].
    n_d : int
        Number of directions (columns) carried.

    Attributes
    ----------
    dw : ndarray (n_h, n_w, n_d)
        Sensitivity of the last committed node displacements [m per unit direction].
    """

    def __init__(self, nodes: MasslessContacts, A: np.ndarray, AR: np.ndarray, n_d: int):
        self.nodes, self.A, self.AR = nodes, np.asarray(A, float), np.asarray(AR, float)
        n_h, n_w = nodes.n_h, nodes.n_b
        self.dw = np.zeros((n_h, n_w, n_d))
        # per law group: sliders' dz (n_h, n_g, n_s, n_d) and residual rest point du_c (n_h, n_g, n_d)
        self.dz = [np.zeros((n_h, idx.size, ref.n_sliders, n_d)) for ref, idx, _ in nodes.groups]
        self.duc = [np.zeros((n_h, idx.size, n_d)) for _, idx, _ in nodes.groups]
        self._order = self._block_order()
        # the products Q_a^T diag(k) Q_b of (M2) as triplets (contact, row, column, Q_a Q_b):
        # a contact touches a few DOFs
        self._pairs = [_pairs(Qa, Qb) for Qa, Qb in ((nodes.Qs, nodes.Qs), (nodes.Qs, nodes.Qp),
                                                     (nodes.Qp, nodes.Qp))]
        self._triangular = self._is_triangular()
        # per block of _order, the entries of Q_s^T k Q_s, Q_s^T k Q_p, Q_p^T k Q_p (each
        # contact row one entry, a DOF one contact of a kind: no two on one entry), or None
        single = nodes.rows_s.gather and nodes.rows_p.gather
        self._index = [next(b for b, blk in enumerate(nodes.blocks) if blk is o) for o in self._order]
        self._entries = [[_entries(Qa, Qb) for Qa, Qb in ((Qs, Qs), (Qs, Qp), (Qp, Qp))]
                         for _, _, Qs, Qp in self._order] if single else None
        self._A_blocks = [self.A[np.ix_(dofs, dofs)] for dofs, *_ in self._order]
        # blocks whose operator is A's block plus a diagonal (no Coulomb coupling inside)
        self._diagonal = [self._entries is not None and self._entries[i][1][0].size == 0
                          and all(np.array_equal(t[1], t[2]) for t in self._entries[i])
                          for i in range(len(self._order))]
        # the same advance in one C call per step where the node solve is compiled (and the
        # end states are this module's: a replaced _end_state, e.g. a test's spy on the
        # branches a march takes, keeps the numpy advance that calls it)
        self.compiled = None
        if (nodes.compiled is not None and self._triangular and self._entries is not None
                and _end_state is _END_STATE):
            from .massless_c import CompiledSensitivity
            self.compiled = CompiledSensitivity(nodes.compiled, self.AR, n_d, self._index, nodes.factors)
            self.dw = self.compiled.dw

    def _is_triangular(self) -> bool:
        """Whether (M2) is block-triangular in ``_order`` whatever the contact states: A and
        the Q_s^T Q_s, Q_p^T Q_p terms stay inside a block (the blocks are their connected
        components), so only the Coulomb coupling Q_s^T Q_p can reach a later block."""
        nodes, seen = self.nodes, np.zeros(self.nodes.n_b, bool)
        coupling = (np.abs(nodes.Qs).T @ np.abs(nodes.Qp)) != 0.0
        for dofs, *_ in self._order:
            later = ~seen
            later[dofs] = False
            if np.any(coupling[np.ix_(dofs, later)]):
                return False
            seen[dofs] = True
        return True

    def _block_order(self) -> list:
        """The march's blocks, those without slip rows (normal only) first (module docstring)."""
        blocks = self.nodes.blocks
        normal = [b for b in blocks if not np.any(b[2])]
        return normal + [b for b in blocks if np.any(b[2])]

    def advance(self, before: list, w1: np.ndarray, dq1: np.ndarray) -> None:
        """Carry the sensitivities over the step just committed.

        Parameters
        ----------
        before : list of ndarray
            The node states committed before the step (copies of ``nodes.states``).
        w1 : ndarray (n_h, n_w)
            The step's node displacements [m].
        dq1 : ndarray (r, n_d)
            Sensitivity of the step's inputs q_1.
        """
        nodes = self.nodes
        if self.compiled is not None:
            self.compiled.advance(before, nodes.states, w1, dq1)
            return
        n_h, n_c = nodes.n_h, len(nodes.kn)
        ds0 = nodes.rows_s.rows(self.dw)
        dP0 = nodes.rows_p.rows(self.dw)
        Kt, KN = np.zeros((n_h, n_c)), np.zeros((n_h, n_c))
        G = np.zeros((n_h, n_c, self.dw.shape[2]))
        updates = []
        for g, ((ref, idx, c), st0, st1) in enumerate(zip(nodes.groups, before, nodes.states)):
            e = _end_state(ref, st0.reshape(n_h, -1), st1.reshape(n_h, -1))
            n_scale = (nodes.kn[idx] / c)[None, :, None]      # dn = k_n dP / c
            dn0 = dP0[:, idx] * n_scale
            g_re = (1.0 - e.t_c)[..., None] * ds0[:, idx] + (e.ds * e.dtc0)[..., None] * dn0
            gz = np.where((e.stick & e.re[..., None])[..., None], g_re[:, :, None], 0.0) \
                + np.where((e.stick & ~e.re[..., None])[..., None], self.dz[g], 0.0)
            gc = np.where(e.re[..., None], g_re, self.duc[g])
            k, closed = np.asarray(ref.k, float), e.closed
            Kt[:, idx] = c * closed * ((1.0 - e.a) @ k + ref.k_res * (1.0 - e.a_c))
            KN[:, idx] = closed * (-(e.b @ k) - ref.k_res * e.b_c)
            G[:, idx] = -(c * closed)[..., None] * (np.einsum("s,hgsd->hgd", k, gz) + ref.k_res * gc)
            updates.append((e, gz, gc, n_scale))
        on = (w1 @ nodes.Qp.T + nodes.p0) > 0.0
        self.dw = self._solve(Kt, KN * nodes.kn, nodes.kn * on, dq1, G)
        ds1 = nodes.rows_s.rows(self.dw)
        dP1 = nodes.rows_p.rows(self.dw)
        for g, ((_, idx, _), (e, gz, gc, n_scale)) in enumerate(zip(nodes.groups, updates)):
            dn1 = dP1[:, idx] * n_scale
            self.dz[g] = e.a[..., None] * ds1[:, idx, None] + e.b[..., None] * dn1[:, :, None] + gz
            self.duc[g] = e.a_c[..., None] * ds1[:, idx] + e.b_c[..., None] * dn1 + gc

    def _solve(self, Kt, KNkn, kn_on, dq1, G) -> np.ndarray:
        """dw (n_h, n_w, n_d) of (M2), block by block (normal blocks first)."""
        nodes = self.nodes
        n_h = nodes.n_h
        rhs_q = self.AR @ dq1
        if n_h == 1 and nodes.factors is not None and self._triangular:
            b = rhs_q - nodes.rows_s.cols(G[:1])[0]
            return self._solve_cached(Kt[0], KNkn[0], kn_on[0], b, dq1)[None]
        J = np.broadcast_to(self.A, (n_h,) + self.A.shape).copy()
        for (c, i, j, v), k in zip(self._pairs, (Kt, KNkn, kn_on)):
            for h in range(n_h):
                np.add.at(J[h], (i, j), v * k[h, c])
        b = rhs_q[None] - nodes.rows_s.cols(G)
        dw = np.zeros_like(b)
        solved = np.zeros(nodes.n_b, bool)
        for dofs, *_ in self._order:
            rest = ~solved
            rest[dofs] = False
            if np.any(J[:, dofs][:, :, rest]):
                return np.linalg.solve(J, b)            # not block-triangular: one dense solve
            rhs = b[:, dofs] - J[:, dofs][:, :, solved] @ dw[:, solved]
            dw[:, dofs] = np.linalg.solve(J[:, dofs][:, :, dofs], rhs)
            solved[dofs] = True
        return dw

    def _solve_cached(self, Kt, KNkn, kn_on, b, dq1) -> np.ndarray:
        """dw (n_w, n_d) of (M2) for one history, block-triangular: each block's factors from
        the nodes' FactorCache (keyed by its contacts' coefficients, which fix its operator),
        the earlier blocks entering through the Coulomb coupling alone (``_is_triangular``).
        A normal block's right-hand side is (A R)[dofs] dq1 (no slip rows, no coupling), so
        it is solved for the r columns of A R and multiplied by dq1 (r, n_d) after."""
        nodes = self.nodes
        dw = np.zeros_like(b)
        for i, (dofs, c, Qs, Qp) in enumerate(self._order):
            kt, kN, kp = Kt[c], KNkn[c], kn_on[c]

            def build(i=i, Qs=Qs, Qp=Qp, kt=kt, kN=kN, kp=kp):
                if self._entries is None:
                    return self._A_blocks[i] + (Qs.T * kt) @ Qs + (Qs.T * kN) @ Qp + (Qp.T * kp) @ Qp
                # the three products' entries, one per contact and term: the dense sum's bits
                J = self._A_blocks[i].copy()
                for (c, r, col, qa, qb), k in zip(self._entries[i], (kt, kN, kp)):
                    J[r, col] += (qa * k[c]) * qb
                return J
            # dw is zero but on the blocks solved: J[dofs, solved] dw = (Q_s^T K_N k_n Q_p dw)[dofs]
            rhs = b[dofs] - nodes.rows_s.cols((KNkn[:, None] * nodes.rows_p.rows(dw[None])[0])[None])[0, dofs]
            key = ("sensitivity", i, kt.tobytes(), kN.tobytes(), kp.tobytes())
            b_n = self._index[i]
            d = None if not self._diagonal[i] else nodes.block_diagonal(b_n, kt, kp)
            if d is None:
                dw[dofs] = nodes.factors.solve(key, build, rhs)
            elif not Qs.any():    # the node solve's reference inverses, updated on the diagonal
                dw[dofs] = nodes.factors.solve_diagonal(("block", b_n), key, self._A_blocks[i], d,
                                                        self.AR[dofs]) @ dq1
            else:
                dw[dofs] = nodes.factors.solve_diagonal(("block", b_n), key, self._A_blocks[i], d, rhs)
        return dw


def _entries(Qa: np.ndarray, Qb: np.ndarray) -> tuple:
    """(c, i, j, Qa[c, i], Qb[c, j]) of Qa^T diag(k) Qb for rows of one entry each."""
    c = np.flatnonzero(np.any(Qa != 0, axis=1) & np.any(Qb != 0, axis=1))
    i, j = np.argmax(Qa[c] != 0, axis=1), np.argmax(Qb[c] != 0, axis=1)
    return c, i, j, Qa[c, i], Qb[c, j]


def _pairs(Qa: np.ndarray, Qb: np.ndarray) -> tuple:
    """(c, i, j, Qa[c, i] Qb[c, j]) over the nonzeros of each contact's rows."""
    out = [], [], [], []
    for c in range(Qa.shape[0]):
        ia, jb = np.flatnonzero(Qa[c]), np.flatnonzero(Qb[c])
        i, j = np.repeat(ia, jb.size), np.tile(jb, ia.size)
        for lst, v in zip(out, (np.full(i.size, c), i, j, Qa[c, i] * Qb[c, j])):
            lst.append(v)
    return tuple(np.concatenate(v) if v else np.zeros(0, int) for v in out)


class _EndState(NamedTuple):
    """A step's end per node (n_h, n_g) and slider (n_h, n_g, n_s) (module docstring)."""

    a: np.ndarray        # dz_1 = a ds_1 + b dn_1 + g (n_h, n_g, n_s)
    b: np.ndarray
    a_c: np.ndarray      # the same for u_c (n_h, n_g)
    b_c: np.ndarray
    stick: np.ndarray    # slider stuck at the step's end (bool)
    re: np.ndarray       # node re-contacted inside the step (bool)
    closed: np.ndarray   # node closed at the step's end (1.0 / 0.0)
    t_c: np.ndarray      # path parameter of the re-contact
    dtc0: np.ndarray     # d t_c / d n_0
    ds: np.ndarray       # s_1 - s_0


def _end_state(ref, st0, st1) -> _EndState:
    """The end-state coefficients of a law's nodes (module docstring).

    Parameters
    ----------
    ref : IwanElement
        The group's law (law units: slip s [m], normal load n [N]).
    st0, st1 : ndarray (n_h, n_g) of STATE_DTYPE
        States before and after the step.
    """
    ns = ref.n_sliders
    z0, z1 = st0["z"][..., :ns], st1["z"][..., :ns]
    s0, s1, n0, n1 = st0["u"], st1["u"], st0["N"], st1["N"]
    closed = st1["in_contact"] == 1
    re = closed & (st0["in_contact"] == 0)
    den = np.where(re, n0 - n1, 1.0)                 # n_0 <= 0 < n_1 where re
    t_c = np.where(re, n0 / den, 0.0)
    dtc1, dtc0 = np.where(re, n0 / den ** 2, 0.0), np.where(re, -n1 / den ** 2, 0.0)
    # a stuck slider sits where it was, or at the re-contact point (C: z = u_c there)
    stick = z1 == np.where(re[..., None], st1["u_contact"][..., None], z0)
    sigma = np.sign(s1[..., None] - z1)
    r = ref.scale * np.asarray(ref.fs, float) / (ref.N_ref * np.asarray(ref.k, float))
    ds = s1 - s0
    a = np.where(stick, t_c[..., None], 1.0)
    b = np.where(stick, (ds * dtc1)[..., None], -sigma * r)
    return _EndState(a, b, t_c, ds * dtc1, stick, re, closed.astype(float), t_c, dtc0, ds)


#: The end states the compiled advance (fmu_src/core/march_sens.c) mirrors.
_END_STATE = _end_state
