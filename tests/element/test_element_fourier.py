"""iwan_periodic_fourier: the loop's exact Fourier coefficients (no AFT sampling).

References: the Jenkins describing function (references.md), the sampled loop
(iwan_periodic) whose coefficients converge to the exact ones as n_t^-2, and central
differences for the Jacobian.
"""
from __future__ import annotations

import numpy as np
import pytest
from elcases import SEED
from refcheck import check

from fmu_src.element import IwanElement, IwanInputError


def basis(harmonics, n):
    """Samples (n, n_b) of cos/sin per harmonic (the mean alone), the C core's order."""
    th = 2 * np.pi * np.arange(n) / n
    cols = []
    for h in harmonics:
        cols += [np.ones(n)] if h == 0 else [np.cos(h * th), np.sin(h * th)]
    return np.column_stack(cols)


def sampled(el, harmonics, U, n):
    """Coefficients of the sampled periodic loop on n points (the AFT's D)."""
    E = basis(harmonics, n)
    F = el.periodic(E @ U).F
    w = np.where(np.repeat([h for h in harmonics], [1 if h == 0 else 2 for h in harmonics]) == 0,
                 1.0, 2.0) / n
    return (E.T @ F) * w


def test_jenkins_describing_function_is_exact():
    """a1 = (k a / pi)(th* - sin(2 th*)/2), b1 = -(k a / pi) sin(th*)^2, W = -pi a b1:
    to round-off (the sampled loop on 256 points is 2e-4 off)."""
    k, fs, a = 2e6, 3.0, 4e-6
    Fh, dFh, W, ne = IwanElement.jenkins(k, fs).periodic_fourier((1, 2, 3), [a, 0, 0, 0, 0, 0], 64)
    th = np.arccos(1 - 2 * fs / (k * a))
    a1, b1 = k * a / np.pi * (th - np.sin(2 * th) / 2), -k * a / np.pi * np.sin(th) ** 2
    assert ne == 2
    df = "Jenkins describing function (references.md)"
    check("exact-link first harmonic a1 [N], Jenkins, a = 2.7 fs/k", Fh[0], a1, rtol=1e-13, source=df)
    check("exact-link first harmonic b1 [N], Jenkins, a = 2.7 fs/k", Fh[1], b1, rtol=1e-13, source=df)
    check("exact-link energy per cycle [J], Jenkins, a = 2.7 fs/k", W, -np.pi * a * b1, rtol=1e-13,
          source="W = -pi a b1")
    # odd harmonics of a symmetric loop; even ones vanish
    assert abs(Fh[2]) < 1e-12 * abs(a1) and abs(Fh[3]) < 1e-12 * abs(a1)


@pytest.mark.parametrize("case", ["jenkins", "iwan with mean and minor loops"])
def test_sampled_loop_converges_to_the_exact_coefficients(case):
    """The sampled AFT's error falls like n_t^-2 (the reversal and the stick ends land
    between samples); the exact coefficients are its limit."""
    if case == "jenkins":
        el, hs = IwanElement.jenkins(2e6, 3.0), (1, 2, 3)
        U = np.array([4e-6, 1e-6, 0.3e-6, 0, 0, 0.2e-6])
    else:
        el, hs = IwanElement.from_sliders([1.0, 2.0, 0.5], [0.2, 0.3, 0.1], k_res=0.3), (0, 1, 2, 3, 5)
        U = np.array([0.1, 1.0, 0.2, 0.3, -0.1, 0.05, 0.2, 0.1, 0.02])
    Fh, _, W, ne = el.periodic_fourier(hs, U, 64)
    assert ne >= 2
    errs = [np.abs(sampled(el, hs, U, n) - Fh).max() / np.abs(Fh).max() for n in (1024, 4096, 16384)]
    # measured: 1e-5 .. 1e-8 by factors ~16 per quadrupling
    assert errs[2] < 1e-6 and errs[0] / errs[1] > 8 and errs[1] / errs[2] > 8
    assert W == pytest.approx(el.periodic(basis(hs, 16384) @ U).W_cycle, rel=1e-6)


def test_jacobian_matches_central_differences():
    """Random multiharmonic inputs (minor loops included); central differences with a
    step 1e-7 of the coefficients' scale: exact between events, round-off ~1e-9."""
    rng = np.random.default_rng(SEED)
    el, hs = IwanElement.from_curve([0, 1e-6, 3e-6, 6e-6], [0, 1.0, 2.2, 3.0], 10.0), (0, 1, 2, 3)
    for _ in range(5):
        U = rng.normal(0.0, 2e-6, 7)
        Fh, dFh, _, _ = el.periodic_fourier(hs, U, 64)
        h = 1e-7 * np.abs(U).max()
        fd = np.column_stack([(el.periodic_fourier(hs, U + h * e, 64)[0]
                               - el.periodic_fourier(hs, U - h * e, 64)[0]) / (2 * h)
                              for e in np.eye(U.size)])
        np.testing.assert_allclose(dFh, fd, rtol=0, atol=1e-6 * np.abs(dFh).max())


def test_a_minor_loop_appears_continuously():
    """u = cos s + eps cos 3s, s = t - phi, grows wiggles at s = pi/2, 3 pi/2 (two more
    extrema each: du/ds = -sin s (1 + 9 eps - 12 eps sin^2 s)) at eps = 1/3. With
    phi = 0.05 the birth sits mid-way between two of the 64 scan points, where u' keeps
    one sign at both: the pair must be found from the sign change of u'' (measured: the
    scan alone finds 2 extrema just after the birth and this test fails). The loop's
    coefficients must not jump there (a jump would stall Newton: the scan alone left
    gaps on a 1e6 k FRF)."""
    el, hs, phi = IwanElement.jenkins(1e3, 0.1), (1, 3), 0.05

    def U(eps):
        return [np.cos(phi), np.sin(phi), eps * np.cos(3 * phi), eps * np.sin(3 * phi)]

    eps = 1.0 / 3.0 + np.linspace(-2e-3, 2e-3, 41)
    F = np.array([el.periodic_fourier(hs, U(e), 64)[0] for e in eps])
    n = [el.periodic_fourier(hs, U(e), 64)[3] for e in eps]
    assert n[0] == 2 and n[-1] == 6
    # across eps* +- 1e-8 the coefficients move by their slope times 2e-8 (a wiggle
    # missed by the scan until it spans a cell would jump by ~f_s dt / pi = 3e-3)
    Fm = el.periodic_fourier(hs, U(1.0 / 3.0 - 1e-8), 64)
    Fp = el.periodic_fourier(hs, U(1.0 / 3.0 + 1e-8), 64)
    assert Fm[3] == 2 and Fp[3] == 6
    slope = np.abs(np.diff(F, axis=0)).max() / 1e-4
    assert np.abs(Fp[0] - Fm[0]).max() < 10 * slope * 2e-8


def test_constant_input_and_bad_arguments():
    el = IwanElement.jenkins(1e3, 0.1)
    Fh, dFh, W, ne = el.periodic_fourier((0, 1), [0.5, 0.0, 0.0], 16)
    assert ne == 0 and not Fh.any() and not dFh.any() and W == 0.0
    with pytest.raises(IwanInputError, match="NaN"):
        el.periodic_fourier((1,), [np.nan, 0.0], 16)
    with pytest.raises(IwanInputError, match="bad parameter"):
        el.periodic_fourier((2, 1), [1.0, 0.0, 0.0, 0.0], 16)      # not ascending
    with pytest.raises(IwanInputError, match="bad parameter"):
        el.periodic_fourier((1, 9), [1.0, 0.0, 0.0, 0.0], 16)      # the scan cannot see h = 9
    with pytest.raises(IwanInputError, match="coefficients"):
        el.periodic_fourier((1, 2), [1.0, 0.0], 16)


def test_branches_between_extrema_are_the_loop_on_any_path_through_them():
    """iwan_periodic_branches against the sampled loop (iwan_periodic) on a dense straight
    path through the same extrema, a minor loop (-0.4 -> 0.6) included: the play operator
    is exact on straight paths, so F agrees to round-off, and so does W."""
    el = IwanElement.from_sliders([1.0, 2.0, 0.5], [0.2, 0.3, 0.1], k_res=0.3)
    ue = np.array([1.0, -0.4, 0.6, -1.0])
    b = el.periodic_branches(ue)
    n = 400
    path = np.concatenate([np.linspace(ue[k], ue[(k + 1) % 4], n + 1)[:-1] for k in range(4)])
    loop = el.periodic(path)
    F = np.empty_like(path)
    for k in range(4):
        for j, u in enumerate(path[k * n:(k + 1) * n]):
            i = [i for i in np.flatnonzero(b["seg"] == k)
                 if min(b["u_lo"][i], b["u_hi"][i]) - 1e-12 <= u <= max(b["u_lo"][i], b["u_hi"][i]) + 1e-12][0]
            F[k * n + j] = b["icpt"][i] + b["slope"][i] * u
    np.testing.assert_allclose(F, loop.F, rtol=0, atol=1e-12)
    assert b["W"] == pytest.approx(loop.W_cycle, rel=1e-12)
    # the intervals cover each segment in travel order, and their slopes are the stuck ones
    assert set(b["slope"]) <= {0.3 + s for s in (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5)}
    with pytest.raises(IwanInputError, match="two extrema"):
        el.periodic_branches([1.0])


#: Agreement of two scans that find the same extrema: the coefficients differ by the
#: round-off of the root refinement and the integrals alone.
SCAN_RTOL = 1e-12


def test_fft_and_phasor_scans_give_the_same_loop():
    """The scan of u' runs by one FFT on a power-of-two grid (128 points) and by phasors
    on any other (96 points): on rich multiharmonic inputs (H = 15 with the mean, many
    extrema and minor loops) both find the same extrema, so the coefficients and the
    Jacobian agree to round-off."""
    rng = np.random.default_rng(SEED)
    el = IwanElement.from_sliders([1.0, 2.0, 0.5], [0.2, 0.3, 0.1], k_res=0.3)
    hs = tuple(range(16))
    for _ in range(5):
        U = rng.normal(0.0, 1.0, 31) / np.repeat(np.arange(1, 17), [1] + [2] * 15)
        a, b = el.periodic_fourier(hs, U, 128), el.periodic_fourier(hs, U, 96)
        assert a[3] == b[3] > 2
        np.testing.assert_allclose(a[0], b[0], rtol=0, atol=SCAN_RTOL * np.abs(a[0]).max())
        np.testing.assert_allclose(a[1], b[1], rtol=0, atol=SCAN_RTOL * np.abs(a[1]).max())


def test_jacobian_matches_central_differences_at_many_harmonics():
    """As the 3-harmonic test, at H = 12 with odd harmonics only and with all of them
    (the Jacobian is built from the stiffness's Fourier coefficients, orders up to 2H,
    plus the anchors' outer products: both sets of orders exercise the index pairs)."""
    rng = np.random.default_rng(SEED + 1)
    el = IwanElement.from_sliders([1.0, 2.0, 0.5], [0.2, 0.3, 0.1], k_res=0.3)
    for hs in (tuple(range(0, 13)), tuple(range(1, 13, 2))):
        nb = sum(1 if h == 0 else 2 for h in hs)
        scale = np.repeat(np.array(hs, float).clip(1.0), [1 if h == 0 else 2 for h in hs])
        U = rng.normal(0.0, 1.0, nb) / scale
        Fh, dFh, _, ne = el.periodic_fourier(hs, U, 64)
        assert ne > 2
        h = 1e-7 * np.abs(U).max()
        fd = np.column_stack([(el.periodic_fourier(hs, U + h * e, 64)[0]
                               - el.periodic_fourier(hs, U - h * e, 64)[0]) / (2 * h)
                              for e in np.eye(nb)])
        np.testing.assert_allclose(dFh, fd, rtol=0, atol=1e-6 * np.abs(dFh).max())
