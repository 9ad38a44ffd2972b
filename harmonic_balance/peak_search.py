"""Peak searches on a branch of fixed-frequency solutions: the refined maximum of an
amplitude near given points (a window of padded curve points, or the previous harmonic
level's peak), used by the truncation checks of :mod:`harmonic_balance.accuracy`.

Symbols: omega [rad/s] the frequency, x the harmonic balance unknowns at it, a(x, omega)
the amplitude whose maximum is sought, tol_lam the tolerance on the peak frequency.
"""
from __future__ import annotations

import math

import numpy as np

from .continuation import Branch, refine_max
from .newton import NewtonError, lu_factor, lu_solve, newton

#: Curve points on each side of the peak padded and corrected at H' (more are added when
#: the peak at H' lies at the end of that window).
WINDOW = 3
#: Largest number of window extensions when the H' peak sits at the window's end.
MAX_EXTEND = 6


def peak_at(fun, amplitude, xs, omegas, i, tol, tol_lam):
    """Refined peak of ``amplitude`` on the branch of ``fun`` near the given points:
    (x, omega, amplitude, solves) of :func:`peak_window`."""
    return peak_window(fun, amplitude, xs, omegas, i, tol, tol_lam)[:4]


def peak_window(fun, amplitude, xs, omegas, i, tol, tol_lam, window: int = WINDOW, amp_rel: float = 0.0):
    """Refined peak of ``amplitude`` on the branch of ``fun`` near the given points, and the
    corrected points of the window searched.

    Parameters
    ----------
    fun : callable (x, omega) -> (R, dR/dx, dR/domega) at the richer set
    amplitude : callable (x, omega) -> float
    xs : list of (N,) arrays, starting guesses (padded curve solutions) at ``omegas``
    omegas : (n,) frequencies [rad/s] of the curve points, monotone
    i : int, index of the curve's peak in ``xs``
    tol : float, Newton tolerance on |R|_2
    tol_lam : float, tolerance on the peak frequency [rad/s]
    window : int, points on each side of ``i`` corrected first (more when the peak lies
        at the window's end)
    amp_rel : float, when > 0 the peak frequency is refined only to the tolerance that
        leaves this relative error in the amplitude, A'' tol_lam^2 / 2 with A'' from the
        three corrected points around the highest (if looser than ``tol_lam``): the
        amplitude is flat at its maximum

    Returns
    -------
    x, omega, amplitude, solves (int), window (dict index -> (N,) corrected solution, or
    None where Newton failed); RuntimeError when no peak is found.
    """
    solved = {}

    def at(j):
        if j not in solved:
            x0 = xs[j]
            near = [k for k in solved if solved[k] is not None]
            if near:  # the nearest corrected point is a better guess than the padded one
                k = min(near, key=lambda k: abs(k - j))
                x0 = solved[k] + (xs[j] - xs[k])
            try:
                solved[j] = newton(lambda z: fun(z, omegas[j])[:2], x0, tol, 40,
                                   factor=getattr(fun, "factorize", None)).x
            except NewtonError:
                solved[j] = None
        return solved[j]
    lo, hi = max(i - window, 0), min(i + window, len(xs) - 1)
    for _ in range(MAX_EXTEND + 1):
        idx = [j for j in range(lo, hi + 1) if at(j) is not None]
        if len(idx) < 3:
            raise RuntimeError("the richer harmonic set has no solution near the peak")
        amps = [amplitude(solved[j], omegas[j]) for j in idx]
        top = int(np.argmax(amps))
        if 0 < top < len(idx) - 1:
            break
        if (top == 0 and lo == 0) or (top == len(idx) - 1 and hi == len(xs) - 1):
            raise RuntimeError("the peak with the richer harmonic set lies at the band's end")
        lo, hi = (max(lo - window, 0), hi) if top == 0 else (lo, min(hi + window, len(xs) - 1))
    else:
        raise RuntimeError("the peak with the richer harmonic set is outside the window searched")
    j = idx[top]
    k0, k1 = idx[top - 1], idx[top + 1]
    if amp_rel > 0:
        tol_lam = flat_tolerance(tol_lam, amp_rel, [omegas[k] for k in (k0, j, k1)], amps[top - 1:top + 2])
    branch = Branch(x=[solved[k0], solved[j], solved[k1]],
                    lam=[omegas[k0], omegas[j], omegas[k1]], iterations=[0, 0, 0])
    x, w, a, n = refine_max(fun, branch, 1, amplitude, tol, tol_lam)
    return x, w, a, len(solved) + n, solved


def flat_tolerance(tol_lam, amp_rel, ws, amps) -> float:
    """The frequency tolerance [rad/s] that leaves ``amp_rel`` in the amplitude at a
    maximum through the points (ws, amps) (their second difference on a non-uniform grid),
    at least ``tol_lam``, at most FLAT_MAX times it and a quarter of the smaller spacing
    (the peak frequency stays within FLAT_MAX of its own tolerance)."""
    h0, h1 = ws[1] - ws[0], ws[2] - ws[1]
    curv = abs(2.0 * (amps[0] * h1 - amps[1] * (h0 + h1) + amps[2] * h0) / (h0 * h1 * (h0 + h1)))
    if not curv > 0:
        return tol_lam
    return max(tol_lam, min(math.sqrt(2.0 * amp_rel * amps[1] / curv), 0.25 * min(abs(h0), abs(h1)),
                            FLAT_MAX * tol_lam))


#: Largest factor on the frequency tolerance of a level's peak (:func:`flat_tolerance`).
FLAT_MAX = 10.0


def spacing(omegas, i) -> float:
    """The curve's frequency step at its point i [rad/s] (the larger of its two sides)."""
    lo, hi = max(i - 1, 0), min(i + 1, len(omegas) - 1)
    return max(abs(omegas[i] - omegas[lo]), abs(omegas[hi] - omegas[i]))


#: Half-width of the bracket of :func:`near_peak`, in units of the peak's last move in
#: frequency between levels: the levels' peaks converge, so the next move is smaller
#: (measured on UPD-24: moves of 1.9, 1.0, 0.74, 0.16 rad/s from H = 7 to 50).
NEAR_BRACKET = 2.0


def near_peak(fun, amplitude, x0, levels, tol, tol_lam, amp_rel, curve_step):
    """The peak of a level after the first from the previous level's, by successive parabolas.

    Solves at the previous level's peak frequency omega_p and at omega_p +- delta (delta =
    NEAR_BRACKET times the peak's last move between levels, at least FLAT_MAX ``tol_lam``,
    at most the curve's step ``curve_step`` [rad/s], :func:`spacing`), from ``x0`` (the
    previous peak padded); then at the vertex of the parabola of the amplitude through the
    highest solved point and its nearest neighbours on either side (successive parabolic
    interpolation, converging
    superlinearly on a smooth maximum: Brent 1973, ch. 5), until the vertex lies within
    the frequency tolerance :func:`flat_tolerance` (``amp_rel``) of the highest solved
    point; then that point's sides at +- the tolerance are probed, and it is the level's
    peak once its neighbours on both sides lie within the tolerance (the bracket bounds
    the peak, as in Brent's stopping rule, whatever the shape of the top). After NEAR_ITER
    vertices and the probes, or a vertex outside the bracket,
    :func:`continuation.refine_max` searches the bracket to the same tolerance.

    Returns
    -------
    (x, omega, amplitude, solves) or None when a solve fails or the peak is not bracketed
    by the first three points (the caller searches the curve's window then).
    """
    w_p = levels[-1][2]
    move = abs(levels[-1][2] - levels[-2][2]) if len(levels) >= 2 else curve_step
    delta = min(max(NEAR_BRACKET * move, FLAT_MAX * tol_lam), curve_step)
    factor = getattr(fun, "factorize", None)

    lu_c = []   # the centre's LU factors, for chord steps at the other points

    def solve(x, w):
        got = chord(fun, lu_c[0], x, w, tol) if lu_c else None
        return got if got is not None else newton(lambda z: fun(z, w)[:2], x, tol, 40, factor=factor).x
    try:
        xc, dxdw, lu = _solve_with_slope(fun, x0, w_p, tol, factor)
        # the neighbours from the branch's tangent at the centre (measured on UPD-24 at
        # H = 50: 2 Newton iterations each instead of 4 from the centre itself)
        pts = [(w_p - delta, solve(xc - delta * dxdw, w_p - delta)), (w_p, xc),
               (w_p + delta, solve(xc + delta * dxdw, w_p + delta))]
        if lu is not None:   # the points inside the bracket by chord steps (too far out there)
            lu_c.append(lu)
    except NewtonError:
        return None
    pts = [(w, amplitude(x, w), x) for w, x in pts]
    if not pts[1][1] > max(pts[0][1], pts[2][1]):
        return None
    flat = flat_tolerance(tol_lam, amp_rel, [p[0] for p in pts], [p[1] for p in pts])
    for _ in range(NEAR_ITER + 2):
        k = max(range(len(pts)), key=lambda j: pts[j][1])
        lo, top, hi = pts[k - 1], pts[k], pts[k + 1]
        if hi[0] - top[0] <= BRACKET_SLACK * flat and top[0] - lo[0] <= BRACKET_SLACK * flat:
            return top[2], top[0], top[1], len(pts)     # the maximum is within flat of top
        v = _vertex(lo, top, hi)
        if v is None or not lo[0] < v < hi[0]:
            break
        if abs(v - top[0]) <= flat:
            # the vertex has settled: probe top +- flat on a side still wider, so that the
            # bracket, not the parabola, bounds the peak (a kink at lift-off or stick-slip
            # has no parabolic top: measured on the 3D contact point at H = 12, a vertex
            # within flat of a point 2.6e-5 below the peak)
            up = hi[0] - top[0] > BRACKET_SLACK * flat and (v >= top[0] or top[0] - lo[0] <= BRACKET_SLACK * flat)
            v = top[0] + (flat if up else -flat)
        near = lo if v < top[0] else hi
        try:
            x = solve(top[2] + (v - top[0]) / (near[0] - top[0]) * (near[2] - top[2]), v)
        except NewtonError:
            break
        pts.insert(k if v < top[0] else k + 1, (v, amplitude(x, v), x))
    k = max(range(1, len(pts) - 1), key=lambda j: pts[j][1])
    branch = Branch(x=[p[2] for p in pts[k - 1:k + 2]], lam=[p[0] for p in pts[k - 1:k + 2]],
                    iterations=[0, 0, 0])
    x, w, a, n = refine_max(fun, branch, 1, amplitude, tol, flat)
    return x, w, a, len(pts) + n


def _solve_with_slope(fun, x0, w, tol, factor):
    """(x, dx/domega) at the solution of fun(., w) = 0 from x0: the slope
    -R_x^-1 R_omega from the last evaluation (at x) and the last Newton step's LU factors
    (of R_x one step before x: a predictor's accuracy), zeros when neither is at hand."""
    last = {}

    def f(z):
        R, J, Rw = fun(z, w)
        last.update(z=z, Rw=Rw)
        return R, J
    res = newton(f, x0, tol, 40, factor=factor)
    lu = res.lu if res.lu is not None else (factor or lu_factor)(res.J)
    if lu is None or not np.array_equal(last["z"], res.x):
        return res.x, np.zeros_like(res.x), lu
    slope = -lu_solve(lu, last["Rw"])
    return res.x, slope if np.all(np.isfinite(slope)) else np.zeros_like(res.x), lu


#: Chord steps (:func:`chord`) allowed per solve, and the factor by which each must
#: reduce |R|; a solve that misses either is Newton's.
CHORD_ITER = 10
CHORD_RATE = 0.5


def chord(fun, lu, x, w, tol):
    """x with |R(x, w)|_2 <= tol by chord steps (Newton's with the fixed factors ``lu`` of
    a nearby Jacobian: Kelley 2003, ch. 5; each step one residual, ``fun.value``, and a
    back-substitution), or None when ``fun`` has no ``value`` or the steps do not contract
    by CHORD_RATE within CHORD_ITER. Inside a peak's bracket the Jacobian changes little
    from the centre's; measured on UPD-24 at H = 50: 3-6 chord steps (a residual each,
    ~1/6 of a Newton iteration with its Jacobian and LU) where Newton took 2 iterations."""
    value = getattr(fun, "value", None)
    if value is None:
        return None
    R = value(x, w)
    n = np.linalg.norm(R)
    for _ in range(CHORD_ITER):
        if n <= tol:
            return x
        x = x - lu_solve(lu, R)
        R = value(x, w)
        n_new = np.linalg.norm(R) if np.all(np.isfinite(R)) else np.inf
        if not n_new <= CHORD_RATE * n:
            return None
        n = n_new
    return x if n <= tol else None


#: Parabola vertices solved by :func:`near_peak` before it hands the bracket to Brent
#: (besides the two probes at the settled vertex's sides).
NEAR_ITER = 4
#: A side of the bracket counts as closed within this factor of the frequency tolerance
#: (the probes land at exactly that tolerance; round-off in the sum).
BRACKET_SLACK = 1.0 + 1e-9


def _vertex(p0, p1, p2) -> float | None:
    """Abscissa of the vertex of the parabola through three points (w, a, ...) with distinct
    w, or None when they are collinear or the parabola opens upwards."""
    (w0, a0), (w1, a1), (w2, a2) = p0[:2], p1[:2], p2[:2]
    d0, d2 = (a0 - a1) / (w0 - w1), (a2 - a1) / (w2 - w1)
    c2 = (d2 - d0) / (w2 - w0)   # Newton's form: a = a0 + d0 (w - w0) + c2 (w - w0)(w - w1)
    if not c2 < 0:
        return None
    return 0.5 * (w0 + w1) - d0 / (2.0 * c2)   # where d0 + c2 (2 w - w0 - w1) = 0
