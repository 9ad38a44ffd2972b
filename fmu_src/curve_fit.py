"""From a virgin-curve table to one the C element holds: diagnosis, concave hull, reduction.

The C element (``iwan.h``) represents a concave piecewise-linear curve exactly with
at most ``MAX_SLIDERS`` Jenkins sliders (one per slope change). This module

- says exactly what is wrong with a table it refuses (:func:`check_table`: which
  point, which rule), before the C core's coarse status code would;
- takes the least concave non-decreasing majorant when asked (``fit="concave"``,
  the same majorant as ``IWAN_FIT_CONCAVE``);
- reduces a table with more segments than the element holds to at most that many
  by the min-max optimal piecewise-linear fit through a subset of its own points
  (:func:`reduce_table`), and returns the resulting largest force error.

Why a subset of the points: the fit then keeps (0, 0), the end point (so a
gross-slip plateau keeps its force) and concavity (chords of a concave polyline
between its vertices are concave), and its error is exact: both curves are linear
between the table's points, so max |T - T_fit| over the points is the max over u.
For a concave table the deviation T - chord is >= 0 and grows as a chord from a
fixed start is extended, so the greedy "longest chord within e" cover uses the
fewest segments for a given e; bisection on e gives the least e that fits the budget.

Symbols: u displacement [m], T tangential force [N], m number of points.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from contact_core import curve as curve_file

from ._clib import MAX_SLIDERS, IwanInputError

__all__ = ["FITS", "TAILS", "check_table", "concave_majorant", "reduce_table",
           "prepare_table", "reduce_virgin_curve"]

FITS = ("reject", "concave")
TAILS = ("slope", "flat")
#: A slope may exceed the previous one by this fraction of the largest slope (round-off
#: of collinear points) before the table counts as not concave (IWAN_CONCAVE_RTOL in iwan.c).
CONCAVE_RTOL = 1e-9
#: Bisection on the reduction error stops at this relative width: the fit is optimal to
#: this fraction (its reported error is exact, measured on the kept chords).
_BISECT_RTOL = 1e-6


def check_table(u, T, fit: str = "reject") -> tuple[np.ndarray, np.ndarray]:
    """Validate a virgin-curve table; ``IwanInputError`` names the point and the rule.

    Parameters
    ----------
    u, T : array_like, shape (m,)
        Displacement [m] and force [N].
    fit : {"reject", "concave"}
        "reject" also requires non-decreasing T and concavity (slopes non-increasing
        to ``CONCAVE_RTOL``); "concave" accepts any shape (its majorant is used).

    Returns
    -------
    u, T : ndarray, shape (m,), float64, C-contiguous
    """
    if fit not in FITS:
        raise IwanInputError(f"fit must be one of {FITS}, got {fit!r}")
    u = np.ascontiguousarray(u, dtype=np.float64)
    T = np.ascontiguousarray(T, dtype=np.float64)
    try:
        curve_file.check_table(u, T)  # the basic rules, written once with the curve file
    except ValueError as err:
        raise IwanInputError(str(err)) from None
    if not np.max(T) > 0.0:
        raise IwanInputError("curve: T is 0 at every point: no stiffness (a virgin curve must rise)")
    if fit == "concave":
        return u, T
    s = np.diff(T) / np.diff(u)
    bad = np.flatnonzero(s < 0.0)
    if bad.size:
        i = int(bad[0]) + 1
        raise IwanInputError(f"curve: point {i}: T = {float(T[i])!r} falls below T[{i - 1}] = {float(T[i - 1])!r} "
                             "(T must not decrease: negative stiffness); fit='concave' flattens it")
    rise = s[1:] - s[:-1] - CONCAVE_RTOL * np.max(np.abs(s))
    bad = np.flatnonzero(rise > 0.0)
    if bad.size:
        i = int(bad[0]) + 1
        raise IwanInputError(f"curve: not concave at point {i}: the slope after it ({s[i]:.6g} N/m) "
                             f"exceeds the slope before it ({s[i - 1]:.6g} N/m); "
                             "fit='concave' uses the least concave majorant")
    return u, T


def concave_majorant(u, T) -> tuple[np.ndarray, np.ndarray]:
    """Least concave non-decreasing majorant through the table's own points.

    The upper hull (monotone chain), flat from its highest point to u[-1] (as
    ``IWAN_FIT_CONCAVE``). Shapes (k,), k <= m + 1.
    """
    hull: list[int] = []
    for i in range(len(u)):
        while len(hull) >= 2:
            a, b = hull[-2], hull[-1]
            # b is under the chord a -> i (or on it): not a hull vertex
            if (T[b] - T[a]) * (u[i] - u[a]) <= (T[i] - T[a]) * (u[b] - u[a]):
                hull.pop()
            else:
                break
        hull.append(i)
    idx = np.asarray(hull)
    idx = idx[: int(np.argmax(T[idx])) + 1]
    if idx[-1] == len(u) - 1:
        return u[idx], T[idx]
    return np.append(u[idx], u[-1]), np.append(T[idx], T[idx[-1]])


def _chord_error(u, T, i: int, j: int) -> float:
    """Largest |T - chord| over the points strictly between i and j [N]."""
    if j - i < 2:
        return 0.0
    s = (T[j] - T[i]) / (u[j] - u[i])
    seg = slice(i + 1, j)
    return float(np.max(np.abs(T[seg] - (T[i] + s * (u[seg] - u[i])))))


def _greedy(u, T, tol: float, limit: int) -> list[int] | None:
    """Fewest-chord cover within ``tol``: vertex indices, or None if more than ``limit`` chords."""
    m = len(u)
    keep, i = [0], 0
    while i < m - 1:
        if len(keep) > limit:
            return None
        lo, step = i + 1, 1           # lo is feasible (a chord between neighbours is exact)
        while lo + step < m and _chord_error(u, T, i, lo + step) <= tol:
            lo, step = lo + step, 2 * step
        hi = min(lo + step, m)        # first index known infeasible (or m)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if _chord_error(u, T, i, mid) <= tol:
                lo = mid
            else:
                hi = mid
        keep.append(lo)
        i = lo
    return keep if len(keep) - 1 <= limit else None


def reduce_table(u, T, max_segments: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Min-max optimal fit of a concave table by at most ``max_segments`` of its chords.

    Parameters
    ----------
    u, T : ndarray, shape (m,)
        A concave table (see :func:`check_table`).
    max_segments : int
        Largest number of linear pieces (>= 1).

    Returns
    -------
    u_fit, T_fit : ndarray, shape (k,), k - 1 <= max_segments
        The kept points (first and last always kept).
    error : float
        max |T - T_fit| over the table's points [N] (0.0 when nothing was removed).
    """
    u = np.asarray(u, dtype=np.float64)
    T = np.asarray(T, dtype=np.float64)
    if max_segments < 1:
        raise IwanInputError(f"max_segments must be >= 1, got {max_segments}")
    if len(u) - 1 <= max_segments:
        return u, T, 0.0
    hi = _chord_error(u, T, 0, len(u) - 1)        # one chord: always feasible
    lo = 0.0
    best = [0, len(u) - 1]
    if _greedy(u, T, 0.0, max_segments) is not None:
        hi = 0.0
    while hi - lo > _BISECT_RTOL * max(hi, np.finfo(float).tiny):
        mid = 0.5 * (lo + hi)
        keep = _greedy(u, T, mid, max_segments)
        if keep is None:
            lo = mid
        else:
            hi, best = mid, keep
    keep = _greedy(u, T, hi, max_segments) or best
    idx = np.asarray(keep)
    error = max(_chord_error(u, T, a, b) for a, b in zip(idx[:-1], idx[1:]))
    return u[idx], T[idx], float(error)


def prepare_table(u, T, fit: str = "reject", tail: str = "slope",
                  max_sliders: int = MAX_SLIDERS) -> tuple[np.ndarray, np.ndarray, float]:
    """A table the element holds: checked, majorant if ``fit="concave"``, reduced if too long.

    A flat tail adds one slope change at the end, so the budget is ``max_sliders``
    segments with ``tail="flat"`` and ``max_sliders + 1`` with ``tail="slope"``.

    Returns
    -------
    u, T : ndarray, shape (k,)
    error : float
        Largest force error of the reduction [N] (0.0 when the table already fits).
    """
    if tail not in TAILS:
        raise IwanInputError(f"tail must be one of {TAILS}, got {tail!r}")
    u, T = check_table(u, T, fit)
    budget = max_sliders + (1 if tail == "slope" else 0)
    if len(u) - 1 <= budget:
        return u, T, 0.0      # the C core takes the majorant itself (the same bits as before)
    if fit == "concave":
        u, T = concave_majorant(u, T)
    return reduce_table(u, T, budget)


def reduce_virgin_curve(curve, fit: str = "reject", max_sliders: int = MAX_SLIDERS):
    """The curve the element will use, and the force error of getting there.

    Parameters
    ----------
    curve : contact_core.curve.VirginCurve
    fit : {"reject", "concave"}
    max_sliders : int
        The element's limit (default ``MAX_SLIDERS``).

    Returns
    -------
    reduced : VirginCurve
        Same metadata and tail, at most the element's number of segments (the input
        object itself when it already fits).
    error : float
        max |T - T_fit| over the curve's points [N]; 0.0 when not reduced.

    Raises
    ------
    IwanInputError (a ValueError)
        The curve breaks a rule; the message names the point.
    """
    u, T, error = prepare_table(curve.u, curve.T, fit, curve.tail, max_sliders)
    if u.size == curve.u.size:
        return curve, 0.0
    return dataclasses.replace(curve, u=u, T=T), error
