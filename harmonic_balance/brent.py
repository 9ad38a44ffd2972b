"""Brent's minimiser of a function of one variable on an interval (the peak refinement's
search, :func:`.continuation.refine_max`)."""
from __future__ import annotations

import numpy as np

#: Golden-section share of Brent's minimiser.
_GOLDEN = 0.5 * (3.0 - np.sqrt(5.0))


def brent_min(f, a: float, b: float, xtol: float, start: float | None = None,
              max_eval: int = 200) -> tuple[float, float, int]:
    """Minimum of f on [a, b] to an absolute tolerance xtol in x (Brent, Algorithms for
    Minimization without Derivatives, 1973, ch. 5: golden-section steps, parabolic steps
    through the three best points where they are safe). ``start``: the first point
    (default the golden-section point). f may return inf (a point to avoid).

    Returns
    -------
    x, f(x), evaluations
    """
    x = w = v = a + _GOLDEN * (b - a) if start is None else float(start)
    fx = fw = fv = f(x)
    d = e = 0.0
    n = 1
    while n < max_eval:
        m = 0.5 * (a + b)
        if abs(x - m) <= 2.0 * xtol - 0.5 * (b - a):
            break
        p = q = r = 0.0
        if abs(e) > xtol and np.isfinite(fx) and np.isfinite(fw) and np.isfinite(fv):
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            p, q = (-p, q) if q > 0.0 else (p, -q)
            r, e = e, d
        if q != 0.0 and abs(p) < abs(0.5 * q * r) and q * (a - x) < p < q * (b - x):
            d = p / q  # parabolic step
            if (x + d) - a < 2.0 * xtol or b - (x + d) < 2.0 * xtol:
                d = xtol if x < m else -xtol
        else:
            e = (b - x) if x < m else (a - x)  # golden-section step into the larger part
            d = _GOLDEN * e
        u = x + (d if abs(d) >= xtol else np.copysign(xtol, d))
        fu = f(u)
        n += 1
        if fu <= fx:
            if u < x:
                b = x
            else:
                a = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v in (x, w):
                v, fv = u, fu
    return x, fx, n
