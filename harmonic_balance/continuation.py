"""Predictor-corrector pseudo-arclength continuation of R(x, lam) = 0.

Knows nothing about mechanics: ``fun(x, lam) -> (R (N,), dR/dx (N, N), dR/dlam (N,))``.

Scaling: the arclength is measured in scaled variables ``x / s_x`` and
``lam / s_lam``, with ``s_lam`` the length of the parameter range and ``s_x`` the RMS
of x at the current point, floored at :data:`S_X_FLOOR` of the largest met so far
(a steep flank is climbed and descended in relative steps, so a resonance peak is
resolved by more points and the step never lets lam run away: with a fixed scale a
50-DOF case wandered to negative frequency, performance.md; with the largest RMS met
as the scale the two flanks of a peak 1e4 high came within 1e-3 of each other in
scaled units and the corrector jumped between them).

Orientation: the branch keeps the sign of det([R_x R_lam; t^T]) (Allgower & Georg,
sec. 2.1), so a corrected point where it flips (the step jumped over a peak or a fold
narrower than itself) is rejected, above :data:`FLIP_STEP`.

Step (Allgower & Georg, Numerical Continuation Methods, ch. 6): tangent t from
``[R_x R_lam; t_prev^T] t = [0; 1]``; predictor ``y + ds t``; corrector Newton on R = 0
and ``t . (y - y_pred) = 0`` (the pseudo-arclength plane), which passes turning points.
Step control: the step grows or shrinks with the corrector's iteration count
(target :data:`TARGET_ITER`), is halved on failure or when the tangent turns by more
than :data:`MAX_TURN` (so a sharp peak is not jumped over).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .newton import NewtonError, newton

#: Floor of the x scale relative to the largest RMS met on the branch (the scale
#: is the current point's RMS above it).
S_X_FLOOR = 1e-4
#: Corrector iterations the step control aims at.
TARGET_ITER = 4
#: Largest angle between successive tangents in scaled variables [rad].
MAX_TURN = 0.35
#: Scaled step below which a large tangent turn is accepted as a kink of the branch.
KINK_STEP = 2e-4
#: Scaled step below which a reversed orientation (det([J; t]) changing sign) is
#: accepted as a kink turning the branch by more than 90 deg; above it, the corrector
#: jumped to the other flank of a peak: measured on the Jenkins FRF with c = 1e-4
#: (resonance 3e-5 of the range wide), which without this test circled the peak
#: (left flank up, jump to the right flank, up it backwards, over the top, down the
#: left flank ...) until the point limit.
FLIP_STEP = 1e-5
#: Smallest scaled step at which a failed pseudo-arclength corrector is retried at
#: fixed parameter (below it the fallback only creeps: measured at 1e6 k, 1e-8 rad/s
#: per point, so the caller's restart is the better way past).
FIXED_MIN_STEP = 1e-4
#: Newton options of the correctors: no Levenberg-Marquardt fallback and a short line
#: search (a failing corrector is retried with half the step, which is cheaper).
#: Measured on the Jenkins FRF at 1e6 k, H = 15, 0.5 -> 0.8 rad/s: 16807 residual
#: evaluations for 577 points with the full globalisation (66 % in failed correctors),
#: 9894 for 579 points with these options.
CORRECTOR_NEWTON = {"lm": False, "min_alpha": 0.1}
FIXED_NEWTON = {}
#: Corrector iteration limit inside the continuation (a step is retried smaller).
CORRECTOR_ITER = 12


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
        by-product of the tangent (:meth:`_Scaled.tangent`): it changes where a real Floquet
        multiplier crosses +1 (folds, branch points), so Hill's stability is only needed
        where it changes (:func:`stability.along_branch`)
    status : str               'complete', or why it stopped
    """

    x: list = field(default_factory=list)
    lam: list = field(default_factory=list)
    iterations: list = field(default_factory=list)
    det_sign: list = field(default_factory=list)
    status: str = "running"

    def append(self, x, lam, it, det_sign=0.0):
        self.x.append(np.array(x))
        self.lam.append(float(lam))
        self.iterations.append(int(it))
        self.det_sign.append(float(det_sign))


class _Scaled:
    """The scaled augmented problem around fixed scales (s_x, s_lam)."""

    def __init__(self, fun, s_x, s_lam, tol):
        self.fun, self.s_x, self.s_lam, self.tol = fun, s_x, s_lam, tol

    def jac(self, y):
        R, Jx, Jl = self.fun(y[:-1] * self.s_x, y[-1] * self.s_lam)
        return R, np.column_stack([Jx * self.s_x, Jl * self.s_lam])

    def tangent(self, J, t_prev):
        """Unit tangent t (N+1,) with t . t_prev > 0, the sign of det([J; t^T]) and the
        sign of det(J_x) (J without its last column).

        The first sign is the branch's orientation (Allgower & Georg, sec. 2.1): it stays
        the same along a regular branch, through turning points and peaks, whatever the
        scaling (positive column scales change det([J; t]) by a positive factor). The
        second is free: by Cramer's rule the last component of the solution of
        [J; t_prev] t = e_(N+1) is det(J_x) / det([J; t_prev]).
        """
        from scipy.linalg import lu_factor, lu_solve  # after the first point: start-up

        A = np.vstack([J, t_prev])
        rhs = np.zeros(A.shape[0])
        rhs[-1] = 1.0
        lu, piv = lu_factor(A, check_finite=False)
        t = lu_solve((lu, piv), rhs, check_finite=False)
        if not np.all(np.isfinite(t)):
            raise np.linalg.LinAlgError("non-finite tangent")
        n = np.linalg.norm(t)
        # det is linear in the last row, det([J; w]) = w . c with c parallel to t (the
        # cofactors), so det([J; t]) has the sign of det([J; t_prev]) (t . t_prev > 0),
        # which the LU gives.
        perm = np.count_nonzero(piv != np.arange(len(piv))) % 2
        sign = (-1.0) ** perm * np.prod(np.sign(np.diag(lu)))
        return t / n, float(sign), float(np.sign(t[-1]) * sign)

    def correct(self, y_pred, normal, max_iter=CORRECTOR_ITER):
        """Newton on R = 0 and normal . (y - y_pred) = 0 from y_pred.

        The unknown is the offset d = y - y_pred, so the plane equation carries no
        round-off of |y| (which would otherwise floor |R| near tol when y is large
        in scaled units, e.g. during peak refinement).
        """
        def aug(d):
            R, J = self.jac(y_pred + d)
            return np.append(R, normal @ d), np.vstack([J, normal])
        res = newton(aug, np.zeros_like(y_pred), self.tol, max_iter, np.linalg.norm(y_pred),
                     **CORRECTOR_NEWTON)
        res.x = y_pred + res.x
        return res

    def correct_fixed(self, y_pred, max_iter=CORRECTOR_ITER):
        """Newton on R = 0 at the predicted parameter (natural-parameter corrector), or None.

        Fallback of :meth:`correct`: where the branch crosses a kink of the piecewise-
        smooth residual (a stiff slider's slip onset moving to the next AFT sample),
        Newton on the pseudo-arclength system can cycle between the two linear pieces
        (measured on the Jenkins FRF at 1e4 k near 0.545 rad/s: |R| stuck at 1e-7-1e-3
        for every step size down to 1e-6) while Newton at fixed parameter from the
        same predictor converges in 2 iterations. The augmented Jacobian returned
        carries the plane row ``e_lam`` (only J[:-1] is used by the caller).
        """
        lam = y_pred[-1]

        def fixed(d):
            R, J = self.jac(np.append(y_pred[:-1] + d, lam))
            return R, J[:, :-1]
        try:
            res = newton(fixed, np.zeros(len(y_pred) - 1), self.tol, max_iter,
                         np.linalg.norm(y_pred[:-1]), **FIXED_NEWTON)
        except NewtonError:
            return None
        R, J = self.jac(np.append(y_pred[:-1] + res.x, lam))
        e = np.zeros(len(y_pred))
        e[-1] = 1.0
        res.x = np.append(y_pred[:-1] + res.x, lam)
        res.J = np.vstack([J, e])
        return res


def continuation(fun, x0, lam0: float, lam_end: float, tol: float, ds: float = 0.01,
                 ds_min: float = 1e-6, ds_max: float = 0.02, max_points: int = 2000,
                 x_scale: float = 0.0, max_turn: float = MAX_TURN, on_point=None) -> Branch:
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
    max_turn : float, tangent turn limit [rad] (np.pi disables it: a homotopy only
        needs to arrive, not to resolve the path)
    on_point : callable (lam) -> None, optional
        Called after every accepted point (progress display); None: no call.

    Returns
    -------
    Branch (status 'complete'); the last point is exactly at lam_end.

    Raises
    ------
    ContinuationError (a RuntimeError) with the parameter reached and ``.branch``.
    """
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
    while len(branch.lam) < max_points:
        sc = _Scaled(fun, s_x, s_lam, tol)
        y = np.append(branch.x[-1] / s_x, branch.lam[-1] / s_lam)
        col = np.append(np.full(len(x0), s_x), s_lam)
        J = J_phys * col  # reuse the corrector's last Jacobian: no extra evaluation
        try:
            t, d, branch.det_sign[-1] = sc.tangent(J, t_prev)
        except (np.linalg.LinAlgError, ValueError):
            raise _stop("singular extended Jacobian (bifurcation?)", branch) from None
        if not orient:
            orient = d  # t points towards lam_end here
        elif d != orient:
            t = -t  # a kink accepted at a tiny step turned the branch by more than 90 deg
        y_new, it, ds, J_new = _step(sc, y, t, ds, ds_min, branch, max_turn, sign, orient)
        J_phys = J_new / col
        lam_new = y_new[-1] * s_lam
        if sign * (lam_new - lam_end) >= 0:  # passed the end: land exactly on it
            x_end = _interpolate(branch, y_new[:-1] * s_x, lam_new, lam_end)
            try:
                res = _solve_fixed(fun, x_end, lam_end, tol, branch)
            except ContinuationError:
                # From the last accepted point instead: measured on the Jenkins start at
                # 100 k, f_s = P, c = 1e-4, H = 51, 2 rad/s (grazing slip), the
                # interpolated guess stalled at |R| = 3e-4 while Newton from the last
                # point (lam = -0.005) converged in 24 iterations.
                res = _solve_fixed(fun, branch.x[-1], lam_end, tol, branch)
            branch.append(res.x, lam_end, res.iterations, np.linalg.slogdet(res.J)[0])
            if on_point is not None:
                on_point(lam_end)
            branch.status = "complete"
            return branch
        if sign * (lam_new - lam0) < 0:
            branch.append(y_new[:-1] * s_x, lam_new, it)
            raise _stop("the branch turned back out of the parameter range", branch)
        branch.append(y_new[:-1] * s_x, lam_new, it)
        if on_point is not None:
            on_point(lam_new)
        s_now = _rms(branch.x[-1])
        s_max = max(s_max, s_now)
        s_x = max(s_now, S_X_FLOOR * s_max, x_scale, 1e-300)
        # Tangent expressed in the (possibly updated) scaling, for the next orientation.
        t_prev = t * np.append(np.full(len(x0), sc.s_x / s_x), 1.0)
        t_prev /= np.linalg.norm(t_prev)
        ds = min(ds_max, ds * np.clip(TARGET_ITER / max(it, 1), 0.5, 2.0))
    raise _stop(f"point limit {max_points} reached", branch)


def _step(sc, y, t, ds, ds_min, branch, max_turn=MAX_TURN, sign=0.0, orient=0.0):
    """One accepted predictor-corrector step; shrinks ds until it succeeds.

    A corrected point is rejected (step halved) when the tangent there turned by more
    than max_turn (above KINK_STEP) or when it has the opposite orientation
    (:meth:`_Scaled.tangent`, above FLIP_STEP): the corrector then landed on the
    other flank of a peak narrower than the step, or on another branch.
    """
    while True:
        try:
            res = sc.correct(y + ds * t, t)
            reason = _rejected(sc, res, t, ds, max_turn, orient)
            if reason is None:
                return res.x, res.iterations, ds, res.J[:-1]
        except NewtonError as err:
            reason = err.reason
            # natural-parameter step of the same scaled length from the last point,
            # towards the end of the range
            step = np.zeros(len(t))
            step[-1] = sign or np.sign(t[-1])
            res = sc.correct_fixed(y + ds * step) if ds >= FIXED_MIN_STEP else None
            if res is not None and _rejected(sc, res, t, ds, max_turn, orient) is None:
                return res.x, res.iterations, ds, res.J[:-1]
        ds *= 0.5
        if ds < ds_min:
            raise _stop(f"step below minimum ({reason})", branch)


def _rejected(sc, res, t, ds, max_turn, orient):
    """Why the corrected point ``res`` is not accepted after a step ds along t, or None.

    A kink of the branch (stick-slip onset: the describing function is only C0 in the
    Jacobian) keeps its turn at any step, so the turn limit only applies to steps
    above KINK_STEP and the orientation test to steps above FLIP_STEP.
    """
    if max_turn >= np.pi and not orient:
        return None
    try:
        t_new, d_new, _ = sc.tangent(res.J[:-1], t)
    except (np.linalg.LinAlgError, ValueError):
        return "singular extended Jacobian at the corrected point"
    if ds > KINK_STEP and max_turn < np.pi and abs(t_new @ t) < np.cos(max_turn):
        return "tangent turned too much"
    if ds > FLIP_STEP and orient and d_new != orient:
        return "orientation of the branch reversed (a peak or fold jumped over)"
    return None


def _solve_fixed(fun, x, lam, tol, branch):
    try:
        return newton(lambda z: fun(z, lam)[:2], x, tol)
    except NewtonError as err:
        raise _stop(f"no solution at fixed parameter {lam:.6g}: {err}", branch) from None


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

    The branch between points i-1 and i+1 is parameterised by tau in [0, 2]: a
    point on the chord of segment k = floor(tau), corrected onto the branch in the
    plane normal to that chord (so it works through turning points). Brent's
    bounded search maximises the amplitude in tau until the bracket is below the
    tau equivalent of ``tol_lam`` (parameter tolerance); the amplitude error is then
    second order, ~ A'' tol_lam^2 / 2.

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
    x : (N,) array, lam : float, amp : float, evaluations : int
    """
    from scipy.optimize import minimize_scalar

    if not 0 < i < len(branch.lam) - 1:
        raise ValueError("refinement needs a point with neighbours on both sides")
    pts = [np.append(branch.x[j], branch.lam[j]) for j in (i - 1, i, i + 1)]
    scale = np.append(np.full(len(branch.x[i]), max(_rms(branch.x[i]), 1e-300)),
                      max(abs(branch.lam[i + 1] - branch.lam[i - 1]), 1e-300))
    pts = [p / scale for p in pts]
    cache = {}

    def point(tau):
        k = min(int(tau), 1)
        a, b = pts[k], pts[k + 1]
        chord = (b - a) / np.linalg.norm(b - a)
        y_pred = a + (tau - k) * (b - a)
        sc = _Scaled(fun, scale[:-1], scale[-1], tol)
        res = sc.correct(y_pred, chord, max_iter=30)
        y = res.x * scale
        cache[tau] = y
        return -amplitude(y[:-1], y[-1])

    dlam = max(abs(branch.lam[i] - branch.lam[i - 1]), abs(branch.lam[i + 1] - branch.lam[i]))
    xatol = max(tol_lam / max(dlam, 1e-300), 1e-12)
    opt = minimize_scalar(point, bounds=(0.0, 2.0), method="bounded",
                          options={"xatol": xatol, "maxiter": 200})
    y = cache.get(opt.x)
    if y is None:
        point(opt.x)
        y = cache[opt.x]
    return y[:-1], float(y[-1]), float(-opt.fun), int(opt.nfev)
