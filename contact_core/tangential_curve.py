"""Virgin curves, force control and cyclic loading on a ``TangentialProblem``.

The contact model itself is advanced step by step with its slip history
(``contact_core.tangential``); nothing here assumes Masing's rule.

Step choice (``march``): the next point is accepted when the computed force
differs from the tangent prediction ``T_prev + k_tan * du`` by at most
``CURVE_TOL * mu N`` (about four times the error of linear interpolation
between the points), else the step is halved; the next step scales with
sqrt(CURVE_TOL / error). Points are therefore dense where the curve bends
(towards gross slip) and sparse where it is straight. A monotone march stops
exactly at gross slip, ``delta_gs`` (``TangentialProblem.gross_slip_displacement``).

Symbols: u (= delta) rigid tangential displacement [m], T tangential force [N],
N normal force [N], mu friction coefficient, k_t initial stiffness [N/m],
u_ref = mu N / k_t [m] the displacement at which the stuck line reaches mu N.
"""
from __future__ import annotations

import datetime
import sys
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from contact_core.curve import VirginCurve
from contact_core.tangential import TangentialProblem, TangentialSolution, TangentialState

#: Tangent-prediction error allowed per step, relative to mu N (module docstring).
CURVE_TOL = 1e-3
#: Largest step, relative to u_ref (at least ~10 points on a straight curve).
MAX_STEP = 0.1
#: Smallest step, relative to u_ref (a stick/slip switch of one node is a kink
#: no step refinement can smooth; stop refining there).
MIN_STEP = 1e-4
#: Force control: a target within this fraction of mu N above mu N is gross
#: slip; more is refused. Root-finding tolerance on T relative to mu N.
FORCE_TOL = 1e-9


@dataclass(frozen=True)
class TangentialPath:
    """Points computed along a loading path, in order.

    Attributes
    ----------
    points : list of TangentialSolution
        Every accepted point, the starting state's point first.
    dissipation : ndarray, shape (m,)
        Cumulative frictional dissipation sum(mult |q| |ds|) [J] at each point.
    state : TangentialState
        The history after the last point (to continue loading).
    """

    points: list
    dissipation: np.ndarray
    state: TangentialState

    @property
    def u(self) -> np.ndarray:
        """Rigid tangential displacement [m], shape (m,)."""
        return np.array([p.delta for p in self.points])

    @property
    def T(self) -> np.ndarray:
        """Tangential force [N], shape (m,)."""
        return np.array([p.T for p in self.points])

    @property
    def stick_fraction(self) -> np.ndarray:
        """Stick share of the contact area per point, shape (m,)."""
        return np.array([p.stick_fraction for p in self.points])

    @property
    def iterations(self) -> np.ndarray:
        """Active-set iterations per point, shape (m,)."""
        return np.array([p.iterations for p in self.points])


def start_point(problem: TangentialProblem, state: TangentialState) -> TangentialSolution:
    """The solution at ``state`` itself (re-solved: zero increment)."""
    return problem.solve(state, state.delta)[0]


#: Resolution of the march's progress reports: ``done`` of ``PROGRESS_TOTAL`` parts of the travel.
PROGRESS_TOTAL = 100


def march(problem: TangentialProblem, state: TangentialState, u_target: float,
          tol: float = CURVE_TOL, first: TangentialSolution | None = None,
          progress=None) -> TangentialPath:
    """Load monotonically from ``state.delta`` to ``u_target`` with adaptive steps.

    ``progress(done, total, label)``, if given, is called after each accepted load
    step with the travelled fraction of the displacement as ``done`` of
    ``PROGRESS_TOTAL`` (the number of steps is not known in advance).
    """
    u_target = float(u_target)
    if not np.isfinite(u_target):
        raise ValueError(f"tangential displacement must be finite, got {u_target}")
    scale = problem.mu * problem.N
    u_ref = scale / problem.k_t if scale > 0 else abs(u_target - state.delta) or 1.0
    prev = first or start_point(problem, state)
    points, diss = [prev], [0.0]
    sign = 1.0 if u_target >= state.delta else -1.0
    du = MAX_STEP * u_ref
    u_start, travel = state.delta, abs(u_target - state.delta)
    while sign * (u_target - state.delta) > 0:
        step = min(du, sign * (u_target - state.delta))
        sol, new = problem.solve(state, state.delta + sign * step)
        err = abs(sol.T - prev.T - prev.k_tan * sign * step) / max(scale, 1e-300)
        if err > tol and step > MIN_STEP * u_ref:
            du = 0.5 * step
            continue
        slip = new.s - state.s
        diss.append(diss[-1] + float(np.sum(problem.w * np.abs(new.q * slip))))
        points.append(sol)
        state, prev = new, sol
        grow = 2.0 if err == 0 else float(np.clip(0.9 * np.sqrt(tol / err), 0.3, 2.0))
        du = min(MAX_STEP * u_ref, max(step * grow, MIN_STEP * u_ref))
        if progress is not None:
            done = int(PROGRESS_TOTAL * min(abs(state.delta - u_start) / travel, 1.0))
            progress(done, PROGRESS_TOTAL, f"load step {len(points) - 1}")
    return TangentialPath(points, np.array(diss), state)


def virgin_curve(problem: TangentialProblem, tol: float = CURVE_TOL, progress=None) -> TangentialPath:
    """The virgin curve T(u) from the unloaded state to gross slip (T = mu N); ``progress``
    as in ``march``."""
    if problem.mu <= 0:
        raise ValueError(f"a virgin curve needs mu > 0, got {problem.mu}")
    state = problem.initial_state()
    return march(problem, state, problem.gross_slip_displacement(state), tol, progress=progress)


def solve_force(problem: TangentialProblem, state: TangentialState, T_target: float):
    """Force control: the increment from ``state`` whose force is ``T_target`` [N].

    Returns
    -------
    (TangentialSolution, TangentialState)

    Raises
    ------
    ValueError
        ``T_target`` not finite or beyond gross slip (|T| > mu N).
    """
    T_target = float(T_target)
    limit = problem.mu * problem.N
    if not np.isfinite(T_target):
        raise ValueError(f"tangential force must be finite, got {T_target}")
    if abs(T_target) > limit * (1.0 + FORCE_TOL):
        raise ValueError(f"tangential force {T_target:.6g} N exceeds the gross-slip limit "
                         f"mu N = {limit:.6g} N: no static solution in force control")
    sign = 1.0 if T_target >= float(problem.w @ state.q) else -1.0
    u_gs = problem.gross_slip_displacement(state, sign)
    if abs(T_target) >= limit * (1.0 - FORCE_TOL):
        return problem.solve(state, u_gs)

    def residual(delta):
        return problem.solve(state, delta)[0].T - T_target

    lo, hi = sorted((state.delta, u_gs))
    delta = optimize.brentq(residual, lo, hi, xtol=1e-14 * max(abs(hi - lo), 1e-300),
                            rtol=4 * np.finfo(float).eps, maxiter=200)
    return problem.solve(state, delta)


def state_of(problem: TangentialProblem, sol: TangentialSolution) -> TangentialState:
    """The slip history a computed point leaves behind (to continue loading from it)."""
    return TangentialState(sol.delta, sol.s[problem.idx].copy(), sol.q[problem.idx].copy())


def virgin_point(problem: TangentialProblem, *, u: float | None = None, T: float | None = None,
                 tol: float = CURVE_TOL) -> TangentialSolution:
    """The state on the virgin curve at displacement ``u`` [m] or force ``T`` [N].

    Loads from the virgin state with the curve's step control, carrying the
    slip history, so tractions and slips at the point are those of the curve.
    ValueError for a force beyond gross slip.
    """
    if (u is None) == (T is None):
        raise ValueError("give exactly one of u or T")
    state = problem.initial_state()
    if u is not None:
        return march(problem, state, u, tol).points[-1]
    T = float(T)
    if not np.isfinite(T):
        raise ValueError(f"tangential force must be finite, got {T}")
    if abs(T) > problem.mu * problem.N * (1.0 + FORCE_TOL):
        return solve_force(problem, state, T)[0]  # raises the gross-slip ValueError
    sign = 1.0 if T >= 0 else -1.0
    path = march(problem, state, problem.gross_slip_displacement(state, sign), tol)
    before = [p for p in path.points if sign * p.T <= sign * T]
    return solve_force(problem, state_of(problem, before[-1]), T)[0]


def cyclic(problem: TangentialProblem, turning_points, tol: float = CURVE_TOL) -> TangentialPath:
    """Displacement-controlled loading through ``turning_points`` [m], from the virgin state.

    Each leg is a monotone ``march``; the slip history is carried across legs,
    so a reversal unloads the contact as the model dictates (no Masing rule).
    """
    state = problem.initial_state()
    points, diss, first = [], [0.0], None
    for u_k in turning_points:
        path = march(problem, state, u_k, tol, first)
        skip = 1 if points else 0
        points.extend(path.points[skip:])
        diss.extend((diss[-1] + path.dissipation[1:]).tolist())
        state, first = path.state, path.points[-1]
    return TangentialPath(points, np.array(diss[: len(points)]), state)


def hysteresis_loop(problem: TangentialProblem, amplitude: float, tol: float = CURVE_TOL):
    """One steady loop at displacement amplitude ``a``: 0 -> a -> -a -> a.

    Returns
    -------
    path : TangentialPath
        The whole history; the loop is the part after the first arrival at +a.
    energy : dict
        ``W_area`` = closed-loop integral of T du (trapezoid) [J] and
        ``W_friction`` = frictional dissipation over the loop [J] (exact for the
        discrete model at the computed steps), ``T_amplitude`` [N].
    """
    a = float(amplitude)
    if not (np.isfinite(a) and a > 0):
        raise ValueError(f"loop amplitude must be positive and finite, got {a}")
    path = cyclic(problem, [a, -a, a], tol)
    u, T = path.u, path.T
    start = int(np.flatnonzero(np.isclose(u, a, rtol=0, atol=1e-12 * a))[0])
    # a -> -a -> a runs the loop counter-clockwise: the driver's work is positive
    W_area = float(np.trapezoid(T[start:], u[start:]))
    W_fric = float(path.dissipation[-1] - path.dissipation[start])
    return path, {"W_area": W_area, "W_friction": W_fric, "T_amplitude": float(T[start])}


def provenance(command: str | None = None) -> dict:
    """Code version, UTC date and command line for a result file."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        code = version("damper-toolkit")
    except PackageNotFoundError:
        code = "unknown (package not installed)"
    return {"code_version": code,
            "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "command": command if command is not None else " ".join(sys.argv)}


def to_virgin_curve(path: TangentialPath, problem: TangentialProblem, *, load_case: str = "CNF",
                    k_n: float | None = None, geometry: dict | None = None,
                    materials: dict | None = None, grid: dict | None = None,
                    command: str | None = None) -> VirginCurve:
    """The virgin curve as the project's curve file object (``contact_core.curve``)."""
    u, T = path.u, path.T
    keep = np.concatenate([[True], np.diff(u) > 0])  # drop repeated u (zero steps)
    return VirginCurve(u=u[keep], T=np.maximum(T[keep], 0.0), N=problem.N, mu=problem.mu, tail="flat",
                       k_t=problem.k_t, k_n=k_n, load_case=load_case,
                       geometry=geometry or {}, materials=materials or {}, grid=grid or {},
                       provenance=provenance(command))
