"""Time-integration reference: the same model marched to its periodic steady state.

Explicit central differences (Newmark gamma = 1/2, beta = 0; second order)::

    (M / dt^2 + C / (2 dt)) x_(n+1) = f(t_n) - K x_n - f_nl(x_n)
                                      + M (2 x_n - x_(n-1)) / dt^2 + C x_(n-1) / (2 dt)

The friction force f_nl(x_n) comes from the C core's element, advanced one sample
per step with its own history (``IwanElement.step`` on the carried state, starting
virgin), so the time integration uses the same law as the harmonic balance
and shares nothing else with it (no Fourier series, no periodic-loop assumption).
Stable for dt < 2 / omega_max, omega_max from K plus the stuck friction springs.

Steady state: each period's response harmonics (DFT of its samples) are compared
with the previous period's; the march stops when the change, extrapolated
geometrically to infinity (the transient decays like rho^p), is below ``tol``
relative to the amplitude. Time-step convergence: :func:`steady_amplitude` runs two
step sizes and reports their difference.

:func:`march_curve` is the same scheme and test vectorised over the frequencies of
a curve (state arrays (n_freq, n_dof), one batched C element call per element per
time step, ``IwanElement.batch_stepper``); :func:`steady_curve` checks its step size.
:func:`march` stays the independent frequency-by-frequency version (LU solve,
one ``IwanElement.step`` per link per step) that the vectorised one is tested against.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .aft import FrictionLink
from .model import Model

#: Fraction of the stability limit 2 / omega_max used as the largest step.
CFL = 0.5


@dataclass
class SteadyState:
    """Periodic steady state of the response DOF at one frequency (SI)."""

    omega: float
    amplitude: float      # peak |x_r| over the last period [m]
    amplitude_h1: float   # first-harmonic magnitude of x_r [m]
    periods: int          # periods marched
    steps_per_period: int
    converged: bool
    x_last: np.ndarray    # (steps_per_period,) response over the last period
    #: energy [J] dissipated by each force element's hysteresis over the last period
    #: (C-element state; the elements' linear dashpots are part of C, not included)
    W_elements: tuple | None = None


def _link_stepper(link):
    """One-sample force update of an element with its carried (virgin) state.

    A friction link returns a float (its historical path); any other force element
    its ``stepper().force`` on local displacements (m,) -> local forces (m,).
    """
    if not isinstance(link, FrictionLink):
        st = link.stepper()
        force = st.force
        force_dissipated = getattr(st, "dissipated", lambda: 0.0)
        return force, force_dissipated
    el = link.element
    state = el.initial_state()

    def force(u: float) -> float:
        return el.step(state, u).F

    return force, lambda: state.W


def _stable_steps(model: Model, omega: float, steps: int) -> int:
    lin = model.linear
    K = model.stuck_stiffness()
    w_max = np.sqrt(max(sla.eigh(K, lin.M, eigvals_only=True).max(), 0.0))
    need = int(np.ceil(2.0 * np.pi / omega * w_max / (2.0 * CFL)))
    return max(steps, need)


def march(model: Model, omega: float, steps_per_period: int = 256, max_periods: int = 3000,
          tol: float = 1e-6, x0=None, v0=None, history=None) -> SteadyState:
    """March the model at frequency omega [rad/s] to its periodic steady state.

    Parameters
    ----------
    model : Model (needs M, C, K matrices)
    steps_per_period : int, raised if needed for stability
    max_periods : int
    tol : float, relative tolerance on the extrapolated distance to steady state
    x0, v0 : (n,) arrays, initial displacement and velocity (default rest)
    history : (k, n) array or None, displacements the force elements are stepped
        through before the start (oldest first), so their sliders carry that past
        (e.g. a harmonic-balance period ending just before ``x0``); default virgin
    """
    lin = model.linear
    if lin.K is None:
        raise ValueError("time integration needs M, C, K matrices")
    n, r = model.n, model.response_dof
    ns = _stable_steps(model, omega, steps_per_period)
    dt = 2.0 * np.pi / omega / ns
    C = lin.C + model.element_damping()  # contact dashpots are linear: implicit, with C
    lhs = sla.lu_factor(lin.M / dt**2 + C / (2 * dt))
    forces, dissipated = zip(*[_link_stepper(link) for link in model.links]) if model.links else ((), ())
    for xh in () if history is None else np.asarray(history, float):
        _friction(model, forces, xh)
    th = 2.0 * np.pi * np.arange(ns) / ns
    fext = sum(np.outer(np.cos(h * th), f.real) - np.outer(np.sin(h * th), f.imag)
               for h, f in model.forcing.items())  # (ns, n): Re(F e^{i h theta})
    x = np.zeros(n) if x0 is None else np.asarray(x0, float).copy()
    v = np.zeros(n) if v0 is None else np.asarray(v0, float)
    x_prev = x - dt * v  # first-order start; the transient forgets it
    hist, prev, deltas = np.empty(ns), None, []
    for p in range(1, max_periods + 1):
        w0 = [d() for d in dissipated]
        for j in range(ns):
            fnl = _friction(model, forces, x)
            rhs = (fext[j] - lin.K @ x - fnl + lin.M @ (2 * x - x_prev) / dt**2
                   + C @ x_prev / (2 * dt))
            x_prev, x = x, sla.lu_solve(lhs, rhs, check_finite=False)
            hist[j] = x_prev[r]
        c = np.fft.rfft(hist)[:8] / ns
        if prev is not None:
            deltas.append(np.linalg.norm(c - prev) / max(np.linalg.norm(c), 1e-300))
            if _settled(deltas, tol):
                return _result(omega, hist, p, ns, True, _worked(dissipated, w0))
        prev = c
    return _result(omega, hist, max_periods, ns, False, _worked(dissipated, w0))


def _worked(dissipated, w0) -> tuple:
    """Energy dissipated per element since w0 (the start of the last period) [J]."""
    return tuple(d() - w for d, w in zip(dissipated, w0))


def _friction(model, forces, x):
    f = np.zeros(model.n)
    for link, force in zip(model.links, forces):
        if not isinstance(link, FrictionLink):
            kin = link.kinematics
            f[list(kin.dofs)] += kin.T @ force(kin.Q @ x[list(kin.dofs)])
            continue
        u = x[link.dof_a] - (0.0 if link.dof_b is None else x[link.dof_b])
        F = force(u)
        f[link.dof_a] += F
        if link.dof_b is not None:
            f[link.dof_b] -= F
    return f


def _settled(deltas, tol) -> bool:
    """Geometric tail estimate: remaining change ~ d_p rho / (1 - rho)."""
    if len(deltas) < 3:
        return False
    d1, d2 = deltas[-2], deltas[-1]
    if d2 == 0.0:
        return True
    rho = min(d2 / d1, 0.999) if d1 > 0 else 0.999
    return d2 * max(1.0, rho / (1.0 - rho)) < tol


def _result(omega, hist, p, ns, ok, W=None):
    # Sample at the step ending each period: hist[j] = x at t = j dt (start of step j+1).
    c = np.fft.rfft(hist) / ns
    h1 = 2.0 * abs(c[1])
    j = int(np.argmax(np.abs(hist)))
    y0, y1, y2 = (abs(hist[(j + k) % ns]) for k in (-1, 0, 1))
    den = y0 - 2 * y1 + y2
    # Parabola through the three samples around the extreme: peak between samples.
    peak = y1 - 0.125 * (y2 - y0) ** 2 / den if den < 0 else y1
    return SteadyState(omega, float(peak), float(h1), p, ns, ok, hist.copy(), W)


def steady_amplitude(model: Model, omega: float, steps_per_period: int = 512, **kw):
    """Steady amplitude at steps_per_period, checked against twice as many steps.

    Central differences with stick-slip kinks converge faster than second order in
    practice (sdof Jenkins near its peak: changes 6e-5, 6e-6, 1e-7 per doubling from
    256 steps), so the finer run is reported and the change is its error bound;
    Richardson extrapolation at order 2 would over-correct.

    Returns (amplitude, amplitude_h1, relative step-size error estimate, finer SteadyState).
    """
    a = march(model, omega, steps_per_period, **kw)
    b = march(model, omega, 2 * a.steps_per_period, **kw)
    if not (a.converged and b.converged):
        raise RuntimeError(f"time integration did not reach steady state at omega = {omega:g}")
    return b.amplitude, b.amplitude_h1, abs(b.amplitude - a.amplitude) / max(b.amplitude, 1e-300), b


# --------------------------------------------------------------------------
# Vectorised reference: every frequency of a curve marched at once.
#
# The same central-difference scheme as :func:`march`, with the step solved in
# closed form per frequency f (dt_f = 2 pi / (omega_f n_s), n_s steps per period
# for all, so step j is at phase 2 pi j / n_s for every frequency):
#     x_(n+1) = A_f^-1 f(t_n) + B1_f x_n + B2_f x_(n-1) - sum_l A_f^-1 e_l F_l,
#     A_f = M / dt^2 + C / (2 dt),  B1_f = A_f^-1 (2 M / dt^2 - K),
#     B2_f = A_f^-1 (C / (2 dt) - M / dt^2),
# with e_l the incidence vector of link l (u_l = e_l . x). The carried vector
# X = [x_n, x_(n-1), F_1 .. F_L] of shape (n_freq, 2 n + L) makes the update one
# batched matrix product, and each element advances its n_freq independent
# histories in one C call per time step (``IwanElement.batch_stepper``).
# Frequencies that reach steady state (the test of :func:`march`, per frequency)
# leave the active set, so the cost follows the slowest transients only.
# --------------------------------------------------------------------------

#: Response harmonics compared between periods by the steady-state test (as in march).
_SS_HARMONICS = 8


@dataclass
class CurveSteadyState:
    """Periodic steady states of the response DOF at n_freq frequencies (SI)."""

    omega: np.ndarray          # (n_freq,) [rad/s]
    amplitude: np.ndarray      # (n_freq,) peak |x_r| over the last period [m]
    amplitude_h1: np.ndarray   # (n_freq,) first-harmonic magnitude of x_r [m]
    periods: np.ndarray        # (n_freq,) periods marched
    converged: np.ndarray      # (n_freq,) bool
    steps_per_period: int
    x_last: np.ndarray         # (n_freq, steps_per_period) response over the last period
    time_steps: int            # time steps taken (each advances every active frequency)


class _BatchLink:
    """A link's element with one independent history per frequency (virgin start)."""

    def __init__(self, link, n_freq: int):
        self.el, self.a, self.b = link.element, link.dof_a, link.dof_b
        if hasattr(self.el, "batch_stepper"):
            self.stepper = self.el.batch_stepper(self.el.initial_states(n_freq))
            self.u = self.stepper.u
        else:  # an element without the batch entry (the test oracle): one state each
            self.states = [self.el.initial_state() for _ in range(n_freq)]
            self.stepper, self.u = None, np.zeros(n_freq)

    def force(self, x: np.ndarray) -> np.ndarray:
        """Friction force (n_active,) at displacements x (n_active, n_dof)."""
        if self.b is None:
            np.copyto(self.u, x[:, self.a])
        else:
            np.subtract(x[:, self.a], x[:, self.b], out=self.u)
        if self.stepper is not None:
            return self.stepper.step()
        return np.array([self.el.step(s, ui).F for s, ui in zip(self.states, self.u)])

    def keep(self, idx: np.ndarray) -> None:
        """Drop the histories not in idx (frequencies that reached steady state)."""
        if self.stepper is not None:
            self.stepper = self.el.batch_stepper(self.stepper.states[idx])
            self.u = self.stepper.u
        else:
            self.states, self.u = [self.states[i] for i in idx], self.u[idx]


def _curve_operators(model: Model, omegas: np.ndarray, ns: int):
    """Step operator B = [B1, B2, -A^-1 e_1 .. -A^-1 e_L] (n_f, n, 2n + L), forcing (ns, n_f, n)."""
    lin = model.linear
    dt = 2.0 * np.pi / (omegas * ns)
    w2, w1 = (1.0 / dt**2)[:, None, None], (1.0 / (2.0 * dt))[:, None, None]
    Ainv = np.linalg.inv(lin.M * w2 + lin.C * w1)
    E = np.zeros((model.n, len(model.links)))
    for l, link in enumerate(model.links):
        E[link.dof_a, l] = 1.0
        if link.dof_b is not None:
            E[link.dof_b, l] = -1.0
    B = np.concatenate([Ainv @ (2.0 * lin.M * w2 - lin.K), Ainv @ (lin.C * w1 - lin.M * w2),
                        -(Ainv @ E)], axis=2)
    th = 2.0 * np.pi * np.arange(ns) / ns
    fext = sum(np.outer(np.cos(h * th), f.real) - np.outer(np.sin(h * th), f.imag)
               for h, f in model.forcing.items())  # (ns, n): Re(F e^{i h theta})
    return B, np.einsum("fij,tj->tfi", Ainv, fext)


def _settled_many(d1, d2, count, tol):
    """:func:`_settled` for many frequencies: d1, d2 the last two changes, count of them."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.where(d1 > 0, np.minimum(d2 / d1, 0.999), 0.999)
    tail = d2 * np.maximum(1.0, rho / (1.0 - rho))
    return (count >= 3) & ((d2 == 0.0) | (tail < tol))


class _CurveMarch:
    """State of :func:`march_curve`: the active frequencies and their arrays."""

    def __init__(self, model: Model, omegas: np.ndarray, ns: int):
        nf, n = omegas.size, model.n
        self.n, self.r, self.ns = n, model.response_dof, ns
        self.B, self.G = _curve_operators(model, omegas, ns)
        self.links = [_BatchLink(link, nf) for link in model.links]
        self.act = np.arange(nf)                          # frequencies still marching
        self.X = np.zeros((nf, 2 * n + len(self.links)))  # [x_n, x_(n-1), F_l]
        self.hist = np.empty((nf, ns))
        self.prev = np.zeros((nf, _SS_HARMONICS), complex)
        self.d = np.zeros((2, nf))                        # last two changes per period
        self.count = np.zeros(nf, int)

    def period(self) -> None:
        """March every active frequency over one period; update the change measure."""
        X, B, n, hist = self.X, self.B, self.n, self.hist
        for j in range(self.ns):
            x = X[:, :n]
            for l, bl in enumerate(self.links):
                X[:, 2 * n + l] = bl.force(x)
            x_new = self.G[j] + (B @ X[..., None])[..., 0]
            X[:, n:2 * n] = x
            X[:, :n] = x_new
            hist[:, j] = X[:, n + self.r]   # x at t = j dt, as in march
        c = np.fft.rfft(hist, axis=1)[:, :_SS_HARMONICS] / self.ns
        change = np.linalg.norm(c - self.prev, axis=1) / np.maximum(
            np.linalg.norm(c, axis=1), 1e-300)
        self.d = np.stack([self.d[1], change])
        self.count += 1
        self.prev = c

    def keep(self, idx: np.ndarray) -> None:
        """Continue with the active frequencies idx (indices into the active set)."""
        self.act, self.X, self.hist, self.prev = (self.act[idx], self.X[idx], self.hist[idx],
                                                  self.prev[idx])
        self.d, self.count, self.B, self.G = (self.d[:, idx], self.count[idx], self.B[idx],
                                              self.G[:, idx])
        for bl in self.links:
            bl.keep(idx)


def march_curve(model: Model, omegas, steps_per_period: int = 256, max_periods: int = 3000,
                tol: float = 1e-6) -> CurveSteadyState:
    """March the model at every frequency of ``omegas`` at once to periodic steady state.

    The scheme and steady-state test of :func:`march` (each frequency starts at rest
    with virgin elements and stops on its own), vectorised over frequencies.

    Parameters
    ----------
    model : Model (needs M, C, K matrices)
    omegas : array_like, shape (n_freq,), positive [rad/s]
    steps_per_period : int, raised if needed for stability at the lowest frequency
    max_periods : int
    tol : float, relative tolerance on the extrapolated distance to steady state

    Returns
    -------
    CurveSteadyState
    """
    if model.linear.K is None:
        raise ValueError("time integration needs M, C, K matrices")
    if not all(isinstance(el, FrictionLink) for el in model.links):
        raise ValueError("march_curve handles friction links only; use march for other force elements")
    omegas = np.atleast_1d(np.asarray(omegas, dtype=float))
    if omegas.ndim != 1 or omegas.size == 0 or not np.all(np.isfinite(omegas) & (omegas > 0)):
        raise ValueError(f"omegas must be a non-empty 1-D array of positive numbers, got {omegas}")
    nf = omegas.size
    ns = _stable_steps(model, float(omegas.min()), steps_per_period)
    run = _CurveMarch(model, omegas, ns)
    out_hist, periods, conv = np.empty((nf, ns)), np.full(nf, max_periods), np.zeros(nf, bool)
    steps = 0
    for p in range(1, max_periods + 1):
        run.period()
        steps += ns
        # the first change (p = 2) compares with the period before; count p = 1 out
        settled = _settled_many(run.d[0], run.d[1], run.count - 1, tol)
        done = settled | (p == max_periods)
        if np.any(done):
            idx = run.act[done]
            out_hist[idx], periods[idx], conv[idx] = run.hist[done], p, settled[done]
            if np.all(done):
                break
            run.keep(np.flatnonzero(~done))
    res = [_result(w, out_hist[i], periods[i], ns, conv[i]) for i, w in enumerate(omegas)]
    return CurveSteadyState(omegas, np.array([s.amplitude for s in res]),
                            np.array([s.amplitude_h1 for s in res]), periods, conv, ns,
                            out_hist, steps)


def steady_curve(model: Model, omegas, steps_per_period: int = 256, **kw):
    """:func:`march_curve` at steps_per_period and twice as many (step-size check).

    Returns (amplitude (n_freq,), amplitude_h1 (n_freq,), relative step-size error
    estimate (n_freq,), finer CurveSteadyState); RuntimeError if a frequency did not
    reach steady state. The finer run is reported, the change is its error bound (as
    in :func:`steady_amplitude`).
    """
    a = march_curve(model, omegas, steps_per_period, **kw)
    b = march_curve(model, omegas, 2 * a.steps_per_period, **kw)
    bad = ~(a.converged & b.converged)
    if np.any(bad):
        raise RuntimeError("time integration did not reach steady state at omega = "
                           f"{', '.join(f'{w:g}' for w in b.omega[bad])}")
    err = np.abs(b.amplitude - a.amplitude) / np.maximum(b.amplitude, 1e-300)
    return b.amplitude, b.amplitude_h1, err, b
