"""Time-integration reference: the ring of N_r blades (tuned) or of all N_b blades with a
mistuning pattern (:mod:`~harmonic_balance.bladed_disk.mistuning`) marched to its periodic steady state.

Explicit central differences (as :mod:`harmonic_balance.timeint`), vectorised over the
frequencies of a curve (state (n_f, n))::

    (M / dt^2 + C / (2 dt)) x_(n+1) = f(t_n) - K x_n - f_c(x_n)
                                      + M (2 x_n - x_(n-1)) / dt^2 + C x_(n-1) / (2 dt)

Contact forces from the ring's ContactElements (:class:`.ring.RingHB`, the same
elements as the HB): N = k_n max(p, 0) (C1 of :mod:`harmonic_balance.contact`) and the
friction of each element's C-core Jenkins element stepped with its own history at
that N (``IwanElement.step_batch``: one call per element type per step, all
frequencies and contact points at once; ContactElement.stepper is one state per call),
dashpots in C. Start: the frictionless prestress state at rest, the
sliders virgin there (tangential input s - s_static), the same convention as the HB;
or (``start``) a given displacement, velocity and acceleration, the sliders first stepped
through a given displacement history (e.g. a harmonic-balance period, :mod:`.steady`).
No Fourier series and no periodicity assumption. Steady state: the first harmonic of
the response DOF (u_a) of every blade, period by period; stops when its change, extrapolated
geometrically (transient ~ rho^p), is below ``tol`` of the amplitude.
"""
from __future__ import annotations

import numpy as np

from .ring import RingHB
from .ring_hb import MistunedRingHB
from .sector import Sector

#: Fraction of the stability limit 2 / omega_max of the stuck ring.
CFL = 0.5


def march_ring(sector: Sector, omegas, cf=None, f0=None, steps_per_period: int = 0,
               max_periods: int = 3000, tol: float = 1e-6, kappa=None, surfaces=None,
               start=None) -> dict:
    """Steady first-harmonic amplitude of the response DOF (u_a) of blade 0 at each
    frequency [rad/s].

    ``kappa`` (N_b,): blade stiffness factors; the whole ring of N_b blades is marched
    (:class:`.ring_hb.MistunedRingHB`'s model, the same elements as its HB).
    ``surfaces`` {"left": Surface, "flat": Surface}: the damper's faces as contact
    surfaces (:class:`.surface_hb.SurfaceSectorHB`'s model on the ring, marched by
    :func:`.ring_surface.march_ring_surface`, whose dict is returned).
    ``start`` (x0 (n,), v0 (n,), a0 (n,), history (k, n)) on the ring's DOFs [m, m/s,
    m/s^2, m]: every frequency starts at x0 with velocity v0 and acceleration a0 (the
    central-difference start x(-dt) = x0 - dt v0 + dt^2 a0 / 2, Bathe, Finite Element
    Procedures, table 9.1: a first-order start errs by dt a0 / 2 in the velocity, 0.5 %
    of the amplitude's phase at 600 steps a period, which decays only with the damping),
    each contact's slider stepped through the displacements of ``history`` (oldest first)
    beforehand so it carries that past; default: rest.

    Returns
    -------
    dict: amplitude (n_f,) [m], amplitude_max (n_f,) (max |u_a - mean| of blade 0 over
    the last period) [m], mean (n_f,) (its mean) [m], amplitude_blades (n_f, N_r),
    phase_steps (n_f, N_r) [rad] (blade j+1 minus blade j, should all be phi), periods, settle_error (n_f,)
    (extrapolated remaining change, relative), steps_per_period, converged (n_f,).
    """
    cfg = sector.cfg
    cf = cfg.cf if cf is None else float(cf)
    f0 = cfg.f0 if f0 is None else float(f0)
    if surfaces is not None:
        if kappa is not None or start is not None:
            raise ValueError("the ring with contact surfaces is marched from rest, tuned: drop the "
                             "mistuning (kappa) and the start state")
        from .ring_surface import march_ring_surface
        from .surface_hb import SurfaceSectorHB
        return march_ring_surface(SurfaceSectorHB(sector, surfaces, 1, cf=cf, f0=f0), omegas,
                                  steps_per_period, max_periods, tol)
    # the ring's model, its contacts and prestress
    ring = (RingHB(sector, 1, cf=cf, f0=f0) if kappa is None
            else MistunedRingHB(sector, kappa, 1, cf=cf, f0=f0))
    lin, n, nr = ring.model.linear, ring.ndof, ring.blades
    c = _contact_arrays(ring)
    M, K = lin.M, lin.K
    C = lin.C + c["C"]
    omegas = np.atleast_1d(np.asarray(omegas, dtype=float))
    nf = omegas.size
    Kst = K + c["K_stuck"]
    w_max = np.sqrt(np.max(np.linalg.eigvals(np.linalg.solve(M, Kst)).real))
    ns = steps_per_period or int(np.ceil(2 * np.pi / omegas.min() / (CFL * 2 / w_max)))
    dt = 2 * np.pi / omegas / ns  # (nf,)
    Ainv = np.array([np.linalg.inv(M / h**2 + C / (2 * h)) for h in dt])
    x, xm, states = _initial(ring, c, nf, dt, start)
    Qp, Qs, kn, s0, groups = c["Qp"], c["Qs"], c["kn"], c["s0"], c["groups"]
    fext = np.zeros((nf, n))
    fext[:, sector.y_d::sector.n_dof] = cf
    phase = cfg.phi * np.arange(nr)
    fd = np.arange(nr) * sector.n_dof + sector.forced  # the EO force's DOFs
    ua = np.arange(nr) * sector.n_dof + sector.response  # the output DOFs
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
                # unclamped k_n p: the C core treats N <= 0 as lift-off (as ContactElement)
                ft[:, idx] = el.step_batch(sts, S[:, idx].ravel(),
                                           (kn[idx] * P[:, idx]).ravel())[0].reshape(nf, -1)
            fc = N @ Qp + ft @ Qs
            fext[:, fd] = f0 * np.cos(theta[i] + phase)
            rhs = (fext - x @ K.T - fc + (2 * x - xm) @ M.T / dt[:, None] ** 2
                   + xm @ C.T / (2 * dt[:, None]))
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
    amp, u0 = np.abs(H1), hist[:, :, 0]
    out.update(amplitude=amp[:, 0], amplitude_blades=amp, periods=periods, mean=u0.mean(axis=0),
               amplitude_max=np.abs(u0 - u0.mean(axis=0)).max(axis=0),
               phase_steps=np.angle(H1[:, (np.arange(nr) + 1) % nr] / H1))
    return out


def _initial(ring: RingHB, c: dict, nf: int, dt: np.ndarray, start):
    """Displacements now and one step back (nf, n) and the sliders' states (one per law
    group) at the start: rest at the prestress state, or ``start`` (:func:`march_ring`)."""
    Qp, Qs, kn, s0 = c["Qp"], c["Qs"], c["kn"], c["s0"]
    x0 = ring.x_static if start is None else np.asarray(start[0], float)
    N0 = kn * np.maximum(ring.x_static @ Qp.T, 0.0)   # virgin at the prestress state
    states = [el.initial_states(nf * len(idx), np.tile(N0[idx], nf)) for el, idx in c["groups"]]
    x = np.tile(x0, (nf, 1))
    if start is None:
        return x, x.copy(), states
    for xh in np.asarray(start[3], float):   # the same past at every frequency
        P, S = np.tile(xh @ Qp.T, (nf, 1)), np.tile(xh @ Qs.T - s0, (nf, 1))
        for (el, idx), sts in zip(c["groups"], states):
            el.step_batch(sts, S[:, idx].ravel(), (kn[idx] * P[:, idx]).ravel())
    v0, a0 = (np.asarray(v, float)[None, :] for v in start[1:3])
    return x, x - dt[:, None] * v0 + 0.5 * dt[:, None] ** 2 * a0, states


def _contact_arrays(ring: RingHB) -> dict:
    """The ring's ContactElements as arrays: rows of s and p (n_c, n), k_n, slip_ref,
    stuck stiffness and dashpots on the structure, and the C elements grouped by their law
    (one batched call per group per step)."""
    n = ring.ndof
    Qs, Qp, kn, s0 = [], [], [], []
    Kst, Cd = np.zeros((n, n)), np.zeros((n, n))
    by_kt = {}
    for i, el in enumerate(ring.points):
        kin = el.kinematics
        if el.m != 2:
            raise ValueError("the ring's time integration handles one slip direction per contact; "
                             "a blade with axial platform DOFs (two slip directions) is solved by "
                             "harmonic balance (damper upd without --timeint)")
        rows = np.zeros((2, n))
        rows[:, list(kin.dofs)] = kin.Q
        Qs.append(rows[0])
        Qp.append(rows[1])
        kn.append(el.k_n)
        s0.append(el.slip_ref)
        Kst += rows.T @ el.stuck_stiffness() @ rows
        if el.local_damping() is not None:
            Cd += rows.T @ el.local_damping() @ rows
        f = el.friction  # equal laws share one batched call (Jenkins points: by k_t, fs)
        key = (tuple(f.k), tuple(f.fs), f.k_res, f.N_ref, f.scale)
        by_kt.setdefault(key, (f, []))[1].append(i)
    groups = [(f, np.array(idx)) for f, idx in by_kt.values()]
    return {"Qs": np.array(Qs), "Qp": np.array(Qp), "kn": np.array(kn), "s0": np.array(s0),
            "K_stuck": Kst, "C": Cd, "groups": groups}
