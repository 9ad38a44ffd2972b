"""A first solution of the sector at a low centrifugal load, reached along a path in CF.

Newton from the stuck start (:meth:`~.hb.SectorHB.stuck_guess`: the prestress plus the
linear response with every contact stuck) converges where that guess keeps the faces
closed. With the faces condensed
(:class:`~.surface_hb.CondensedSurfaceSectorHB`) the stuck response's first-harmonic
normal resultant on a face, |F_n,1|, grows with F0 while its prestress F_n,0 grows with
CF, so below the *open load*

    CF_open = CF max_faces |F_n,1| / F_n,0                                    (P1)

the guess opens a face for part of the period and Newton from it fails (UPD-24, 5 nodes
per side, H 1, CF 120 N, 400 Hz: no convergence in 40 iterations, 314 evaluations).
CF_open does not depend on the CF it is computed at (both sides of (P1) scale with it).
:func:`first_point` therefore starts at CF_open, where the stuck start holds, and walks
down to the CF in log-spaced loads, each Newton warm-started from the last
(:func:`cf_path`), halving a load step in log CF where Newton fails.

Symbols: CF centrifugal load of the damper [N], F0 EO force amplitude [N], omega [rad/s].
"""
from __future__ import annotations

import math

import numpy as np

from ..newton import NewtonError
from .solve import SolverError, solve_point

#: Largest ratio of two consecutive loads of the path. Measured on UPD-24 (5 nodes per
#: side, H 1, 400 Hz, 815 N -> 120 N): 2 steps of ratio 2.6 took 15 evaluations, 5 of
#: ratio 1.5 took 26, 8 steps from 300 N (ratio 1.12) 44: a few Newton iterations per load
#: at any of these ratios, so the path's cost is its number of loads.
STEP_RATIO = 2.0
#: Halvings (in log CF) of a load step whose Newton fails, before the path gives up
#: (a step of ratio 2 is then 2^(1/16) = 1.04).
MAX_HALVINGS = 4
#: Failed Newton solves one step of the path may take (its halvings' included) before the
#: path gives up: with MAX_HALVINGS alone a step that meets a wall (a load below which no
#: warm start converges) could fail 2^(MAX_HALVINGS + 1) - 1 times, each failure a Newton's
#: worth of line searches: ~350 evaluations on UPD-24 (condensed, 5 nodes per side, H 7),
#: ~70 s with the march's node solve in C, several minutes before. Paths that arrive fail
#: less: 815 -> 10 N at 400 Hz twice in 10 loads, 300 -> 40 N at 449.16 Hz once in 26.
MAX_STEP_FAILURES = 4
#: Newton iterations per load (a converging step took 3-9 on UPD-24; a failing one spends
#: its iterations' line searches, ~8 evaluations each).
MAX_ITER = 40


def open_load(hb, omega: float) -> float:
    """CF_open (P1) [N] of a sector with condensed surfaces at ``omega`` [rad/s].

    Parameters
    ----------
    hb : CondensedSurfaceSectorHB
        Its :class:`~harmonic_balance.surface_condensed.CondensedSurface` elements' first
        input is the face's approach (normal), as in
        :func:`~.surface_hb.face_inputs`.

    Raises
    ------
    ValueError
        ``hb`` has no condensed surface, or a face carries no prestress.
    """
    from ..surface_condensed import CondensedSurface

    x = hb.stuck_guess(omega)
    ic, isn = hb.basis.index(1)
    ratios = []
    for el in hb.model.elements:
        if not isinstance(el, CondensedSurface):
            continue
        U = (el.kinematics.operators(hb.basis, hb.residual.dofs)[0] @ x).reshape(hb.nb, el.m)
        F1 = el.stuck_stiffness() @ (U[ic] - 1j * U[isn])        # stuck: linear in U
        F0 = el.RtAR @ el.q_static - el.RtA @ el.w_static         # prestress resultant (Q2)
        if not F0[0] > 0.0:
            raise ValueError(f"the {el.name} face carries no prestress (normal resultant {F0[0]:.3g} N)")
        ratios.append(abs(F1[0]) / F0[0])
    if not ratios:
        raise ValueError("open_load needs a sector with condensed surfaces (CondensedSurfaceSectorHB)")
    return hb.cf * max(ratios)


def cf_path(make, omega: float, cf: float, start_cf: float, steps: int | None = None,
            max_iter: int | None = None, report=None) -> tuple:
    """The solution at ``cf`` [N] reached from the stuck start at ``start_cf`` [N].

    Parameters
    ----------
    make : callable
        ``make(c)``: the sector model (a :class:`~.hb.SectorHB`) at centrifugal load c [N].
    omega : float
        Frequency [rad/s], fixed along the path.
    cf, start_cf : float
        Target and start load [N]; ``start_cf <= cf``: Newton from the stuck start at cf.
    steps : int, optional
        Log-spaced load steps (default: the fewest of ratio at most STEP_RATIO); a step
        whose Newton fails is halved in log CF up to MAX_HALVINGS times.
    max_iter : int, optional
        Newton iterations per load (default MAX_ITER).
    report : callable, optional
        ``report(c, hb, x)`` after each load solved.

    Returns
    -------
    x : ndarray (size,)
        The solution of ``make(cf)`` at omega.
    loads : list of float
        Every load solved, in order [N].

    Raises
    ------
    SolverError
        Newton failed at the start, or at a step halved MAX_HALVINGS times; the message
        names the load and what to change.
    """
    start_cf = max(float(start_cf), float(cf))
    max_iter = MAX_ITER if max_iter is None else max_iter
    if steps is None:
        steps = max(1, math.ceil(math.log(start_cf / cf) / math.log(STEP_RATIO) - 1e-12))
    hb = make(start_cf)
    try:
        x = solve_point(hb, omega, hb.stuck_guess(omega), max_iter)
    except NewtonError as err:
        raise SolverError(_failed(start_cf, [start_cf], cf, omega, err)) from None
    loads = [start_cf]
    if report:
        report(start_cf, hb, x)
    if start_cf == cf:
        return x, loads
    for c in np.geomspace(start_cf, cf, steps + 1)[1:]:
        x = _step(make, omega, loads, x, float(c), 0, max_iter, report, cf, [0])
    return x, loads


def _step(make, omega, loads, x, c, depth, max_iter, report, cf, failed):
    """Newton at load c warm-started from the last load's x; halves the step on failure
    (``failed``: the failures of this step of the path so far, a one-item list)."""
    hb = make(c)
    try:
        x1 = solve_point(hb, omega, x, max_iter)
    except NewtonError as err:
        failed[0] += 1
        if depth >= MAX_HALVINGS or failed[0] >= MAX_STEP_FAILURES:
            raise SolverError(_failed(c, loads, cf, omega, err)) from None
        mid = math.sqrt(loads[-1] * c)
        x = _step(make, omega, loads, x, mid, depth + 1, max_iter, report, cf, failed)
        return _step(make, omega, loads, x, c, depth + 1, max_iter, report, cf, failed)
    loads.append(c)
    if report:
        report(c, hb, x1)
    return x1


def warm_path(make, omega: float, x, c_from: float, c_to: float, max_iter: int | None = None) -> np.ndarray:
    """The solution at ``c_to`` [N] from a solution ``x`` at ``c_from`` [N] whose direct warm
    start failed: the step halved in log CF (Newton at sqrt(c_from c_to), then at c_to, each
    halved again where it fails, MAX_HALVINGS in all, at most MAX_STEP_FAILURES failures
    counting the direct start's). ``make`` and ``omega`` as :func:`cf_path`'s; the unknowns
    of ``make(c_from)`` and ``make(c_to)`` must be the same.

    Raises
    ------
    SolverError
        A step still failed after MAX_HALVINGS halvings or MAX_STEP_FAILURES failures.
    """
    max_iter = MAX_ITER if max_iter is None else max_iter
    loads, failed = [float(c_from)], [1]
    x = _step(make, omega, loads, x, math.sqrt(c_from * c_to), 1, max_iter, None, c_to, failed)
    return _step(make, omega, loads, x, float(c_to), 1, max_iter, None, c_to, failed)


def _failed(c: float, loads, cf: float, omega: float, err) -> str:
    start = loads[0]
    where = "its stuck start" if c == start else f"{c:.4g} N (the last load solved: {loads[-1]:.4g} N)"
    return (f"the path in CF from {start:.4g} N to {cf:.4g} N at {omega / 2 / np.pi:.6g} Hz failed at "
            f"{where} ({err}): start the band at another frequency, or raise the CF")


def first_point(make, omega: float, cf: float, report=None) -> tuple:
    """The first solution of a curve at ``cf`` [N] and ``omega`` [rad/s]: by the path from
    CF_open (:func:`open_load`, computed on ``make(cf)``) where cf is below it, else by
    Newton from the stuck start at cf.

    A failed Newton at a low CF costs hundreds of evaluations before the path could
    begin (module docstring), so the load decides, not a first attempt.

    Returns
    -------
    x : ndarray (size,)
    record : dict
        ``start_cf`` [N] (CF_open or cf), ``open_load`` [N], ``loads`` (every load solved).

    Raises
    ------
    SolverError (:func:`cf_path`).
    """
    hb = make(cf)
    c_open = open_load(hb, omega)
    x, loads = cf_path(make, omega, cf, c_open, report=report)
    return x, {"start_cf": loads[0], "open_load": c_open, "loads": loads}
