"""Quasi-static loading of a contact surface (:mod:`.surface`): preload, cyclic slip.

Each load step solves the equilibrium of the surface piece with its contact
points' history carried from the last accepted step::

    K x + f_c(x) = f_ext,     x = [w; q]                                  (Q1)

on the free DOFs (every w, and the rigid inputs q that are force-controlled; the
others are prescribed). f_c are the ContactElements' forces reached from the
committed state along the straight path (the C core's ``iwan2_eval``, the trial of
``iwan2_step``), so a step is one increment of the incremental plasticity problem
the contact core's tangential solve poses (thesis A.2), solved by Newton with the
consistent tangent of the element. The laws are piecewise linear: Newton ends
exactly once the stick/slip and contact sets settle; a step whose Newton does not
settle in ``MAX_NEWTON`` iterations is split in two (at most ``MAX_SPLITS`` times).

Symbols as in :mod:`.surface`; N the full-model normal force [N], e its
eccentricity along x [m] (flat face), T the full-model tangential force [N].
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

#: Newton stops when the residual is below this fraction of the load scale
#: (round-off of the dense solves with PENALTY 1e4 is ~1e-12 of it).
RESIDUAL_RTOL = 1e-9
#: Newton iterations per step before the step is split.
MAX_NEWTON = 30
#: Splits of one step in halves before giving up (RuntimeError).
MAX_SPLITS = 12


@dataclass
class SurfaceState:
    """A converged state: DOFs x (3 n + r,), the nodes' friction states (committed) and
    the loads {input name: force [N] or moment [N m]} it carries."""

    x: np.ndarray
    friction: list
    loads: dict = field(default_factory=dict)

    def copy(self) -> SurfaceState:
        return SurfaceState(self.x.copy(), [s.copy() for s in self.friction], dict(self.loads))


def _slider(el):
    """The element's friction law in its slip dimension (2D for two tangents, else 1D)."""
    return el.friction2d if el.friction2d is not None else el.friction


def initial_state(surface) -> SurfaceState:
    """Unloaded, open surface: x = 0, virgin sliders at N = 0."""
    return SurfaceState(np.zeros(surface.n_dof),
                        [_slider(el).initial_state(0.0) for el in surface.elements])


def contact_forces(surface, state: SurfaceState, x: np.ndarray, jac: bool = True):
    """f_c (n_dof,) and its tangent (n_dof, n_dof) reached from ``state`` (trial, not committed)."""
    f = np.zeros(surface.n_dof)
    J = np.zeros((surface.n_dof, surface.n_dof)) if jac else None
    m = surface.d
    for i, el in enumerate(surface.elements):
        d = slice(m * i, m * i + m)
        w = x[d]
        p = el.preload + w[-1]
        on = p > 0.0
        if m == 3:
            out = el.friction2d.eval(state.friction[i], w[:2] - el.slip_ref, el.k_n * p)
            Ft, Kt, dFdN = out.F, out.K, out.dFdN
        else:
            out = el.friction.eval(state.friction[i], w[0] - el.slip_ref, el.k_n * p)
            Ft, Kt, dFdN = np.array([out.F]), np.array([[out.kt]]), np.array([out.dFdN])
        f[d] = np.append(Ft, el.k_n * p if on else 0.0)
        if jac:
            J[d, d] = np.block([[Kt, (dFdN * el.k_n)[:, None]],
                                [np.zeros((1, m - 1)), np.array([[el.k_n if on else 0.0]])]])
    return f, J


def commit(surface, state: SurfaceState, x: np.ndarray, loads: dict) -> SurfaceState:
    """The state after accepting x under ``loads``: every node's slider stepped to its w."""
    new = state.copy()
    new.x = x.copy()
    new.loads = dict(loads)
    m = surface.d
    for i, el in enumerate(surface.elements):
        w = x[m * i:m * i + m]
        slip = w[:2] - el.slip_ref if m == 3 else w[0] - el.slip_ref
        _slider(el).step(new.friction[i], slip, el.k_n * (el.preload + w[-1]))
    return new


def _newton(surface, state, x, free, f_ext, scale):
    """Solve (Q1) on ``free`` from the guess x; returns x or None (did not settle).

    Newton with backtracking on |r|: a node at its stick/slip (or contact) threshold
    switches its tangent between iterates, and the full step can cycle between two
    sets; the damped step cannot (the residual must fall)."""
    def residual(x):
        fc, Jc = contact_forces(surface, state, x)
        return (surface.K @ x + fc - f_ext)[free], Jc

    r, Jc = residual(x)
    for _ in range(MAX_NEWTON):
        norm = np.linalg.norm(r)
        if np.max(np.abs(r)) <= RESIDUAL_RTOL * scale:
            return x
        J = (surface.K + Jc)[np.ix_(free, free)]
        try:
            dx = sla.solve(J, -r, check_finite=False)
        except (sla.LinAlgError, ValueError):
            return None   # singular: no contact holds the free DOFs at this iterate
        if not np.all(np.isfinite(dx)):
            return None
        alpha = 1.0
        while True:
            trial = x.copy()
            trial[free] += alpha * dx
            r_t, Jc_t = residual(trial)
            if np.linalg.norm(r_t) < (1.0 - 1e-4 * alpha) * norm or alpha < 1e-6:
                break
            alpha *= 0.5
        x, r, Jc = trial, r_t, Jc_t
    return None


def step(surface, state: SurfaceState, prescribed: dict, loads: dict, guess=None) -> SurfaceState:
    """One load step to the prescribed inputs and loads (split when Newton does not settle).

    Parameters
    ----------
    surface : Surface
    state : SurfaceState
        The last accepted state.
    prescribed : dict {input name: value}
        Displacement-controlled rigid inputs [m or rad]; the rest are free.
    loads : dict {input name: value}
        Forces [N] (moments [N m]) on free rigid inputs.
    guess : ndarray (n_dof,), optional
        Start of Newton (default: the state's x with the prescribed values set).

    Raises
    ------
    RuntimeError
        The step cannot be solved even after MAX_SPLITS splits.
    """
    return _step(surface, state, prescribed, loads, guess, 0)


def _targets(surface, prescribed, loads):
    n_dof = surface.n_dof
    free = np.ones(n_dof, bool)
    fixed_val, f_ext = {}, np.zeros(n_dof)
    for name, v in prescribed.items():
        k = surface.input_dof(name)
        free[k] = False
        fixed_val[k] = float(v)
    for name, v in loads.items():
        f_ext[surface.input_dof(name)] = float(v)
    return free, fixed_val, f_ext


def _step(surface, state, prescribed, loads, guess, depth):
    free, fixed_val, f_ext = _targets(surface, prescribed, loads)
    x = (state.x if guess is None else guess).copy()
    for k, v in fixed_val.items():
        x[k] = v
    scale = max(np.max(np.abs(f_ext)), surface_force_scale(surface, state), 1e-300)
    sol = _newton(surface, state, x, free, f_ext, scale)
    if sol is not None:
        return commit(surface, state, sol, loads)
    if depth >= MAX_SPLITS:
        raise RuntimeError("the contact surface found no equilibrium at this load step even "
                           f"after {MAX_SPLITS} step halvings: refine the load path or check "
                           "that the surface stays in contact")
    mid_p = {k: 0.5 * (state.x[surface.input_dof(k)] + v) for k, v in prescribed.items()}
    mid_l = {k: 0.5 * (state.loads.get(k, 0.0) + v) for k, v in loads.items()}
    half = _step(surface, state, mid_p, mid_l, None, depth + 1)
    return _step(surface, half, prescribed, loads, None, depth + 1)


def surface_force_scale(surface, state) -> float:
    """Force scale [N] of the residual test: the largest nodal elastic force of the state."""
    return float(np.max(np.abs(surface.K @ state.x)))


def preload(surface, force: float, eccentricity: float = 0.0,
            tangential=(0.0, 0.0)) -> SurfaceState:
    """Press the surface with full-model normal force N (at x = e on a flat face).

    Force control on the approach (and rotation); the tangential inputs are held
    at ``tangential`` [m]. Starts from every node in contact, so the first Newton
    iterate is the thesis's first contact-set hypothesis (A.1.4).

    Raises
    ------
    ValueError
        N not positive and finite, or an eccentricity on a surface without rotation.
    RuntimeError
        No equilibrium (e.g. the load leaves the face: the surface loses contact).
    """
    if not (np.isfinite(force) and force > 0):
        raise ValueError(f"the normal force must be positive and finite, got {force!r}: "
                         "a surface without normal load falls out of contact")
    loads = {"approach": float(force)}
    half = float(np.max(np.abs(surface.contact.grid.x)))
    if not (np.isfinite(eccentricity) and abs(eccentricity) < half):
        raise ValueError(f"eccentricity {eccentricity!r} m lies outside the face (|e| < {half:g} m): "
                         "the surface would tip over and lose contact")
    if "rotation" in surface.inputs:
        loads["rotation"] = float(force) * float(eccentricity)
    elif eccentricity:
        raise ValueError("an eccentric normal load needs a flat face (a rotation input)")
    state = initial_state(surface)
    x = state.x.copy()
    k_n = np.array([el.k_n for el in surface.elements])
    x[surface.d - 1:surface.n_w:surface.d] = surface.contact.grid.h + force / k_n.sum()
    x[surface.input_dof("approach")] = surface.contact.grid.h.max()
    pres = {f"tangential_{t}": u for t, u in zip(surface.tangents, tangential)}
    state = step(surface, state, pres, loads, guess=x)
    loaded = surface.normal_forces(state.x) > 0
    if not np.any(loaded):
        raise RuntimeError("the contact surface lost contact at every node: raise the normal load")
    if np.any(loaded & surface.zone_edge):
        raise ValueError("the contact reaches the edge of the potential contact zone: condense with "
                         "a larger zone (the spec's p_design or load_hint) for this load")
    return state


@dataclass(frozen=True)
class SurfacePath:
    """A displacement-controlled tangential path: u (k,) [m], T (k,) [N], friction work W (k,) [J]."""

    u: np.ndarray
    T: np.ndarray
    W: np.ndarray
    state: SurfaceState


def tangential_path(surface, state: SurfaceState, u_points, direction: str = "x") -> SurfacePath:
    """March the tangential input through ``u_points`` [m] at the state's normal loads.

    T is the force the driver applies on the input (the full-model tangential
    force, R^T W f); W the cumulative friction work of all nodes (exact for the
    straight paths between the points).
    """
    name = f"tangential_{direction}"
    k = surface.input_dof(name)
    held = {f"tangential_{t}": state.x[surface.input_dof(f"tangential_{t}")]
            for t in surface.tangents if t != direction}
    u, T, W = [], [], []
    for v in np.asarray(u_points, float):
        state = step(surface, state, {name: v} | held, state.loads)
        u.append(v)
        T.append(float((surface.K @ state.x)[k]))
        W.append(sum(s.W for s in state.friction))
    return SurfacePath(np.array(u), np.array(T), np.array(W), state)


def hysteresis_loop(surface, state: SurfaceState, amplitude: float, steps: int = 200):
    """Steady loop 0 -> a -> -a -> a at the state's normal loads.

    Returns
    -------
    path : SurfacePath
        The whole history.
    energy : dict
        ``W_area`` closed-loop integral of T du over -> -a -> a (trapezoid) [J],
        ``W_friction`` friction work over the loop [J], ``T_amplitude`` [N].
    """
    a = float(amplitude)
    if not (np.isfinite(a) and a > 0):
        raise ValueError(f"loop amplitude must be positive and finite, got {a!r}")
    leg = np.linspace(0.0, 1.0, steps + 1)[1:]
    pts = np.concatenate([a * leg, a - 2 * a * leg, -a + 2 * a * leg])
    path = tangential_path(surface, state, pts)
    start = steps - 1
    u, T = np.concatenate([[a], path.u[start + 1:]]), path.T[start:]
    W_area = float(np.trapezoid(T, u))
    return path, {"W_area": W_area, "W_friction": float(path.W[-1] - path.W[start]),
                  "T_amplitude": float(path.T[start])}


def stuck_stiffness(surface, state: SurfaceState, direction: str = "x") -> float:
    """Initial tangential stiffness dT/du [N/m] with every contact node stuck.

    The Schur complement of the stuck system on the tangential input: the bodies'
    stiffness on [w_d; u] plus each node in contact's slider stiffness on w_d.
    """
    d, n = surface.tangents.index(direction), surface.n
    rows = np.concatenate([np.arange(d, surface.n_w, surface.d),
                           [surface.input_dof(f"tangential_{direction}")]])
    Kd = surface.K[np.ix_(rows, rows)].copy()
    on = surface.normal_forces(state.x) > 0
    Kd[np.arange(n)[on], np.arange(n)[on]] += np.array([el.k_t for el in surface.elements])[on]
    Kww, kwu, kuu = Kd[:n, :n], Kd[:n, n], Kd[n, n]
    return float(kuu - kwu @ sla.solve(Kww, kwu, assume_a="sym"))


def cyclic_friction_work(surface, normal: float, amplitude: float, steps: int = 40) -> float:
    """Friction work [J] of one cycle of a force-controlled quasi-static loop.

    Preload ``normal`` [N], then the tangential force ramps 0 -> T_a, T_a -> -T_a,
    -T_a -> T_a in ``steps`` increments per leg (T_a = ``amplitude`` [N]); the work of
    the last two legs (the closed cycle, after the virgin loading) is returned.
    """
    state = preload(surface, normal)
    leg = np.linspace(0.0, 1.0, steps + 1)[1:]
    W = []
    for T in np.concatenate([amplitude * leg, amplitude - 2 * amplitude * leg,
                             -amplitude + 2 * amplitude * leg]):
        state = step(surface, state, {}, state.loads | {"tangential_x": T})
        W.append(sum(f.W for f in state.friction))
    return W[-1] - W[steps - 1]
