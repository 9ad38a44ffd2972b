"""Statistics of a Monte Carlo sample of amplification factors, each with its confidence.

Pure functions of a sample x_1 .. x_n (the amplification factors of the samples that
solved); nothing here knows about bladed disks.

Symbols: n the sample size, x_(1) <= .. <= x_(n) the order statistics, xi_q the true
q-quantile, 1 - alpha the confidence level (0.95).

Quantile interval, distribution-free (order statistics; Hahn, Meeker and Escobar,
*Statistical Intervals*, 2nd ed., Wiley 2017, sec. 5.2; David and Nagaraja, *Order
Statistics*, 3rd ed., Wiley 2003, sec. 7.1). The number K of sample values below xi_q is
binomial (n, q) for any continuous distribution, so::

    P(x_(l) <= xi_q <= x_(u)) = P(l <= K <= u - 1) = B(u - 1) - B(l - 1)      (S1)

with B the binomial (n, q) distribution function. l is the largest index with
B(l - 1) <= alpha / 2 and u the smallest with B(u - 1) >= 1 - alpha / 2: each tail holds
at most alpha / 2, the coverage (S1) is at least 1 - alpha (conservative: K is discrete).
When B(0) > alpha / 2 no order statistic bounds xi_q from below (``low`` is None), when
B(n - 1) < 1 - alpha / 2 none bounds it from above (``high`` is None): the two-sided
95 % interval of the 0.95 quantile needs n >= 72, the 0.99 quantile's n >= 368. With
one end the interval is one-sided, at its exact coverage (S1) with the missing end at
infinity (at least 1 - alpha / 2).

The estimate is the sample quantile (numpy's linear interpolation, at the 1-based rank
1 + (n - 1) q). A sample too small for a high quantile can bound it without estimating
it: at n = 2 the 0.99 quantile is at least x_(2) (coverage 0.980), while the
interpolation at rank 1.99 lies below x_(2). An estimate outside its own interval is
not reported (``value`` None); for the reported quantiles this happens only at
n = 2, q = 0.99 (checked for n < 3000).

An interval checked against the q-quantile *estimate* of an independent sample of m
(not the true xi_q) holds it less often than its coverage: the estimate scatters too.
For large n and m both estimates are nearly normal about xi_q with variances
q (1 - q) / (n f^2) and q (1 - q) / (m f^2) (f the density at xi_q: the sample quantile's asymptotic
normality, David and Nagaraja ch. 10), the interval is about the n-estimate +- z sigma_n with z the normal quantile
of its coverage, so::

    P(low <= estimate_m <= high) ~ 2 Phi(z / sqrt(1 + n / m)) - 1                  (S2)

0.93 for n = 1000, m = 4000 (coverage 0.958): one such pair in 15 misses.

Mean interval: Student's t, mean +- t_(1 - alpha/2, n - 1) s / sqrt(n) (s the sample
standard deviation): exact for normal samples, asymptotically right for any finite
variance (the amplification is bounded); at n = 1 there is none.

Fitted distribution: the amplification is the largest of N_b blade peaks, a maximum, so
its distribution belongs to the generalized extreme value (GEV) family in the limit
(Coles, *An Introduction to Statistical Modeling of Extreme Values*, Springer 2001,
ch. 3); a maximum bounded above (Whitehead's bound) gives its reversed-Weibull branch
(scipy's ``genextreme`` shape c > 0, upper end loc + scale / c). The three-parameter
Weibull (``weibull_min`` with a location) is fitted as the alternative; both by maximum
likelihood (``scipy.stats``), the one with the smaller AIC reported as ``best``. The
goodness of fit is the Kolmogorov-Smirnov distance D = sup |F_n - F| between the
empirical and the fitted distribution function, with the KS p-value (optimistic: the
parameters were fitted to the same sample, Lilliefors 1967).
"""
from __future__ import annotations

import math
import warnings

import numpy as np
from scipy import stats

#: Quantiles reported with their intervals (the 0.95 one is the design figure).
QUANTILES = (0.5, 0.9, 0.95, 0.99)
#: Confidence level of every interval.
LEVEL = 0.95
#: Distribution families fitted (scipy.stats names).
FAMILIES = ("genextreme", "weibull_min")
#: Starting shapes of the GEV fit (Frechet-like, near Gumbel, reversed Weibull).
GEV_SHAPE_STARTS = (-0.2, 0.1, 0.4)
#: Smallest sample a distribution is fitted to (three parameters; fewer points fit anything).
MIN_FIT = 10


def _sample(x) -> np.ndarray:
    """Finite 1-D float sample, ValueError when empty or not finite."""
    x = np.asarray(x, dtype=float).reshape(-1)
    if x.size == 0 or not np.all(np.isfinite(x)):
        raise ValueError("a sample of finite values is needed")
    return x


def quantile_ci_ranks(n: int, q: float, level: float = LEVEL) -> tuple[int | None, int | None, float]:
    """1-based ranks (l, u) of the order statistics bounding the q-quantile (S1) and the
    interval's exact coverage; a rank is None when no order statistic bounds that side."""
    if not (0.0 < q < 1.0 and 0.0 < level < 1.0 and n >= 1):
        raise ValueError(f"need n >= 1, 0 < q < 1, 0 < level < 1 (got {n}, {q}, {level})")
    a2 = (1.0 - level) / 2.0
    cdf = stats.binom.cdf(np.arange(n + 1), n, q)           # B(k), k = 0..n
    lows = np.flatnonzero(cdf[:n] <= a2)                     # candidates l - 1 = k
    low = int(lows[-1]) + 1 if lows.size else None
    highs = np.flatnonzero(cdf[:n] >= 1.0 - a2)              # candidates u - 1 = k <= n - 1
    high = int(highs[0]) + 1 if highs.size else None
    cov = (cdf[high - 1] if high else 1.0) - (cdf[low - 1] if low else 0.0)
    return low, high, float(cov)


def quantile_ci(x, q: float, level: float = LEVEL) -> dict:
    """The q-quantile of the sample ``x`` (n,) and its distribution-free interval (S1).

    Returns
    -------
    dict
        ``q``, ``value`` (numpy's default linear interpolation; None where it lies outside
        the interval: the sample bounds the quantile but cannot estimate it, module
        docstring), ``low``, ``high`` (order statistics, None where the sample is too
        small to bound that side: the interval is then one-sided), ``coverage`` (the
        interval's exact coverage, >= level when both ends exist, >= (1 + level) / 2 with
        one), ``half_width`` ((high - low) / 2, None when a side is missing: JSON has no
        infinity).
    """
    xs = np.sort(_sample(x))
    lo, hi, cov = quantile_ci_ranks(xs.size, q, level)
    low = None if lo is None else float(xs[lo - 1])
    high = None if hi is None else float(xs[hi - 1])
    half = None if low is None or high is None else (high - low) / 2.0
    value = float(np.quantile(xs, q))
    if (low is not None and value < low) or (high is not None and value > high):
        value = None
    return {"q": q, "value": value, "low": low, "high": high, "coverage": cov, "half_width": half}


def containment_probability(n: int, m: int, q: float = 0.95, level: float = LEVEL) -> float:
    """Probability (S2) that the q-quantile's interval from n samples holds the q-quantile
    estimate of an independent sample of m (large-sample normal approximation)."""
    cov = quantile_ci_ranks(n, q, level)[2]
    if not m >= 1:
        raise ValueError(f"need m >= 1 (got {m})")
    z = stats.norm.ppf(0.5 + 0.5 * cov)
    return float(2.0 * stats.norm.cdf(z / math.sqrt(1.0 + n / m)) - 1.0)


def mean_ci(x, level: float = LEVEL) -> dict:
    """Sample mean of ``x`` (n,) and its Student-t interval (None bounds and half-width
    when n = 1)."""
    x = _sample(x)
    m = float(x.mean())
    if x.size < 2:
        return {"value": m, "low": None, "high": None, "half_width": None}
    half = float(stats.t.ppf(0.5 + level / 2.0, x.size - 1) * x.std(ddof=1) / math.sqrt(x.size))
    return {"value": m, "low": m - half, "high": m + half, "half_width": half}


def fit_family(x, family: str) -> dict:
    """Maximum-likelihood fit of one scipy.stats family (:data:`FAMILIES`) to ``x`` (n,).

    Returns
    -------
    dict
        ``family``, ``params`` (``c`` shape, ``loc``, ``scale``; scipy's convention),
        ``log_likelihood``, ``aic`` (2 k - 2 log L, k = 3), ``ks_distance`` (sup
        |F_n - F|), ``ks_pvalue`` (optimistic, module docstring), ``quantiles``
        (the fitted distribution's :data:`QUANTILES`).
    """
    x = _sample(x)
    if family not in FAMILIES:
        raise ValueError(f"family must be one of {FAMILIES}, got {family!r}")
    dist = getattr(stats, family)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        # the optimizer probes shapes where the density is zero: log(0) warnings
        warnings.simplefilter("ignore", RuntimeWarning)
        if family == "weibull_min":
            # the location must stay below the smallest value; start from a scale of the spread
            spread = max(float(np.ptp(x)), 1e-12 * abs(float(x.mean())) + 1e-300)
            c, loc, scale = dist.fit(x, 2.0, loc=float(x.min()) - 0.5 * spread, scale=spread)
        else:
            c, loc, scale = _fit_gev(x)
        logl = float(np.sum(dist.logpdf(x, c, loc, scale)))
    ks = stats.kstest(x, dist.cdf, args=(c, loc, scale))
    return {"family": family, "params": {"c": float(c), "loc": float(loc), "scale": float(scale)},
            "log_likelihood": logl, "aic": 6.0 - 2.0 * logl,
            "ks_distance": float(ks.statistic), "ks_pvalue": float(ks.pvalue),
            "quantiles": {f"{q:g}": float(dist.ppf(q, c, loc, scale)) for q in QUANTILES}}


def _fit_gev(x: np.ndarray) -> tuple:
    """GEV maximum likelihood from the Gumbel moment estimates and three shapes (scipy's
    default start, c = 1, loc = 0, scale = 1, ends far from the optimum on samples near 1)."""
    scale = float(x.std()) * math.sqrt(6.0) / math.pi         # Gumbel: var = pi^2 s^2 / 6
    loc = float(x.mean()) - 0.5772156649 * scale                # Gumbel: mean = loc + gamma s
    best = None
    for c0 in GEV_SHAPE_STARTS:
        p = stats.genextreme.fit(x, c0, loc=loc, scale=scale)
        ll = float(np.sum(stats.genextreme.logpdf(x, *p)))
        if best is None or ll > best[0]:
            best = (ll, p)
    return best[1]


def fit_distribution(x) -> dict | None:
    """Both :data:`FAMILIES` fitted to ``x``; ``best`` the family with the smaller AIC.
    None when the sample has fewer than :data:`MIN_FIT` values or no spread."""
    x = _sample(x)
    if x.size < MIN_FIT or np.ptp(x) <= 1e-12 * abs(float(x.mean())):
        return None
    fits = {}
    for f in FAMILIES:
        try:
            fits[f] = fit_family(x, f)
        except (ValueError, RuntimeError, FloatingPointError) as err:   # an optimizer that failed
            fits[f] = {"family": f, "error": f"{type(err).__name__}: {err}"}
    ok = [f for f in FAMILIES if "error" not in fits[f] and np.isfinite(fits[f]["aic"])]
    return {"best": min(ok, key=lambda f: fits[f]["aic"]) if ok else None, "fits": fits}


def summary(x, quantiles=QUANTILES, level: float = LEVEL) -> dict:
    """Everything above for one sample: ``n``, ``level``, ``mean``, ``quantiles`` (a list of
    :func:`quantile_ci` dicts), ``fit`` (:func:`fit_distribution`)."""
    x = _sample(x)
    return {"n": int(x.size), "level": level, "mean": mean_ci(x, level),
            "quantiles": [quantile_ci(x, q, level) for q in quantiles],
            "fit": fit_distribution(x)}


def quantile_half_width(x, q: float = 0.95, level: float = LEVEL) -> float:
    """Half-width of the q-quantile's interval (inf while the sample is too small)."""
    h = quantile_ci(x, q, level)["half_width"]
    return math.inf if h is None else h
