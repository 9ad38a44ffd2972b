"""damper.mistuning_stats: intervals and fits checked against known distributions."""
import math

import numpy as np
import pytest
from scipy import stats

from damper.mistuning_stats import (
    QUANTILES,
    containment_probability,
    fit_distribution,
    fit_family,
    mean_ci,
    quantile_ci,
    quantile_ci_ranks,
    quantile_half_width,
    summary,
)

#: Replications of a coverage experiment; the empirical coverage's standard error is
#: sqrt(p (1 - p) / REPS) ~ 0.011 at p = 0.95.
REPS = 400
#: Allowed distance of an empirical coverage from the exact one: 4 standard errors (a
#: false alarm once in ~16000 seeds; a wrong rank moves the coverage by > 0.05).
COVERAGE_SIGMAS = 4.0
#: A GEV of the shape amplification factors have (bounded above: c > 0).
GEV = (0.3, 1.2, 0.1)


def _coverage_tol(p):
    return COVERAGE_SIGMAS * math.sqrt(p * (1 - p) / REPS)


def test_median_interval_of_six_is_the_extremes_with_coverage_1_minus_2_over_64():
    # K ~ Bin(6, 1/2): P(K = 0) = 1/64 <= 0.025, so l = 1, u = 6 (David and Nagaraja 7.1)
    low, high, cov = quantile_ci_ranks(6, 0.5)
    assert (low, high) == (1, 6)
    assert cov == pytest.approx(1 - 2 / 64, abs=1e-14)


@pytest.mark.parametrize("q", [0.95, 0.99])
def test_upper_bound_of_a_quantile_exists_from_n_with_q_to_the_n_below_alpha_over_2(q):
    # x_(n) bounds xi_q from above with probability 1 - q^n: needs q^n <= 0.025
    n_min = math.ceil(math.log(0.025) / math.log(q))
    assert quantile_ci_ranks(n_min - 1, q)[1] is None
    assert quantile_ci_ranks(n_min, q)[1] == n_min
    assert quantile_ci(np.arange(n_min - 1.0), q)["half_width"] is None
    assert quantile_half_width(np.arange(n_min - 1.0), q) == math.inf


@pytest.mark.parametrize("q, n", [(0.5, 40), (0.95, 200), (0.9, 1000)])
def test_quantile_interval_covers_the_true_quantile_as_often_as_its_exact_coverage(q, n):
    rng = np.random.default_rng(20261127)
    true = stats.genextreme.ppf(q, *GEV)
    hits = 0
    for _ in range(REPS):
        r = quantile_ci(stats.genextreme.rvs(*GEV, size=n, random_state=rng), q)
        hits += r["low"] <= true <= r["high"]
    cov = quantile_ci_ranks(n, q)[2]
    assert cov >= 0.95
    assert abs(hits / REPS - cov) <= _coverage_tol(cov)


#: The design case: the 0.95 quantile's interval from 1000 samples, replicated 2000 times
#: (standard error of an empirical coverage ~0.0045 at 0.958).
DESIGN_N, DESIGN_REPS = 1000, 2000


def _design_tol(p):
    return COVERAGE_SIGMAS * math.sqrt(p * (1 - p) / DESIGN_REPS)


def test_0p95_quantile_interval_of_1000_samples_has_its_exact_coverage_over_2000_studies():
    """The distribution-free interval holds the true quantile as often as (S1) says; the
    same draws mapped through another distribution give the same hits (order statistics
    are invariant under a monotone map), so one family suffices."""
    draws = stats.genextreme.ppf(np.random.default_rng(20261127).random((DESIGN_REPS, DESIGN_N)), *GEV)
    true = stats.genextreme.ppf(0.95, *GEV)
    hits = sum(r["low"] <= true <= r["high"] for r in (quantile_ci(x, 0.95) for x in draws))
    cov = quantile_ci_ranks(DESIGN_N, 0.95)[2]
    assert cov >= 0.95
    assert abs(hits / DESIGN_REPS - cov) <= _design_tol(cov)


def test_interval_holds_an_independent_4x_estimate_as_often_as_the_normal_approximation():
    """The check 'the interval of 1000 samples holds the 0.95 quantile of an independent
    4000' succeeds with probability (S2) ~0.93, not 0.95: the large study's estimate
    scatters as well."""
    # Gumbel draws (numpy's own sampler, the GEV with shape 0): fast for 10 million values
    draws = np.random.default_rng(31415).gumbel(1.2, 0.1, (DESIGN_REPS, 5 * DESIGN_N))
    big = np.quantile(draws[:, DESIGN_N:], 0.95, axis=1)     # the independent 4000 of each pair
    hits = sum(r["low"] <= y <= r["high"] for r, y in
               zip((quantile_ci(x, 0.95) for x in draws[:, :DESIGN_N]), big))
    p = containment_probability(DESIGN_N, 4 * DESIGN_N)
    assert p < quantile_ci_ranks(DESIGN_N, 0.95)[2] - 0.02
    assert abs(hits / DESIGN_REPS - p) <= _design_tol(p)


def test_containment_tends_to_the_coverage_for_a_much_larger_second_sample():
    cov = quantile_ci_ranks(DESIGN_N, 0.95)[2]
    assert containment_probability(DESIGN_N, 10**9) == pytest.approx(cov, abs=1e-5)


def test_interval_of_the_0p95_quantile_from_1000_samples_contains_the_true_one():
    x = stats.genextreme.rvs(*GEV, size=1000, random_state=np.random.default_rng(31))
    r = quantile_ci(x, 0.95)
    assert r["low"] <= stats.genextreme.ppf(0.95, *GEV) <= r["high"]
    assert r["low"] <= r["value"] <= r["high"]


def test_mean_interval_covers_the_true_mean_95_percent_of_normal_samples():
    rng = np.random.default_rng(7011)
    hits = 0
    for _ in range(REPS):
        r = mean_ci(1.3 + 0.2 * rng.standard_normal(15))
        hits += r["low"] <= 1.3 <= r["high"]
    assert abs(hits / REPS - 0.95) <= _coverage_tol(0.95)


def test_mean_of_one_sample_has_no_interval():
    assert mean_ci([1.2]) == {"value": 1.2, "low": None, "high": None, "half_width": None}


#: Fit tolerances at n = 3000: about 4 standard errors of the maximum-likelihood
#: estimates (measured spread over five seeds: c 0.01, loc 0.002, scale 0.001).
FIT_N = 3000
FIT_TOL = {"c": 0.06, "loc": 0.01, "scale": 0.008}


def test_gev_fit_recovers_known_parameters_and_is_preferred_over_weibull():
    x = stats.genextreme.rvs(*GEV, size=FIT_N, random_state=np.random.default_rng(4409))
    out = fit_distribution(x)
    p = out["fits"]["genextreme"]["params"]
    for k, v in zip(("c", "loc", "scale"), GEV):
        assert abs(p[k] - v) <= FIT_TOL[k], k
    # the KS distance of the true family stays near its sampling size ~ 1 / sqrt(n)
    assert out["fits"]["genextreme"]["ks_distance"] < 1.63 / math.sqrt(FIT_N)
    assert out["best"] == "genextreme"


def test_three_parameter_weibull_fit_recovers_known_parameters():
    c, loc, scale = 2.5, 1.0, 0.3
    x = stats.weibull_min.rvs(c, loc, scale, size=FIT_N, random_state=np.random.default_rng(5521))
    p = fit_family(x, "weibull_min")["params"]
    # about 4 standard errors (measured spread over seeds: c 0.03, loc 0.003, scale 0.004)
    assert abs(p["c"] - c) <= 0.15 and abs(p["loc"] - loc) <= 0.015 and abs(p["scale"] - scale) <= 0.02


def test_no_fit_below_ten_samples_or_without_spread():
    assert fit_distribution(np.linspace(1, 2, 9)) is None
    assert fit_distribution(np.full(50, 1.3)) is None


def test_summary_orders_quantiles_and_refuses_nonfinite():
    s = summary(stats.genextreme.rvs(*GEV, size=500, random_state=np.random.default_rng(88)))
    v = [q["value"] for q in s["quantiles"]]
    assert v == sorted(v) and s["n"] == 500
    with pytest.raises(ValueError):
        summary([1.0, float("nan")])


#: Sample sizes over which every reported quantile is checked against its own interval
#: (the small sizes where intervals are one-sided, and beyond the 0.99 quantile's 368).
SIZES = range(1, 401)


def test_a_reported_quantile_estimate_lies_inside_its_own_interval():
    rng = np.random.default_rng(20261128)
    for n in SIZES:
        x = stats.genextreme.rvs(*GEV, size=n, random_state=rng)
        for r in (quantile_ci(x, q) for q in QUANTILES):
            if r["value"] is not None:
                assert r["low"] is None or r["low"] <= r["value"]
                assert r["high"] is None or r["value"] <= r["high"]


def test_two_samples_bound_the_99_percent_quantile_without_estimating_it():
    # K ~ Bin(2, 0.99): P(K <= 1) = 1 - 0.99^2 <= 0.025, so xi_0.99 >= x_(2) with coverage
    # 0.99^2, while the interpolated estimate at rank 1.99 lies below x_(2)
    r = quantile_ci([1.2, 1.4], 0.99)
    assert r["low"] == 1.4 and r["high"] is None and r["value"] is None
    assert r["coverage"] == pytest.approx(0.99**2, abs=1e-14)
    assert quantile_ci([1.2, 1.4], 0.95)["value"] == pytest.approx(1.2 + 0.95 * 0.2, abs=1e-14)


def test_printed_quantiles_say_when_an_interval_is_one_sided_and_print_no_estimate_outside_it():
    from damper.cli.upd_mistuning import statistics_lines

    out = {"statistics": summary([1.2, 1.4]),
           "efficiency": {"efficiency": 1.0, "cpu_s": 1.0, "chunks": 1, "chunk_size": 2, "workers": 1, "wall_s": 1.0}}
    q99 = next(line for line in statistics_lines(out) if "quantile 0.99" in line)
    assert "1.39" not in q99 and "[1.4000, -]" in q99 and "at least 1.4000" in q99 and "98.0 %" in q99
