"""Time-integration reference of the UPD ring with contact surfaces.

The sector model of :class:`.surface_hb.SurfaceSectorHB` (the blade, its damper's
faces as contact surfaces: massless node DOFs w, the bodies' condensed stiffness, one
ContactElement per node) is unrolled onto the short ring of N_r sectors
(:mod:`.ring`): sector j's DOFs (blade, damper and its nodes) are n j .. n (j + 1) - 1,
and every cyclic element of the sector (the blade coupling, the flat face on blade
j+1's platform) acts on sector j's DOFs through ``Q`` and on sector (j + 1) mod N_r's
through ``Q_next``, at the same time (no phase: the ring carries it). The EO force on
blade j is F0 cos(omega t + j phi). No cyclic-symmetry assumption, no Fourier series:
the ring is marched by :func:`harmonic_balance.timeint_surface.march_curve` from the
frictionless prestress state (its sliders virgin there, the harmonic balance's
convention) to its periodic steady state.
"""
from __future__ import annotations

import numpy as np

from ..contact import ContactElement, frictionless_statics
from ..forces import LinearElement
from ..kinematics import Kinematics
from ..linear import LinearModel
from ..model import Model
from ..timeint_surface import march_curve


def _unrolled(kin: Kinematics, offset: int, next_offset: int) -> Kinematics:
    """Kinematics of a sector element on ring DOFs (the neighbour's columns at next_offset)."""
    if not kin.cyclic:
        return Kinematics(np.asarray(kin.dofs) + offset, kin.Q)
    dofs = np.r_[np.asarray(kin.dofs) + offset, np.asarray(kin.dofs) + next_offset]
    Q = np.hstack([kin.Q, kin.Q_next])
    uniq, inv = np.unique(dofs, return_inverse=True)   # N_r = 1: the neighbour is itself
    Qu = np.zeros((Q.shape[0], uniq.size))
    np.add.at(Qu.T, inv, Q.T)
    return Kinematics(uniq, Qu)


def _element_on_ring(el, offset: int, next_offset: int, blade: int):
    kin = _unrolled(el.kinematics, offset, next_offset)
    name = f"{el.name} blade {blade}"
    if isinstance(el, LinearElement):
        return LinearElement(kin, el.K, el.C, name=name)
    if isinstance(el, ContactElement):
        return ContactElement(kin, el.k_n, el.friction, preload=el.preload, beta_c=el.beta_c,
                              name=name)
    raise ValueError(f"element {el.name!r} ({type(el).__name__}) has no ring form")


def surface_ring_model(shb) -> Model:
    """The ring of N_r sectors of a SurfaceSectorHB's model (module docstring).

    Parameters
    ----------
    shb : SurfaceSectorHB (or any SectorHB whose model's linear part is per sector)

    Returns
    -------
    Model on N_r n DOFs; the response DOF is blade 0's.
    """
    sec, model = shb.sector, shb.model
    nr, n, phi = sec.cfg.ring_blades, model.n, sec.cfg.phi
    lin = model.linear
    M, C, K = (np.kron(np.eye(nr), A) for A in (lin.M, lin.C, lin.K))
    els = [_element_on_ring(el, n * j, n * ((j + 1) % nr), j)
           for j in range(nr) for el in model.elements]
    f_static = np.tile(np.real(model.forcing[0]), nr)
    f_eo = np.concatenate([model.forcing[1] * np.exp(1j * phi * j) for j in range(nr)])
    return Model(LinearModel(M=M, C=C, K=K), els, {0: f_static, 1: f_eo}, model.response_dof)


def ring_start(shb, x: np.ndarray, basis=None):
    """The ring's periodic motion of a sector solution, for :func:`march_ring_surface`'s ``start``.

    Parameters
    ----------
    shb : SurfaceSectorHB
        The ring's sector model.
    x : ndarray (n_b n_x,)
        A harmonic balance solution on ``basis``: of ``shb`` (n_x = the sector's and node
        DOFs) or of the sector alone (n_x = ``shb.sector.n_dof``, e.g. of
        :class:`.surface_hb.CondensedSurfaceSectorHB`); the node DOFs are not used (the
        march solves them).
    basis : FourierBasis, optional
        Default ``shb.basis``.

    Returns
    -------
    callable ``ns`` -> (ns, N_r n) [m]: sector j's DOFs are the sector's at theta + j phi
    (the EO force's phase on blade j), sampled at theta = 2 pi k / ns.
    """
    from ..fourier import FourierBasis
    from .hb import neighbour_map

    basis = shb.basis if basis is None else basis
    phi, n = shb.sector.cfg.phi, shb.model.n
    X = np.asarray(x, float).reshape(basis.nb, -1)
    if X.shape[1] not in (n, shb.sector.n_dof):
        raise ValueError(f"x has {X.shape[1]} DOFs per harmonic; the sector has {shb.sector.n_dof}, "
                         f"with its nodes {n}")
    X = np.hstack([X, np.zeros((basis.nb, n - X.shape[1]))])
    Xr = np.hstack([neighbour_map(basis, j * phi) @ X for j in range(shb.sector.cfg.ring_blades)])
    return lambda ns: FourierBasis(basis.harmonics, ns).E @ Xr


def march_ring_surface(shb, omegas, steps_per_period: int = 0, max_periods: int = 3000,
                       tol: float = 1e-6, start=None, start_basis=None) -> dict:
    """Steady response of blade 0's u_a on the ring with surfaces at each frequency [rad/s].

    ``start``: a sector solution x on ``start_basis`` (:func:`ring_start`); the ring then
    starts on its motion, its nodes in equilibrium along it and their sliders stepped
    through its loop (:func:`harmonic_balance.timeint_surface.march_curve`), instead of at
    rest at the frictionless prestress state.

    Returns
    -------
    dict: amplitude (n_f,) first-harmonic |u_a| of blade 0 [m] (the sector HB's
    ``amplitude_h1``), amplitude_max (n_f,) peak |u_a - mean| [m], periods (n_f,),
    converged (n_f,), steps_per_period, time_steps, W_friction (n_f,) [J] (all nodes of
    the ring over the last period), ring_dofs.
    """
    ring = surface_ring_model(shb)
    x0, _ = frictionless_statics(ring, apply=True)
    res = march_curve(ring, omegas, steps_per_period, max_periods, tol, x0=x0,
                      start=None if start is None else ring_start(shb, start, start_basis))
    mean = res.x_last.mean(axis=1, keepdims=True)
    return {"amplitude": res.amplitude_h1, "amplitude_max": np.abs(res.x_last - mean).max(axis=1),
            "periods": res.periods, "converged": res.converged,
            "steps_per_period": res.steps_per_period, "time_steps": res.time_steps,
            "W_friction": res.W_friction, "ring_dofs": ring.n}
