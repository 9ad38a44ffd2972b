"""Time-integration reference for models with massless DOFs (contact surfaces).

A contact surface (:mod:`.surface`) joins its node DOFs w to a model without mass:
M is singular and the explicit scheme of :mod:`harmonic_balance.timeint` cannot advance them. The
DOFs split into those with mass (a, M_aa invertible, M_ab = 0) and the massless
ones (b, carrying every node contact); each time step of length dt::

    a: central differences at t_n (as :mod:`harmonic_balance.timeint`, C_aa implicit)
       M_aa (x_a+ - 2 x_a + x_a-) / dt^2 + C_aa (x_a+ - x_a-) / (2 dt)
           = f_a(t_n) - K_aa x_a - K_ab w - C_ab v_b(t_n)                    (T1)
    b: equilibrium at t_(n+1), velocities by the backward difference (BDF2)
       K_bb w+ + C_bb v_b(t_(n+1)) + f_c(w+) = f_b(t_(n+1)) - K_ba x_a+ - C_ba v_a(t_(n+1))
       v(t_(n+1)) = (3 x+ - 4 x + x-) / (2 dt)                              (T2)

(T2) is solved by Newton on w+ with the contacts' tangent, the friction states
carried between steps and committed at the converged w+ (:mod:`.massless`).

Why this scheme: w is an algebraic variable of an index-1 DAE (its equilibrium fixes
it given x_a); the state-space approach (Hairer & Wanner, *Solving Ordinary
Differential Equations II*, 2nd ed., 1996, sec. VI.1) marches x_a with the ODE method
and solves the constraint at every step, so the DOFs with mass keep the explicit
second-order scheme and its stability limit (of the stuck model condensed onto them,
:func:`stable_steps`), and the only implicit solve is the small nonlinear one of the
nodes. The bodies' dashpots on w (beta_c K of the surface) make b stiff first-order
rows with time constants far below dt (beta_c over the penalty factor); BDF2 is
L-stable there (Hairer & Wanner, sec. V.1), so they relax to the quasi-static w in
one step instead of ringing as the trapezoidal rule would. Both halves are second order;
v_b(t_n) in (T1) is the BDF2 velocity of the steps already taken (explicit).

Start: at rest at x_a = x0 (default 0) with w from (T2) without velocities (the static
equilibrium of the massless rows), the sliders virgin at s = s_0, as the harmonic
balance's convention (:mod:`.contact`; x0 the frictionless prestress state whose slips
are the s_0 of :func:`.contact.frictionless_statics`); or on a given periodic motion
(``start``, e.g. a harmonic balance solution: its DOFs with mass prescribed over two
periods, the nodes in equilibrium with them, the march continued from t = 0), which the march then corrects to its own
steady state in fewer periods. Steady state and step-size check as
:func:`.timeint.march_curve` (all frequencies of a curve marched together, each
stopping on its own).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contact import ContactElement
from .forces import LinearElement
from .massless import MAX_NEWTON_UNSPLIT, MasslessContacts
from .model import Model, _on_dofs
from .timeint import _SS_HARMONICS, CFL, CurveSteadyState, _result, _settled_many

#: Periods of a given periodic motion the node sliders are stepped through before a start
#: on it (:func:`march_curve`'s ``start``): the first closes the loop from the virgin state,
#: the second retraces it, so the states carry the loop's past as at a steady state.
START_PERIODS = 2


@dataclass
class SurfaceCurveSteadyState(CurveSteadyState):
    """:class:`.timeint.CurveSteadyState` and the nodes' friction work over the last period."""

    W_friction: np.ndarray | None = None   # (n_freq,) [J]


def _split(model: Model):
    """Massive DOFs a, massless b, and the model's K and C with its linear elements."""
    lin = model.linear
    if lin.K is None:
        raise ValueError("time integration needs M, C, K matrices")
    M = np.asarray(lin.M, float)
    K, C = np.array(lin.K, float), np.array(lin.C, float)
    contacts = []
    for el in model.links:
        if isinstance(el, LinearElement):
            K += _on_dofs(el.kinematics, el.K, model.n)
            if el.C is not None:
                C += _on_dofs(el.kinematics, el.C, model.n)
        elif isinstance(el, ContactElement):
            contacts.append(el)
            if el.local_damping() is not None:
                C += _on_dofs(el.kinematics, el.local_damping(), model.n)
        else:
            raise ValueError(f"force element {el.name!r}: a model with massless DOFs takes linear "
                             "elements and contacts on massless DOFs; use timeint.march_curve")
    b = np.flatnonzero(~np.any(M != 0.0, axis=1))
    a = np.flatnonzero(np.any(M != 0.0, axis=1))
    if b.size == 0 or a.size == 0:
        raise ValueError("the model needs DOFs with mass and massless DOFs (use timeint.march_curve)")
    if np.any(M[np.ix_(a, b)] != 0.0):
        raise ValueError("the massless DOFs must not couple to the others through M")
    return a, b, M, K, C, contacts


def stable_steps(M_aa, K_cond, omega_min: float, steps: int) -> int:
    """Steps per period for stability: dt < CFL 2 / omega_max of the condensed stuck model."""
    lam = np.linalg.eigvals(np.linalg.solve(M_aa, K_cond)).real.max()
    w_max = np.sqrt(max(lam, 0.0))
    return max(int(steps), int(np.ceil(2.0 * np.pi / omega_min * w_max / (2.0 * CFL))))


class _SurfaceMarch:
    """State of :func:`march_curve`: the DOFs with mass, the nodes, their histories."""

    def __init__(self, model: Model, omegas: np.ndarray, steps_per_period: int, x0=None,
                 start=None):
        a, b, M, K, C, contacts = _split(model)
        nf = omegas.size
        self.a, self.b, self.r = a, b, model.response_dof
        pattern = (K[np.ix_(b, b)] != 0) | (C[np.ix_(b, b)] != 0)
        self.nodes = MasslessContacts(contacts, b, nf, pattern)
        Kbb = K[np.ix_(b, b)]
        Kcond = K[np.ix_(a, a)] - K[np.ix_(a, b)] @ np.linalg.solve(
            Kbb + self.nodes.stuck_stiffness(), K[np.ix_(b, a)])
        ns = stable_steps(M[np.ix_(a, a)], Kcond, float(omegas.min()), steps_per_period)
        self.ns = ns
        dt = 2.0 * np.pi / (omegas * ns)
        self.dt = dt[:, None]
        Maa, Caa = M[np.ix_(a, a)], C[np.ix_(a, a)]
        self.Ainv = np.linalg.inv(Maa / dt[:, None, None] ** 2 + Caa / (2 * dt[:, None, None]))
        self.Maa, self.Caa = Maa, Caa
        self.Kaa, self.Kab, self.Kba, self.Kbb = K[np.ix_(a, a)], K[np.ix_(a, b)], K[np.ix_(b, a)], Kbb
        self.Cab, self.Cba, self.Cbb = C[np.ix_(a, b)], C[np.ix_(b, a)], C[np.ix_(b, b)]
        self.Ab = self.nodes.split(Kbb + 1.5 * self.Cbb / dt[:, None, None])   # (T2)'s linear part
        th = 2.0 * np.pi * np.arange(ns) / ns
        self.fext = sum(np.outer(np.cos(h * th), f.real) - np.outer(np.sin(h * th), f.imag)
                        for h, f in model.forcing.items())  # (ns, n): Re(F e^{i h theta})
        if start is not None:
            self._start_periodic(start, nf)
            return
        # start: rest at x0, w from the static equilibrium of b (guess: x0's, else the
        # stuck linearisation)
        x0 = np.zeros(model.n) if x0 is None else np.asarray(x0, float)
        self.xa = np.tile(x0[a], (nf, 1))
        self.xa_m = self.xa.copy()
        rhs0 = np.tile(self.fext[0][b], (nf, 1)) - self.xa @ self.Kba.T
        guess = np.tile(x0[b], (nf, 1)) if np.any(x0 != 0.0) else np.linalg.solve(
            Kbb + self.nodes.stuck_stiffness(), (rhs0 - self.nodes.stuck_offset()).T).T
        self.w = self.nodes.solve(self.nodes.split(Kbb), rhs0, guess, MAX_NEWTON_UNSPLIT)
        self.w_m = self.w.copy()
        self.w_mm = self.w.copy()

    def _start_periodic(self, start, nf: int) -> None:
        """Start on a given periodic motion (:func:`march_curve`'s ``start``): its DOFs with
        mass prescribed over START_PERIODS periods ending at t = 0, the nodes solved from
        (T2) at every step of them (their own equilibrium: the motion's w is not used), so
        the sliders carry that loop's past; then x_a at x(0) and x(-dt)."""
        X = np.asarray(start(self.ns), float)
        if X.shape != (self.ns, self.a.size + self.b.size) or not np.all(np.isfinite(X)):
            raise ValueError(f"start must give ({self.ns}, {self.a.size + self.b.size}) finite "
                             f"displacements, got shape {X.shape}")
        xa = X[:, self.a]
        k0 = 1 - START_PERIODS * self.ns
        rhs0 = np.tile(self.fext[k0 % self.ns][self.b] - xa[k0 % self.ns] @ self.Kba.T, (nf, 1))
        self.w = np.linalg.solve(self.Kbb + self.nodes.stuck_stiffness(),
                                 (rhs0 - self.nodes.stuck_offset()).T).T
        self.w_m, self.w_mm = self.w.copy(), self.w.copy()
        # t = (k0 .. 0) dt: the committed states end at t = 0
        for k in range(k0, 1):
            xa_p = np.tile(xa[k % self.ns], (nf, 1))
            va_p = np.tile(3 * xa[k % self.ns] - 4 * xa[(k - 1) % self.ns] + xa[(k - 2) % self.ns],
                           (nf, 1)) / (2 * self.dt)
            self._nodes_step(k % self.ns, xa_p, va_p)
        self.xa = np.tile(xa[0], (nf, 1))
        self.xa_m = np.tile(xa[-1], (nf, 1))

    def _nodes_step(self, j1: int, xa_p: np.ndarray, va_p: np.ndarray) -> None:
        """(T2) at step index j1 for the DOFs with mass at xa_p, va_p; shifts the w history."""
        w = self.w
        rhs_b = (self.fext[j1][self.b] - xa_p @ self.Kba.T - va_p @ self.Cba.T
                 - (-4 * w + self.w_m) @ self.Cbb.T / (2 * self.dt))
        w_p = self.nodes.solve(self.Ab, rhs_b, 2 * w - self.w_m, MAX_NEWTON_UNSPLIT)
        self.w_mm, self.w_m, self.w = self.w_m, w, w_p

    def step(self, j: int) -> None:
        """Advance every history from t_j to t_(j+1): (T1), then (T2)."""
        dt, xa, xa_m, w = self.dt, self.xa, self.xa_m, self.w
        vb = (3 * w - 4 * self.w_m + self.w_mm) / (2 * dt)
        rhs = (self.fext[j][self.a] - xa @ self.Kaa.T - w @ self.Kab.T - vb @ self.Cab.T
               + (2 * xa - xa_m) @ self.Maa.T / dt**2 + xa_m @ self.Caa.T / (2 * dt))
        xa_p = (self.Ainv @ rhs[..., None])[..., 0]
        va_p = (3 * xa_p - 4 * xa + xa_m) / (2 * dt)
        self._nodes_step((j + 1) % self.ns, xa_p, va_p)
        self.xa_m, self.xa = xa, xa_p

    def response(self) -> np.ndarray:
        """The response DOF of every history at the current time, (n_h,)."""
        hit = np.flatnonzero(self.a == self.r)
        return self.xa[:, hit[0]] if hit.size else self.w[:, np.flatnonzero(self.b == self.r)[0]]

    def keep(self, idx: np.ndarray) -> None:
        """Continue only the histories idx."""
        for name in ("xa", "xa_m", "w", "w_m", "w_mm", "dt", "Ainv"):
            setattr(self, name, getattr(self, name)[idx])
        self.Ab = [A[idx] for A in self.Ab]
        self.nodes.keep(idx)


def march_curve(model: Model, omegas, steps_per_period: int = 256, max_periods: int = 3000,
                tol: float = 1e-6, x0=None, start=None) -> SurfaceCurveSteadyState:
    """March a model with massless DOFs at every frequency of ``omegas`` to periodic steady state.

    Parameters
    ----------
    model : Model
        M, C, K matrices (M zero on the massless DOFs), linear elements and
        ContactElements (one slip direction) on massless DOFs.
    omegas : array_like, shape (n_freq,), positive [rad/s]
    steps_per_period : int, raised if needed for stability at the lowest frequency
    max_periods : int
    tol : float, relative tolerance on the extrapolated distance to steady state
    x0 : array_like (n,), optional
        Start at rest [m]: the DOFs with mass there, the massless ones in equilibrium
        (guess x0's); default 0 (e.g. a prestress state, its sliders virgin there).
    start : callable, optional
        ``start(ns)`` -> (ns, n) displacements [m] of a periodic motion at the phases
        theta_j = 2 pi j / ns (j = 0 .. ns - 1, the march's own steps; e.g. a harmonic
        balance solution): every frequency starts on it instead of at rest; the DOFs with
        mass follow it for START_PERIODS periods before t = 0 while the massless ones are
        solved from their equilibrium (their columns are not used), so the node sliders
        carry that motion's past (``x0`` is then unused).
        A start near the steady state settles in far fewer periods than one from rest;
        the march's equations are the same, so the state it settles to is its own.

    Returns
    -------
    SurfaceCurveSteadyState
        As :func:`.timeint.march_curve`, with the friction work of the last period.
    """
    omegas = np.atleast_1d(np.asarray(omegas, dtype=float))
    if omegas.ndim != 1 or omegas.size == 0 or not np.all(np.isfinite(omegas) & (omegas > 0)):
        raise ValueError(f"omegas must be a non-empty 1-D array of positive numbers, got {omegas}")
    nf = omegas.size
    run = _SurfaceMarch(model, omegas, steps_per_period, x0, start)
    ns = run.ns
    act = np.arange(nf)
    hist, prev = np.empty((nf, ns)), np.zeros((nf, _SS_HARMONICS), complex)
    d, count = np.zeros((2, nf)), np.zeros(nf, int)
    out_hist, periods, conv = np.empty((nf, ns)), np.full(nf, max_periods), np.zeros(nf, bool)
    steps, W = 0, np.zeros(nf)
    for p in range(1, max_periods + 1):
        w_start = run.nodes.dissipated()
        for j in range(ns):
            hist[:, j] = run.response()      # x at t = j dt, as timeint.march
            run.step(j)
        steps += ns
        c = np.fft.rfft(hist, axis=1)[:, :_SS_HARMONICS] / ns
        change = np.linalg.norm(c - prev, axis=1) / np.maximum(np.linalg.norm(c, axis=1), 1e-300)
        d, prev = np.stack([d[1], change]), c
        count += 1
        settled = _settled_many(d[0], d[1], count - 1, tol)
        done = settled | (p == max_periods)
        if np.any(done):
            out_hist[act[done]], periods[act[done]], conv[act[done]] = hist[done], p, settled[done]
            W[act[done]] = (run.nodes.dissipated() - w_start)[done]
            if np.all(done):
                break
            keep = np.flatnonzero(~done)
            act, hist, prev, d, count = act[keep], hist[keep], prev[keep], d[:, keep], count[keep]
            run.keep(keep)
    res = [_result(w, out_hist[i], periods[i], ns, conv[i]) for i, w in enumerate(omegas)]
    return SurfaceCurveSteadyState(omegas, np.array([s.amplitude for s in res]),
                                   np.array([s.amplitude_h1 for s in res]), periods, conv, ns,
                                   out_hist, steps, W)
