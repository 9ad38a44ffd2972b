"""Time-integration reference: the ring of N_r blades marched to its periodic steady state.

Explicit central differences (as :mod:`harmonic_balance.timeint`), vectorised over the
frequencies of a curve (state (n_f, n))::

    (M / dt^2 + C / (2 dt)) x_(n+1) = f(t_n) - K x_n - f_c(x_n)
                                      + M (2 x_n - x_(n-1)) / dt^2 + C x_(n-1) / (2 dt)

Contact forces f_c = Q^T [N, f_t]: N = k_n max(p, 0) and the friction of the C core's
Jenkins element (``IwanElement.step_batch``, one call per element type per step, its
own history, slip force mu N). Start: the frictionless prestress state at rest, the
sliders virgin there (tangential input s - s_static), the same convention as the HB.
No Fourier series and no periodicity assumption. Steady state: the first harmonic of
u_a of every blade, period by period; stops when its change, extrapolated
geometrically (transient ~ rho^p), is below ``tol`` of the amplitude.
"""
from __future__ import annotations

import numpy as np

from fmu_src.element import IwanElement

from .hb import prestress
from .ring import ring_matrices
from .sector import N_DOF, U_A, Y_D, Sector

#: Fraction of the stability limit 2 / omega_max of the stuck ring.
CFL = 0.5


def march_ring(sector: Sector, omegas, cf=None, f0=None, steps_per_period: int = 0,
               max_periods: int = 3000, tol: float = 1e-6) -> dict:
    """Steady first-harmonic amplitude of u_a (blade 0) at each frequency [rad/s].

    Returns
    -------
    dict: amplitude (n_f,) [m], amplitude_blades (n_f, N_r), phase_steps (n_f, N_r) [rad]
    (blade j+1 minus blade j, should all be phi), periods (n_f,), settle_error (n_f,)
    (extrapolated remaining change, relative), steps_per_period, converged (n_f,).
    """
    cfg = sector.cfg
    cf = cfg.cf if cf is None else float(cf)
    f0 = cfg.f0 if f0 is None else float(f0)
    r = ring_matrices(sector)
    omegas = np.atleast_1d(np.asarray(omegas, dtype=float))
    nf, n, nr = omegas.size, r.M.shape[0], r.n_blades
    Kst = r.K + r.Q.T @ (r.k[:, None] * r.Q)
    w_max = np.sqrt(np.max(np.linalg.eigvals(np.linalg.solve(r.M, Kst)).real))
    ns = steps_per_period or int(np.ceil(2 * np.pi / omegas.min() / (CFL * 2 / w_max)))
    dt = 2 * np.pi / omegas / ns  # (nf,)
    Ainv = np.array([np.linalg.inv(r.M / h**2 + r.C / (2 * h)) for h in dt])
    st = prestress(sector, cf)
    x = np.tile(np.tile(st["q"], nr), (nf, 1))
    xm = x.copy()
    Qp, Qs = r.Q[0::2], r.Q[1::2]
    kn = r.k[0::2]
    s0 = np.tile(st["s"], nr)
    groups = _groups(r.points, sector.cfg.mu)
    N_ring = np.tile(st["N"], nr)
    states = [el.initial_states(nf * len(idx), np.tile(N_ring[idx], nf)) for el, idx in groups]
    fext = np.zeros((nf, n))
    fext[:, Y_D::N_DOF] = cf
    phase = cfg.phi * np.arange(nr)
    ua = np.arange(nr) * N_DOF + U_A
    theta = 2 * np.pi * np.arange(ns) / ns
    hist = np.empty((ns, nf, nr))
    prev, deltas, periods = None, [], 0
    est = np.full(nf, np.inf)
    out = {"steps_per_period": ns, "dt": dt}
    while periods < max_periods:
        periods += 1
        for i in range(ns):
            P = x @ Qp.T
            N = kn * np.maximum(P, 0.0)
            S = x @ Qs.T - s0
            ft = np.empty_like(S)
            for (el, idx), sts in zip(groups, states):
                ft[:, idx] = el.step_batch(sts, S[:, idx].ravel(), N[:, idx].ravel())[0].reshape(nf, -1)
            fc = N @ Qp + ft @ Qs
            fext[:, ua] = f0 * np.cos(theta[i] + phase)
            rhs = (fext - x @ r.K.T - fc + (2 * x - xm) @ r.M.T / dt[:, None] ** 2
                   + xm @ r.C.T / (2 * dt[:, None]))
            xm, x = x, np.einsum("fij,fj->fi", Ainv, rhs)
            hist[i] = x[:, ua]
        H1 = 2.0 / ns * (np.exp(-1j * theta) @ hist.reshape(ns, -1)).reshape(nf, nr)
        if prev is not None:
            deltas.append(np.abs(H1 - prev).max(axis=1) / np.abs(H1).max(axis=1))
            if len(deltas) >= 3:
                d = np.array(deltas[-3:])
                rho = np.clip(d[-1] / np.maximum(d[-2], 1e-300), 0.0, 0.999)
                est = d[-1] * rho / (1 - rho)
                if np.all((est < tol) & (d[-1] < tol)):
                    out.update(converged=np.ones(nf, bool), settle_error=est)
                    break
        prev = H1
    else:
        out.update(converged=np.zeros(nf, bool), settle_error=est)
    amp = np.abs(H1)
    out.update(amplitude=amp[:, 0], amplitude_blades=amp, periods=periods,
               phase_steps=np.angle(H1[:, (np.arange(nr) + 1) % nr] / H1))
    return out


def _groups(points, mu):
    """One C element per distinct (k_t) and the indices of its contact points."""
    kts = sorted({p.kt for p in points})
    return [(IwanElement.jenkins(kt, mu), np.array([i for i, p in enumerate(points) if p.kt == kt]))
            for kt in kts]
