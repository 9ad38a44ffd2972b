"""iwan_periodic_jac: exact derivatives of the periodic loop vs finite differences."""
from __future__ import annotations

import numpy as np
import pytest
from elcases import N_SPHERE, SEED, cattaneo_table

from fmu_src.element import IwanElement, IwanInputError

#: Central differences with step 1e-7 of the coefficient scale: truncation is zero
#: for this piecewise-linear map away from kinks, round-off ~1e-16/1e-7 ~ 1e-9.
FD_STEP, FD_RTOL = 1e-7, 1e-6
N_T, H = 64, 3


def basis(n=N_T, h=H):
    """Inverse real DFT: columns 1, cos(t), sin(t), ..., shape (n, 2h+1)."""
    th = 2 * np.pi * np.arange(n) / n
    cols = [np.ones(n)]
    for j in range(1, h + 1):
        cols += [np.cos(j * th), np.sin(j * th)]
    return np.column_stack(cols)


def fd_jac(fun, X):
    step = FD_STEP * np.abs(X).max()
    cols = []
    for e in np.eye(X.size):
        cols.append((fun(X + step * e) - fun(X - step * e)) / (2 * step))
    return np.column_stack(cols)


@pytest.fixture(scope="module")
def el():
    return IwanElement.from_curve(*cattaneo_table(24), N_ref=N_SPHERE)


CASES = {
    "slipping": (np.array([1e-6, 6e-6, 1e-6, 1.5e-6, 0, 0, 0.4e-6]), None),
    "mostly stuck, offset": (np.array([2e-6, 0.4e-6, 0.1e-6, 0, 0.05e-6, 0, 0]), None),
    "varying N": (np.array([1e-6, 6e-6, 1e-6, 1.5e-6, 0, 0, 0.4e-6]),
                  np.array([N_SPHERE, 30, 0, 0, 10, 5, 0])),
    "stuck, negative offset, varying N": (np.array([-3e-6, 0.4e-6, 0.1e-6, 0, 0.05e-6, 0, 0]),
                                           np.array([N_SPHERE, 10, 5, 0, 3, 0, 0])),
    "lift-off": (np.array([1e-6, 6e-6, 1e-6, 1.5e-6, 0, 0, 0.4e-6]),
                 np.array([N_SPHERE, 120, 0, 0, 10, 5, 0])),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_periodic_jacobian_matches_finite_differences(el, case):
    X, XN = CASES[case]
    E = basis()
    N = None if XN is None else E @ XN
    F, J, JN, W = el.periodic_jac(E @ X, E, N, None if XN is None else E)
    loop = el.periodic(E @ X, N)
    np.testing.assert_allclose(F, loop.F, rtol=0, atol=1e-12 * np.ptp(F))
    assert W == pytest.approx(loop.W_cycle, rel=1e-10)
    J_fd = fd_jac(lambda Y: el.periodic(E @ Y, N).F, X)
    np.testing.assert_allclose(J, J_fd, rtol=0, atol=FD_RTOL * np.abs(J).max())
    if XN is not None:
        JN_fd = fd_jac(lambda Y: el.periodic(E @ X, E @ Y).F, XN)
        np.testing.assert_allclose(JN, JN_fd, rtol=0, atol=FD_RTOL * np.abs(JN).max())


def test_jacobian_of_random_multiharmonic_loops(el):
    rng = np.random.default_rng(SEED)
    E = basis()
    for _ in range(5):
        X = rng.normal(0.0, 2e-6, E.shape[1])
        F, J, _, _ = el.periodic_jac(E @ X, E)
        J_fd = fd_jac(lambda Y: el.periodic(E @ Y).F, X)
        np.testing.assert_allclose(J, J_fd, rtol=0, atol=FD_RTOL * np.abs(J).max())


def test_jenkins_first_harmonic_matches_the_describing_function():
    # references.md: a1 = (k a / pi)(th* - sin(2 th*)/2), b1 = -(k a / pi) sin(th*)^2
    k, fs, a = 2e6, 3.0, 4e-6
    E = basis(256, 1)
    F, J, _, W = IwanElement.jenkins(k, fs).periodic_jac(E @ np.array([0, a, 0]), E)
    th = np.arccos(1 - 2 * fs / (k * a))
    a1 = k * a / np.pi * (th - np.sin(2 * th) / 2)
    b1 = -k * a / np.pi * np.sin(th) ** 2
    # DFT of the exact loop sampled at 256 points: a1, b1 to the sampling error O(1/n^2)
    assert 2 * np.mean(F * E[:, 1]) == pytest.approx(a1, rel=1e-3)
    assert 2 * np.mean(F * E[:, 2]) == pytest.approx(b1, rel=1e-3)
    assert W == pytest.approx(-np.pi * a * b1, rel=1e-12)


@pytest.mark.parametrize("case", sorted(CASES))
def test_packed_rows_are_the_dense_jacobian(el, case):
    """periodic_jac_rows: the same numbers as periodic_jac, every omitted row exactly zero."""
    X, XN = CASES[case]
    E = basis()
    N, EN = (None, None) if XN is None else (E @ XN, E)
    F, J, JN, W = el.periodic_jac(E @ X, E, N, EN)
    F2, rows, Jr, JNr, W2 = el.periodic_jac_rows(E @ X, E, N, EN)
    assert len(set(rows)) == len(rows) and np.array_equal(F, F2) and W == W2
    full = np.zeros_like(J)
    full[rows] = Jr
    assert np.array_equal(full, J)
    if JN is not None:
        full[:] = 0.0
        full[rows] = JNr
        assert np.array_equal(full, JN)


def test_packed_rows_of_a_stiff_jenkins_link_in_gross_slip_are_its_stuck_samples():
    """1e4 N/m, f_s = 0.5 N, amplitude 1 m: a slider sticks for 2 f_s / k = 1e-4 m of
    travel after each reversal (theta < sqrt(2e-4), 9 samples of 4096), so 18 samples
    carry a row; the rest slip at +-f_s."""
    E = basis(4096, 15)
    X = np.zeros(E.shape[1])
    X[1] = 1.0
    link = IwanElement.jenkins(1e4, 0.5)
    F, rows, Jr, _, W = link.periodic_jac_rows(E @ X, E)
    _, J, _, _ = link.periodic_jac(E @ X, E)
    stuck = np.flatnonzero(np.any(J != 0.0, axis=1))
    assert 16 <= len(rows) <= 20 and set(stuck) == set(rows)
    slipping = np.setdiff1d(np.arange(4096), rows)
    np.testing.assert_allclose(np.abs(F[slipping]), 0.5, rtol=1e-12)


def test_packed_rows_refuse_a_non_finite_basis_row_they_use():
    """The packed layout checks Eu through its rows: a NaN in a row the Jacobian uses is
    refused (IwanInputError), one in the row of a sample mid-way between the reversals
    (slipping, and no slider's anchor) is not read."""
    E = basis(256, 3)
    X = np.array([0, 1.0, 0, 0, 0, 0, 0])
    link = IwanElement.jenkins(1e2, 0.5)
    _, rows, _, _, _ = link.periodic_jac_rows(E @ X, E)
    bad = E.copy()
    bad[rows[0], 2] = np.nan
    with pytest.raises(IwanInputError, match="NaN"):
        link.periodic_jac_rows(E @ X, bad)
    unused = 64   # theta = pi / 2: stick episodes and their anchors are near 0 and pi
    assert unused not in rows
    ok = E.copy()
    ok[unused, 2] = np.nan
    assert np.array_equal(link.periodic_jac_rows(E @ X, ok)[2], link.periodic_jac_rows(E @ X, E)[2])
    with pytest.raises(IwanInputError, match="NaN"):   # the dense layout reads every row
        link.periodic_jac(E @ X, ok)


#: The sparse terms and the dense rows sum the same products in another order.
TERMS_ROUND = 1e-13


@pytest.mark.parametrize("case", sorted(CASES))
def test_jacobian_terms_rebuild_the_dense_jacobian(el, case):
    """periodic_jac_terms: diag(dX) + the off-diagonal terms, times the basis, is
    periodic_jac's Jacobian (lift-off: the re-contact steps' ends among the terms)."""
    X, XN = CASES[case]
    E = basis()
    N, EN = (None, None) if XN is None else (E @ XN, E)
    F, J, JN, W = el.periodic_jac(E @ X, E, N, EN)
    F2, dX, dXN, row, col, cX, cXN, W2 = el.periodic_jac_terms(E @ X, N, with_N=XN is not None)
    assert np.array_equal(F, F2) and W == W2 and not np.any(row == col)
    for dense, d, c in ((J, dX, cX), (JN, dXN, cXN)):
        S = np.diag(d)
        np.add.at(S, (row, col), c)
        if dense is None:
            assert not np.any(S)
        else:
            np.testing.assert_allclose(S @ E, dense, rtol=0, atol=TERMS_ROUND * np.abs(dense).max())


def test_many_elements_in_one_call_are_each_elements_own_loop(el):
    """periodic_jac_many: every element (its own law, samples and normal basis) gets
    the bits of its own periodic_jac call."""
    from fmu_src.element_batch import periodic_jac_many

    E = basis()
    els = [el, IwanElement.jenkins(2e5, 0.3 * N_SPHERE), IwanElement.from_curve(*cattaneo_table(6), N_ref=N_SPHERE)]
    cases = [CASES[k] for k in ("varying N", "lift-off", "stuck, negative offset, varying N")]
    u = np.array([E @ X for X, _ in cases])
    N = np.array([E @ XN for _, XN in cases])
    EN = [E, 2.0 * E, 0.5 * E]   # N = EN XN: each element's own normal basis
    N = N * np.array([1.0, 2.0, 0.5])[:, None]
    F, J, JN, W = periodic_jac_many(els, u, E, N, EN)
    for i, e in enumerate(els):
        Fi, Ji, JNi, Wi = e.periodic_jac(u[i], E, N[i], EN[i])
        assert np.array_equal(F[i], Fi) and np.array_equal(J[i], Ji)
        assert np.array_equal(JN[i], JNi) and W[i] == Wi


def test_many_elements_name_the_one_that_fails(el):
    """A NaN in one element's samples: IwanInputError naming that element, and the
    same error as its own call."""
    from fmu_src.element_batch import periodic_jac_many

    E = basis()
    X, XN = CASES["varying N"]
    u = np.array([E @ X] * 3)
    u[1, 5] = np.nan
    with pytest.raises(IwanInputError, match=r"element 1\)"):
        periodic_jac_many([el] * 3, u, E, np.array([E @ XN] * 3), [E] * 3)
    with pytest.raises(IwanInputError):
        el.periodic_jac(u[1], E, E @ XN, E)


def test_many_loops_without_jacobian_are_each_elements_own_terms_call(el):
    """periodic_many (and a PeriodicBatch, reused on other samples): every element gets
    the F and W_cycle bits of its own periodic_jac_terms call, the residual path it
    replaces; varying N, lift-off; a NaN names its element."""
    from fmu_src.element_batch import PeriodicBatch, periodic_many

    E = basis()
    els = [el, IwanElement.jenkins(2e5, 0.3 * N_SPHERE), IwanElement.from_curve(*cattaneo_table(6), N_ref=N_SPHERE)]
    cases = [CASES[k] for k in ("varying N", "lift-off", "stuck, negative offset, varying N")]
    u = np.array([E @ X for X, _ in cases])
    N = np.array([E @ XN for _, XN in cases]) * np.array([1.0, 2.0, 0.5])[:, None]
    batch = PeriodicBatch(els)
    for scale in (1.0, 0.3):
        for F, W in (periodic_many(els, scale * u, N), batch.loops(scale * u, N)):
            for i, e in enumerate(els):
                Fi, *_, Wi = e.periodic_jac_terms(scale * u[i], N[i])
                assert np.array_equal(F[i], Fi) and W[i] == Wi
    u[1, 5] = np.nan
    with pytest.raises(IwanInputError, match=r"periodic_many \(element 1\)"):
        batch.loops(u, N)
