"""The 3D contact point (fmu_src/core/contact_point.c): normal law, the 2D element at
N(p), energy balance with the normal spring, the 3 x 3 tangent, dashpots, bad input."""
from __future__ import annotations

import math

import numpy as np
import pytest
from elcases import N_SPHERE, SEED, cattaneo_table
from scipy.integrate import quad

from fmu_src.contact_point import ContactPoint
from fmu_src.element import IwanElement, IwanInputError
from fmu_src.element2d import IwanElement2D

#: Quadrature of the input work on PIECES sub-intervals a step (each holds few of the
#: sliders' stick-slip kinks, which adaptive quadrature resolves): round-off of the sums.
WORK_RTOL, PIECES = 1e-12, 24
#: Central differences at 1e-7 of the slip radius (truncation ~1e-14, round-off ~1e-9).
FD_STEP, FD_RTOL = 1e-7, 1e-6

#: Normal law of a Hertz-like contact: N = c p^1.5 sampled at 6 points (convex).
P_TAB = np.linspace(0.0, 2e-6, 6)
N_TAB = N_SPHERE * (P_TAB / 1e-6) ** 1.5


@pytest.fixture(scope="module")
def tangential():
    return IwanElement.from_curve(*cattaneo_table(10), N_ref=N_SPHERE, tail="flat")


@pytest.fixture(scope="module")
def point(tangential):
    return ContactPoint(tangential, P_TAB, N_TAB)


def test_normal_law_interpolates_the_table(point):
    for p in (-1e-7, 0.0, 0.3e-6, 1.2e-6, 2e-6, 3e-6):
        N, slope = point.normal(p)
        want = 0.0 if p <= 0 else np.interp(p, P_TAB, N_TAB) if p <= 2e-6 else \
            N_TAB[-1] + (p - 2e-6) * (N_TAB[-1] - N_TAB[-2]) / (P_TAB[-1] - P_TAB[-2])
        assert math.isclose(N, want, rel_tol=1e-14, abs_tol=0.0), p
    assert math.isclose(point.normal(point.penetration(N_SPHERE))[0], N_SPHERE, rel_tol=1e-14)


def test_penalty_law_is_k_n_p(tangential):
    cp = ContactPoint.penalty(tangential, 3e8)
    for p in (1e-9, 2.5e-6, 1e-3):
        assert cp.normal(p) == (3e8 * p, 3e8)
    assert cp.normal(-1e-6) == (0.0, 0.0)


def test_constant_penetration_is_the_2d_element(tangential, point):
    rng = np.random.default_rng(SEED)
    p = point.penetration(N_SPHERE)
    el, st2 = IwanElement2D(tangential), None
    st = point.initial_state(p)
    st2 = el.initial_state(point.normal(p)[0])
    for u in np.cumsum(rng.normal(scale=3e-7, size=(30, 2)), axis=0):
        a = point.step(st, [*u, p])
        b = el.step(st2, u, point.normal(p)[0])
        assert np.array_equal(a.f[:2], b.F) and a.W == b.W


def path_work(point, st, q1):
    """int f . dq along the straight step: quad on PIECES sub-intervals (a few stick-slip
    kinks each) and at the points where p crosses the normal table (kinks of N)."""
    q0 = st.q
    d = np.asarray(q1) - q0
    cuts = set(np.linspace(0.0, 1.0, PIECES + 1))
    cuts |= {(pb - q0[2]) / d[2] for pb in P_TAB if d[2] != 0 and 0 < (pb - q0[2]) / d[2] < 1}
    cuts = sorted(cuts)
    power = lambda s: point.eval(st, q0 + s * d).f @ d  # noqa: E731
    return sum(quad(power, a, b, epsabs=1e-20, epsrel=1e-13)[0] for a, b in zip(cuts[:-1], cuts[1:]))


def test_energy_balance_with_normal_spring_and_lift_off(point):
    """Input work of (F_x, F_y, N) = W + change of E (sliders + normal spring), through
    lift-off and re-contact (flat-tail curve: k_res = 0)."""
    r = point.tangential.slip_radii().max()
    t = 2 * np.pi * np.arange(1, 41) / 20
    q = np.c_[1.5 * r * np.cos(t), 0.7 * r * np.sin(t), 1e-6 * (0.5 + 0.8 * np.sin(2 * t))]
    st = point.initial_state(0.5e-6)
    E0 = point.eval(st, st.q).E
    work = 0.0
    for qi in q:
        work += path_work(point, st, qi)
        out = point.step(st, qi)
        assert math.isclose(work, out.W + out.E - E0, rel_tol=WORK_RTOL, abs_tol=1e-15)
    assert st.W > 0 and (q[:, 2] < 0).any()


def fd_jacobian(point, st, q, h):
    cols = []
    for k in range(3):
        dq = np.zeros(3)
        dq[k] = h
        cols.append((point.eval(st, q + dq).f - point.eval(st, q - dq).f) / (2 * h))
    return np.column_stack(cols)


def test_tangent_equals_central_differences_across_table_points(point):
    rng = np.random.default_rng(SEED + 1)
    r = point.tangential.slip_radii().max()
    st = point.initial_state(1e-6)
    checked = 0
    for _ in range(30):
        q1 = st.q + rng.normal(size=3) * np.array([0.5 * r, 0.5 * r, 0.6e-6])
        q1[2] = abs(q1[2]) + 0.05e-6                  # stays in contact at the end
        out = point.eval(st, q1)
        fd = fd_jacobian(point, st, q1, FD_STEP * r)
        if np.abs(fd - out.K).max() <= FD_RTOL * np.abs(out.K).max():
            checked += 1
        point.step(st, q1)
    assert checked >= 26


def test_zero_step_tangent_continued_motion(point):
    st = point.initial_state(1e-6)
    r = point.tangential.slip_radii(point.normal(1e-6)[0]).max()
    point.step(st, [3 * r, 0.0, 1e-6])                # gross slip along +x
    out = point.eval(st, st.q)
    N, kn = point.normal(1e-6)
    assert out.state == 2 and math.isclose(out.K[2, 2], kn)
    assert abs(out.K[0, 0]) < 1e-9 * kn               # every slider slipping along x
    mu = point.tangential.gross_slip_force() / N_SPHERE
    assert math.isclose(out.K[0, 2], mu * kn, rel_tol=1e-12)   # d(mu N)/dp for decreasing p


def test_dashpots_add_in_contact_and_never_pull(tangential):
    cp = ContactPoint(tangential, P_TAB, N_TAB, c_t=10.0, c_n=20.0)
    st = cp.initial_state(1e-6)
    N = cp.normal(1e-6)[0]
    a = cp.eval(st, st.q, v=[0.1, -0.2, 0.5])
    assert np.allclose(a.f, [1.0, -2.0, N + 10.0]) and np.array_equal(a.C, [10.0, 10.0, 20.0])
    b = cp.eval(st, st.q, v=[0.0, 0.0, -1e3])           # fast separation: no adhesion
    assert b.f[2] == 0.0 and b.C[2] == 0.0 and b.K[2, 2] == 0.0
    c = cp.eval(st, [0.0, 0.0, -1e-6], v=[1.0, 1.0, 1.0])   # open: no dashpot force
    assert np.array_equal(c.f, np.zeros(3)) and c.state == 0


@pytest.mark.parametrize("p, N, what", [
    ([0, 1e-6, 2e-6], [0, 5, 4], "not monotone"),
    ([0, 2e-6, 1e-6], [0, 5, 9], "p not increasing"),
    ([-1e-6, 0, 1e-6], [0, 5, 9], "negative penetration"),
    ([1e-7, 1e-6], [0, 5], "not from (0, 0)"),
    ([0.0], [0.0], "one point"),
])
def test_bad_normal_laws_are_refused(tangential, p, N, what):
    with pytest.raises(IwanInputError, match="strictly increasing|2 to 256"):
        ContactPoint(tangential, p, N)


def test_bad_inputs_leave_the_state(point):
    st = point.initial_state(1e-6)
    point.step(st, [1e-7, 0.0, 1.1e-6])
    before = bytes(st._raw)
    for q in ([np.nan, 0, 1e-6], [0, 0, np.inf]):
        with pytest.raises(IwanInputError, match="NaN or infinite"):
            point.step(st, q)
    with pytest.raises(IwanInputError, match="NaN or infinite"):
        point.step(st, [0, 0, 1e-6], v=[0, np.nan, 0])
    assert bytes(st._raw) == before
    st._raw.s.N *= 1.5                                 # N no longer N(p): corrupted
    with pytest.raises(IwanInputError, match="bad state"):
        point.step(st, [0, 0, 1e-6])
    with pytest.raises(IwanInputError, match="dashpot|bad parameter"):
        ContactPoint(point.tangential, P_TAB, N_TAB, c_t=-1.0)
