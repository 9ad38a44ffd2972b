"""Predictor-corrector pseudo-arclength continuation of R(x, lam) = 0.

Knows nothing about mechanics: ``fun(x, lam) -> (R (N,), dR/dx (N, N), dR/dlam (N,))``.

Scaling: the arclength is measured in scaled variables ``x / s_x`` and
``lam / s_lam``, with ``s_lam`` the length of the parameter range and ``s_x`` the
largest RMS of x met so far on the branch (at least ``x_scale``): the curve's accuracy
and its steps are relative to the size of the response, so a stretch of small amplitude
next to a resonance (an antiresonance, the tail of a flank) is crossed in a few steps.
(With the current point's RMS as the scale, every decade of amplitude and every phase
turn of a small response would cost as much as the resonance itself: 2-4 times the points
on the friction chains of :mod:`harmonic_balance.bench_models`.) The two flanks of a sharp peak
then lie close together in scaled units near their feet; the orientation (below) and
the step control keep the corrector on its own flank.

Orientation: the branch keeps the sign of det([R_x R_lam; t^T]) (Allgower & Georg,
sec. 2.1), whatever the scaling, through turning points and peaks; so the forward
tangent at a new point is the one of the branch's orientation, not the one closest to
the last tangent (which goes backwards after a turn of more than 90 deg in scaled
variables: a kink, or a peak narrower than the step).

Step (Allgower & Georg, Numerical Continuation Methods, ch. 6): tangent t from
``[R_x R_lam; t_prev^T] t = [0; 1]``; predictor ``y + ds t``; corrector Newton on R = 0
and ``t . (y - y_pred) = 0`` (the pseudo-arclength plane), which passes turning points;
where it fails, Newton at the predictor's parameter (:meth:`.corrector.ScaledSystem.correct_fixed`).
The corrector's matrix is ``[R_x R_lam; t^T]``, the tangent system at the corrected
point but for R's Jacobian, which its last Newton step took one (converged) step
earlier: the new tangent is solved with those LU factors, and the corrector asks for no
Jacobian at its converged point, so a point costs its Newton iterations and nothing
more. On a curve (with a tolerance) Newton starts in the plane at the quadratic through
the previous point (:func:`_bend`), closer to the branch than the predictor; the point
it converges to is the same.

Step size by the curve's shape (Allgower & Georg sec. 6.1, steplength adaptation by
the asymptotic error model): after a corrector the step is judged by the distance
delta from predictor to corrected point (delta ~ kappa ds^2 / 2 on a branch of
curvature kappa; the chord between two points then deviates from the branch by
~delta / 4) and the angle alpha between the tangents:
``f = max(sqrt(delta / (4 tolerance)), alpha / TURN)``; the step is rejected and
retried at ds / f when f > REJECT, else the next one is ds / f (at most GROW times
longer, at most ds_max, and at most ``lam_step`` of the range in lam). So a straight
stretch is crossed in long steps and a curved one (a peak, a fold) in short ones, to
``tolerance`` in scaled variables (the relative accuracy of the polyline). A kink of the
branch (a friction link starting or stopping to slip: the residual is only piecewise
smooth) turns the tangent by the same angle at any step; when a shorter retry leaves
alpha above CORNER_SHARE of the last one, the angle is not held against the step (only
delta, which falls like ds past a corner, is), so a kink is crossed in a few points
instead of shrinking the step to nothing. A step at which no corrector converged bounds
the next ones (FAIL_SHARE, GROW_AFTER_FAIL), so that the shape does not grow them back
into the same failure. Without a tolerance (homotopies, which only need to arrive) the
corrector's iterations size the steps (target TARGET_ITER).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .brent import brent_min
from .corrector import ScaledSystem
from .newton import NewtonError, newton

#: Largest step in lam of a forced-response curve (frf, bladed_disk.solve), as a fraction
#: of the range: a resonance of 0.6 % on a nearly flat curve (3-mass chain, knl 2000, force
#: 0.5, ~7 % of the range wide) was stepped over by the shape control alone; at least
#: ~1 / LAM_STEP points per curve.
LAM_STEP = 0.03
#: Corrector iterations the step control aims at.
TARGET_ITER = 4
#: Default curve accuracy: the polyline of the points deviates from the branch by
#: about this much in scaled variables (x relative to the largest RMS met, lam to the
#: range).
CURVE_TOL = 1e-2
#: Nominal angle between successive tangents in scaled variables [rad].
TURN = 0.5
#: A step whose shape factor f (module docstring) exceeds this is retried at ds / f.
REJECT = 2.0
#: Largest growth of the step from one point to the next.
GROW = 2.0
#: After a step in which no corrector converged at ds_fail, the next steps of a curve (a
#: run with a tolerance; not a homotopy, whose steps the iterations size) are at most
#: FAIL_SHARE ds_fail, a bound that grows by GROW_AFTER_FAIL per step without such a
#: failure: the shape alone would double the step again into the failure (measured on
#: chain5 at H = 31: 30 steps of 0.5 failed and were retried at 0.25, each with f ~ 0.25).
#: Measured there (points, evaluations, LU factorisations): no bound 412, 8248, 4098;
#: 0.7 and 1.25: 448, 5995, 3303; 0.5 and 1.1: 547, 4820, 2945, but UPD-24's curve at
#: H = 21 then took other points and its peak moved to another maximum of the sampled
#: contact's ripple (4e-6 lower, 0.8 rad/s away), which 0.7 and 1.25 leave as it was.
FAIL_SHARE = 0.7
GROW_AFTER_FAIL = 1.25
#: A retry whose tangent angle stays above this share of the longer attempt's angle
#: found a kink (a smooth branch halves the angle with the step).
CORNER_SHARE = 0.6
#: Scaled step below which a step is judged by delta alone: neither the tangent's turn nor
#: a step back in lam without a change of det(R_x) rejects it. A non-smooth branch can
#: turn back at a corner without det changing sign (measured: the Jenkins oscillator at
#: 1e4 k, f_s = P, c = 1e-4, H = 51 near 1.9609 rad/s, where the slip episodes grazing
#: the turning points come and go: a turn of 143 deg, crossed only in steps this small).
KINK_STEP = 2e-4
#: Points accepted in a row below KINK_STEP after which the continuation stops as stalled
#: (the caller restarts past the kink): a sampled AFT's staircase of kinks (64 samples,
#: grazing slip) took 2000 such points without getting past 1.471 rad/s; the grazing
#: corner above needs fewer than 10.
CREEP_POINTS = 30
#: Smallest scaled step at which a failed pseudo-arclength corrector is retried at
#: fixed parameter (below it the fallback only creeps: measured at 1e6 k, 1e-8 rad/s
#: per point, so the caller's restart is the better way past).
FIXED_MIN_STEP = 1e-4
#: Newton options of the peak refinement's fixed-parameter corrector (:func:`refine_max`):
#: the full globalisation, since a point it cannot reach counts as no maximum.
REFINE_NEWTON = {}


class ContinuationError(RuntimeError):
    """Continuation stopped early; ``branch`` holds the points computed so far."""

    def __init__(self, message: str, branch: Branch):
        super().__init__(message)
        self.branch = branch


@dataclass
class Branch:
    """Solution points of a continuation run.

    Attributes
    ----------
    x : list of (N,) arrays
    lam : list of float
    iterations : list of int   corrector iterations per point
    det_sign : list of float   sign of det(dR/dx) per point (+1, -1; 0: not known), free
        by-product of the tangent (:meth:`.corrector.ScaledSystem.tangent`): it changes where a real Floquet
        multiplier crosses +1 (folds, branch points), so Hill's stability is only needed
        where it changes (:func:`stability.along_branch`)
    tangent : list of (N + 1,) arrays or None   forward unit tangent (dx, dlam) per point
        in unscaled variables (None: not known), for interpolation between points
    status : str               'complete', or why it stopped
    """

    x: list = field(default_factory=list)
    lam: list = field(default_factory=list)
    iterations: list = field(default_factory=list)
    det_sign: list = field(default_factory=list)
    tangent: list = field(default_factory=list)
    status: str = "running"

    def append(self, x, lam, it, det_sign=0.0, tangent=None):
        self.x.append(np.array(x))
        self.lam.append(float(lam))
        self.iterations.append(int(it))
        self.det_sign.append(float(det_sign))
        self.tangent.append(tangent)


def continuation(fun, x0, lam0: float, lam_end: float, tol: float, ds: float = 0.01,
                 ds_min: float = 1e-6, ds_max: float = 0.5, max_points: int = 2000,
                 x_scale: float = 0.0, tolerance: float | None = CURVE_TOL,
                 on_point=None, rtol: float = 0.0, lam_step: float | None = None) -> Branch:
    """Trace the branch through (x0, lam0) until lam reaches lam_end.

    Parameters
    ----------
    fun : callable (x, lam) -> (R, dR/dx, dR/dlam)
    x0 : (N,) array, initial guess at lam0 (corrected first at fixed lam0)
    lam0, lam_end : float, parameter range (either order)
    tol : float, absolute tolerance on |R|_2
    ds, ds_min, ds_max : float, initial / smallest / largest step in scaled arclength
        (lam scaled by |lam_end - lam0|, so ds_max = 0.02 means >= 50 points on a flat branch)
    max_points : int
    x_scale : float, smallest scale of x (default 0: the RMS of the first point); a
        homotopy from a tiny level passes the final level's size so that the first
        steps are not 1 % of a tiny x
    tolerance : float or None, curve accuracy in scaled variables (module docstring);
        None: steps by the corrector's iterations alone (a homotopy only needs to
        arrive, not to resolve its path)
    on_point : callable (lam) -> None, optional
        Called after every accepted point (progress display); None: no call.
    lam_step : float or None, largest step in lam as a fraction of the range (None: no
        limit): a feature narrower than the steps the shape allows on a flat stretch
        (a bump of 0.6 % on a flat curve) is still sampled
    rtol : float, relative tolerance of the correctors: |R| <= max(tol, rtol |R_x x|)
        at the last point (the size of the terms that balance in R: a resonance's
        internal forces, a slipping response many times the stuck one that sized tol)

    Returns
    -------
    Branch (status 'complete'); the last point is exactly at lam_end.

    Raises
    ------
    ContinuationError (a RuntimeError) with the parameter reached and ``.branch``.
    """
    if tolerance is not None and not (np.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"curve tolerance must be a positive number, got {tolerance}")
    branch = Branch()
    first = _solve_fixed(fun, x0, lam0, tol, branch)
    branch.append(first.x, lam0, first.iterations)
    sign = 1.0 if lam_end >= lam0 else -1.0
    s_lam = abs(lam_end - lam0)
    if s_lam == 0:
        raise ValueError("empty parameter range")
    s_max = _rms(first.x)
    s_x = max(s_max, x_scale, 1e-300)
    t_prev = np.zeros(len(x0) + 1)
    t_prev[-1] = sign
    _, Jx, Jl = fun(first.x, lam0)
    J_phys = np.column_stack([Jx, Jl])  # unscaled Jacobian at the last accepted point
    orient = 0.0  # sign of det([J; t]): the branch's orientation (set at the first point)
    ctl = _Control(tolerance, lam_step)
    ds_cap = np.inf  # bound after a failed corrector (FAIL_SHARE, GROW_AFTER_FAIL)
    creep = 0  # points accepted in a row at steps below KINK_STEP
    known = None  # (unscaled unit tangent, sign of det(R_x)) at the last point, from _step
    while len(branch.lam) < max_points:
        tol_now = max(tol, rtol * float(np.linalg.norm(J_phys[:, :-1] @ branch.x[-1])))
        sc = ScaledSystem(fun, s_x, s_lam, tol_now)
        y = np.append(branch.x[-1] / s_x, branch.lam[-1] / s_lam)
        col = np.append(np.full(len(x0), s_x), s_lam)
        if known is None:
            J = J_phys * col  # reuse the corrector's last Jacobian: no extra evaluation
            try:
                t, d, branch.det_sign[-1] = sc.tangent(J, t_prev)
            except (np.linalg.LinAlgError, ValueError):
                raise _stop("singular extended Jacobian (bifurcation?)", branch) from None
            if not orient:
                orient = d  # t points towards lam_end here
            elif d != orient:
                t = -t  # forward is the branch's orientation (a turn of more than 90 deg)
        else:
            # the step judged its point by this tangent, already oriented: a positive
            # rescaling of the columns maps it (and both det signs) to the new scales
            # without a second factorisation of the same extended Jacobian
            t = known[0] / col
            t /= np.linalg.norm(t)
            branch.det_sign[-1] = known[1]
        branch.tangent[-1] = _unscaled(t, col)
        y_new, it, ds, J_new, f, known, ds_fail = _step(sc, y, t, min(ds, ds_max, ds_cap), ds_min,
                                                        branch, ctl, orient)
        known = (_unscaled(known[0], col), known[1])
        if ds_fail is not None and tolerance is not None:  # (homotopies: as measured)
            ds_cap = max(FAIL_SHARE * ds_fail, ds_min)
        else:
            ds_cap *= GROW_AFTER_FAIL
        creep = creep + 1 if ds < KINK_STEP else 0
        if creep > CREEP_POINTS:
            raise _stop(f"step below minimum (more than {CREEP_POINTS} points in steps below "
                        f"{KINK_STEP:g}: the corrector creeps along a kink)", branch)
        lam_new = y_new[-1] * s_lam
        if sign * (lam_new - lam_end) >= 0:  # passed the end: land exactly on it
            try:
                res = _land(fun, branch, y_new[:-1] * s_x, lam_new, lam_end, tol)
            except ContinuationError:
                if ds < 4.0 * ds_min:
                    raise
                # a long last step leaves both guesses too far from the end's solution
                # (measured: a residual that cannot be evaluated off the branch): a
                # shorter step from the last point, whose J_phys and tangent stand
                ds_cap, known = 0.5 * ds, None
                ds = ds_cap
                continue
            branch.append(res.x, lam_end, res.iterations, *_end_tangent(fun, res.x, lam_end, sign))
            if on_point is not None:
                on_point(lam_end)
            branch.status = "complete"
            return branch
        J_phys = J_new / col
        if sign * (lam_new - lam0) < 0:
            branch.append(y_new[:-1] * s_x, lam_new, it)
            raise _stop("the branch turned back out of the parameter range", branch)
        branch.append(y_new[:-1] * s_x, lam_new, it)
        if on_point is not None:
            on_point(lam_new)
        s_max = max(s_max, _rms(branch.x[-1]))
        s_x = max(s_max, x_scale, 1e-300)
        # Tangent expressed in the (possibly updated) scaling, for the next orientation.
        t_prev = t * np.append(np.full(len(x0), sc.s_x / s_x), 1.0)
        t_prev /= np.linalg.norm(t_prev)
        ds = min(ds_max, ds / max(f, 1.0 / GROW))
    raise _stop(f"point limit {max_points} reached", branch)


class _Control:
    """The shape factor f of a corrected step (module docstring): > REJECT rejects it,
    else the next step is ds / f; and the largest scaled step in lam."""

    def __init__(self, tolerance, lam_step):
        self.delta_ok = None if tolerance is None else 4.0 * tolerance
        self.lam_step = np.inf if lam_step is None else float(lam_step)

    def factor(self, delta, alpha, it, corner=False):
        """(shape factor: rejects above REJECT, factor for the next step). Without a
        tolerance the corrector's iterations size the next step (target TARGET_ITER, at
        most halving it); with one, the shape alone does (delta and alpha already grow
        where Newton struggles, and the iterations count the tolerance's digits too)."""
        if self.delta_ok is None:
            return 0.0, min(it / TARGET_ITER, 2.0)
        shape = max(np.sqrt(delta / self.delta_ok), 0.0 if corner else alpha / TURN)
        return shape, shape


def _step(sc, y, t, ds, ds_min, branch, ctl, orient):
    """One accepted predictor-corrector step: (y_new, iterations, ds, J, shape factor,
    (forward unit tangent at y_new, sign of det(R_x) there), the last step at which no
    corrector converged or None).

    Corrector: the pseudo-arclength plane, else Newton at the predictor's parameter
    (where the plane misses the branch: past a kink that turns it by more than 90 deg
    in scaled variables, or Newton's direction fails at the kink). The forward tangent
    at the corrected point is the branch's orientation's; the step is retried shorter
    while its shape factor exceeds REJECT, and halved when no corrector converges.
    """
    alpha_prev, reason, ds_fail = None, "", None
    if abs(t[-1]) * ds > ctl.lam_step:
        ds = ctl.lam_step / abs(t[-1])
    # not without a tolerance: there the corrector's iterations size the steps, and a
    # better start would lengthen them past what the homotopies were measured with
    bend = None if ctl.delta_ok is None else _bend(sc, y, t, branch)
    while True:
        y_pred = y + ds * t
        res = None
        try:
            res = sc.correct(y_pred, t, start=None if bend is None else ds**2 * bend)
        except NewtonError as err:
            reason = err.reason
            if ds >= FIXED_MIN_STEP:
                res = sc.correct_fixed(y_pred)
        f = None
        if res is None:
            ds_fail = ds
        else:
            try:
                t_new, d_new, det_x = sc.tangent(res.J[:-1], t, res.lu)
            except (np.linalg.LinAlgError, ValueError):
                t_new, reason = None, "singular extended Jacobian at the corrected point"
            if t_new is not None:
                if orient and d_new != orient:
                    t_new = -t_new
                alpha = float(np.arccos(np.clip(t_new @ t, -1.0, 1.0)))
                delta = float(np.linalg.norm(res.x - y_pred))
                corner = ds < KINK_STEP or (alpha_prev is not None
                                            and alpha > CORNER_SHARE * alpha_prev)
                f, f_next = ctl.factor(delta, alpha, res.iterations, corner)
                if ds >= KINK_STEP and _backwards(res.x[-1] - y[-1], t[-1], t_new[-1]):
                    f, reason = max(f, 2.0 * REJECT), "the corrector went back in the parameter"
                if f <= REJECT:
                    return res.x, res.iterations, ds, res.J[:-1], f_next, (t_new, det_x), ds_fail
                alpha_prev = alpha
                if not reason.startswith("the corrector went back"):
                    reason = "the branch bends more than the tolerance allows"
        ds *= 0.5 if f is None else max(1.0 / f, 0.25)
        if ds < ds_min:
            raise _stop(f"step below minimum ({reason})", branch)


def _bend(sc, y, t, branch):
    """Curvature term c (N + 1,) normal to t of the quadratic through the previous point
    with tangent t at y (scaled variables), or None at a branch's first point.

    The point y + ds t + ds^2 c lies in the corrector's plane (normal t through the
    predictor y + ds t) and is second-order closer to the branch there: Newton starts
    from it and converges to the same point in fewer iterations (the residual of a
    friction branch at the predictor is far outside Newton's quadratic region:
    measured on chain5 at H = 31, |R| ~ 0.3 and five damped iterations before it).
    """
    if len(branch.lam) < 2:
        return None
    prev = np.append(branch.x[-2] / sc.s_x, branch.lam[-2] / sc.s_lam)
    h = -float(np.linalg.norm(y - prev))
    if h == 0.0:
        return None
    c = (prev - y - h * t) / h**2
    return c - (c @ t) * t


def _unscaled(t, col):
    """Unit tangent in unscaled variables from one in scaled ones (column scales col)."""
    u = t * col
    return u / np.linalg.norm(u)


def _end_tangent(fun, x, lam, sign):
    """(sign of det(R_x), unit tangent (dx, dlam) pointing along ``sign`` in lam) at the
    last point of a branch, from one more evaluation there (None where R_x is singular)."""
    _, Jx, Jl = fun(x, lam)
    det = float(np.linalg.slogdet(Jx)[0])
    try:
        dx = -np.linalg.solve(Jx, Jl)
    except np.linalg.LinAlgError:
        return det, None
    u = sign * np.append(dx, 1.0)
    return det, u / np.linalg.norm(u) if np.all(np.isfinite(u)) else None


def _backwards(dlam, t_lam, t_new_lam) -> bool:
    """True when a step moved lam against the branch's direction at both its ends: no
    fold lies between them (t's lam component has one sign), so the corrector landed on
    an earlier part of the branch (the other flank of a sharp resonance, whose feet lie
    close together in scaled variables: measured on x'' + 1e-4 x' + x = cos(lam t), which
    circled its peak without this test)."""
    return bool(dlam * t_lam < 0.0 and dlam * t_new_lam < 0.0)


def _solve_fixed(fun, x, lam, tol, branch):
    value = getattr(fun, "value", None)
    try:
        return newton(lambda z: fun(z, lam)[:2], x, tol,
                      value=None if value is None else (lambda z: value(z, lam)))
    except NewtonError as err:
        raise _stop(f"no solution at fixed parameter {lam:.6g}: {err}", branch) from None


def _land(fun, branch, x_new, lam_new, lam_end, tol):
    """Solution at lam_end from a point x_new past it: Newton from the interpolated
    guess, else from the last accepted point (measured on the Jenkins start at 100 k,
    f_s = P, c = 1e-4, H = 51, 2 rad/s (grazing slip): the interpolated guess stalled
    at |R| = 3e-4 while Newton from the last point converged in 24 iterations)."""
    try:
        return _solve_fixed(fun, _interpolate(branch, x_new, lam_new, lam_end), lam_end, tol, branch)
    except ContinuationError:
        return _solve_fixed(fun, branch.x[-1], lam_end, tol, branch)


def _interpolate(branch, x_new, lam_new, lam_end):
    lam_old = branch.lam[-1]
    f = (lam_end - lam_old) / (lam_new - lam_old)
    return branch.x[-1] + f * (x_new - branch.x[-1])


def _stop(message, branch):
    lam = branch.lam[-1] if branch.lam else float("nan")
    branch.status = message
    return ContinuationError(f"continuation stopped at parameter {lam:.6g} after "
                             f"{len(branch.lam)} points: {message}", branch)


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def refine_max(fun, branch: Branch, i: int, amplitude, tol: float, tol_lam: float):
    """Locate the local maximum of ``amplitude(x, lam)`` on the branch near point i.

    The branch between points i-1 and i+1 is parameterised by tau in [-1, 1] (0 at
    point i): a point on the chord of the segment tau lies on, corrected onto the
    branch in the plane normal to that chord (so it works through turning points), or,
    where that corrector fails (a kink of a friction branch), at the chord point's
    parameter (:meth:`.corrector.ScaledSystem.correct_fixed`); a point neither corrector reaches counts
    as no maximum. Brent's search (:func:`brent_min`) maximises the amplitude in tau
    until the bracket is below the tau equivalent of ``tol_lam`` (parameter
    tolerance); the amplitude error is then second order, ~ A'' tol_lam^2 / 2.

    Parameters
    ----------
    fun : callable (x, lam) -> (R, dR/dx, dR/dlam)
    branch : Branch
    i : int, index of a point whose amplitude is not below its neighbours'
    amplitude : callable (x, lam) -> float
    tol : float, corrector tolerance on |R|_2
    tol_lam : float, tolerance on the peak's parameter

    Returns
    -------
    x : (N,) array, lam : float, amp : float, evaluations : int (of the amplitude);
    point i itself when no corrected point is higher.
    """
    if not 0 < i < len(branch.lam) - 1:
        raise ValueError("refinement needs a point with neighbours on both sides")
    pts = [np.append(branch.x[j], branch.lam[j]) for j in (i - 1, i, i + 1)]
    scale = np.append(np.full(len(branch.x[i]), max(_rms(branch.x[i]), 1e-300)),
                      max(abs(branch.lam[i + 1] - branch.lam[i - 1]), 1e-300))
    pts = [p / scale for p in pts]
    sc = ScaledSystem(fun, scale[:-1], scale[-1], tol)
    cache = {0.0: pts[1] * scale}

    def point(tau):
        if tau == 0.0:
            return -amplitude(branch.x[i], branch.lam[i])
        a, b = (pts[0], pts[1]) if tau < 0 else (pts[1], pts[2])
        chord = (b - a) / np.linalg.norm(b - a)
        y_pred = a + (tau + 1.0 if tau < 0 else tau) * (b - a)
        try:
            res = sc.correct(y_pred, chord, max_iter=30)
        except NewtonError:
            res = sc.correct_fixed(y_pred, max_iter=30, options=REFINE_NEWTON)
            if res is None:
                return np.inf
        y = res.x * scale
        cache[tau] = y
        return -amplitude(y[:-1], y[-1])

    dlam = max(abs(branch.lam[i] - branch.lam[i - 1]), abs(branch.lam[i + 1] - branch.lam[i]))
    xtol = max(tol_lam / max(dlam, 1e-300), 1e-12)
    tau, f, n = brent_min(point, -1.0, 1.0, xtol, start=0.0)
    y = cache[tau]
    return y[:-1], float(y[-1]), float(-f), n
