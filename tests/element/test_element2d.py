"""The 2D Masing/Iwan element (fmu_src/core/iwan2d.c) against closed forms, the 1D
element, an independent reference (iwan2d_ref.py) and its own invariants."""
from __future__ import annotations

import math

import numpy as np
import pytest
from elcases import N_SPHERE, SEED, cattaneo_table
from iwan2d_ref import QUAD_RTOL, RefIwan2D
from scipy.integrate import quad

from fmu_src.element import IwanElement, IwanInputError
from fmu_src.element2d import IwanElement2D

#: Sums of a few hundred slider terms: relative round-off.
ROUNDOFF = 1e-12
#: The reference integrates with quad/brentq to QUAD_RTOL; positions and work of a
#: history of tens of steps agree to this relative tolerance.
REF_RTOL = 1e-10
#: The required accuracy of the circle at 4000 steps per cycle (the polygon's own error ~1e-7).
CIRCLE_RTOL = 1e-4
#: Central differences at 1e-7 of the slip radius: truncation O(h^2) ~ 1e-14 of the
#: curvature scale, round-off ~1e-16 / 1e-7 = 1e-9 of the force scale.
FD_STEP, FD_RTOL = 1e-7, 1e-6

K_J, FS_J = 2e6, 3.0          # Jenkins slider [N/m], [N]
R_J = FS_J / K_J              # its slip radius [m]


@pytest.fixture(scope="module")
def iwan():
    return IwanElement2D.from_curve(*cattaneo_table(12), N_ref=N_SPHERE)


def random_history(rng, n, scale, N0, dN, lift=False):
    """Random walk of n points in the plane (step ~scale) and N around N0 (+- dN)."""
    u = np.cumsum(rng.normal(scale=scale, size=(n, 2)), axis=0)
    N = N0 + dN * rng.uniform(-1, 1, size=n)
    if lift:
        N[n // 3: n // 3 + 3] = -0.2 * N0
    return u, N


def circle(a, n, periods, center=(0.0, 0.0)):
    t = 2 * np.pi * np.arange(n * periods + 1) / n
    return np.c_[center[0] + a * np.cos(t), center[1] + a * np.sin(t)]


# ---------------------------------------------------------------- the reference
@pytest.mark.parametrize("lift", [False, True])
def test_matches_independent_reference_on_random_paths(iwan, lift):
    rng = np.random.default_rng(SEED)
    r_max = iwan.element.slip_radii().max()
    u, N = random_history(rng, 40, 0.4 * r_max, N_SPHERE, 0.5 * N_SPHERE, lift)
    ref, st = RefIwan2D.of(iwan), iwan.initial_state()
    for ui, Ni in zip(u, N):
        out = iwan.step(st, ui, Ni)
        ref.step(ui, Ni)
        scale = max(np.abs(ref.force()).max(), 1e-3)
        assert np.allclose(out.F, ref.force(), rtol=0, atol=REF_RTOL * scale)
        assert math.isclose(out.W, ref.W, rel_tol=REF_RTOL, abs_tol=1e-20)
        assert np.allclose(st.z, ref.z, rtol=0, atol=REF_RTOL * r_max)


def test_reference_sees_the_turning_and_the_varying_radius():
    """A single step with the stretch across the motion and N changing: the regime
    where the work needs the quadrature (K_d of iwan2d.c)."""
    el = IwanElement2D.jenkins(K_J, FS_J)
    for N1 in (1.0, 0.3, 1.7, 0.0):
        st = el.initial_state(1.0)
        el.step(st, [0.0, R_J], 1.0)               # stretch along +y at its limit
        ref = RefIwan2D.of(el)
        ref.step([0.0, R_J], 1.0)
        el.step(st, [5 * R_J, R_J], N1)            # pulled along +x, radius r0 -> r1
        ref.step([5 * R_J, R_J], N1)
        assert math.isclose(st.W, ref.W, rel_tol=REF_RTOL), N1
        assert np.allclose(st.z, ref.z, rtol=0, atol=REF_RTOL * R_J), N1


# ---------------------------------------------------------------- the 1D element
@pytest.mark.parametrize("angle", [0.0, 0.7, -2.5, np.pi / 2])
def test_straight_line_is_the_1d_element(iwan, angle):
    rng = np.random.default_rng(SEED + 1)
    s = np.cumsum(rng.normal(scale=2e-7, size=60))
    N = N_SPHERE * (1 + 0.5 * rng.uniform(-1, 1, size=60))
    N[20:23] = -10.0                                # lift-off and re-contact
    t = np.array([np.cos(angle), np.sin(angle)])
    r1 = iwan.element.series(s, N)
    r2 = iwan.series(s[:, None] * t, N)
    Fmax = np.abs(r1.F).max()
    assert np.abs(r2.F @ t - r1.F).max() <= ROUNDOFF * Fmax
    assert np.abs(r2.F @ np.array([-t[1], t[0]])).max() <= ROUNDOFF * Fmax
    assert np.abs(r2.W - r1.W).max() <= ROUNDOFF * r1.W.max()


def test_tangent_on_a_line_is_the_1d_tangent(iwan):
    st1, st2 = iwan.element.initial_state(), iwan.initial_state()
    t = np.array([0.6, 0.8])
    for s in (1e-6, 4e-7, 7e-7):
        o1 = iwan.element.step(st1, s)
        o2 = iwan.step(st2, s * t)
        assert np.allclose(o2.K @ t, o1.kt * t, rtol=0, atol=ROUNDOFF * o1.kt + 1e-3)
        assert np.allclose(o2.dFdN, o1.dFdN * t, rtol=0, atol=ROUNDOFF)


# ---------------------------------------------------------------- circles
def test_jenkins_circle_energy_and_its_convergence_order():
    """Steady circle of radius a: the slider moves on a circle sqrt(a^2 - r^2), W per
    cycle = 2 pi f_s sqrt(a^2 - r^2). The exact chord update converges at order 2 (the
    inscribed polygon), within 1e-4 at 4000 steps a cycle."""
    el, a = IwanElement2D.jenkins(K_J, FS_J), 3 * R_J
    want = 2 * np.pi * FS_J * math.sqrt(a * a - R_J * R_J)
    errs = []
    for n in (500, 1000, 2000, 4000):
        W = el.series(circle(a, n, 6)).W
        errs.append(abs((W[-1] - W[-1 - n]) / want - 1))
    assert errs[-1] < CIRCLE_RTOL
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.05), orders


def test_iwan_circle_energy_is_the_sum_over_its_sliders(iwan):
    """Virgin at the centre: sliders with r_j < a slip on their circles, the others stay."""
    el = iwan.element
    r = el.slip_radii()
    a, n = 0.6 * r.max(), 4000
    W = iwan.series(circle(a, n, 6)).W
    slips = r < a
    want = np.sum(2 * np.pi * el.fs[slips] * np.sqrt(a * a - r[slips] ** 2))
    assert abs((W[-1] - W[-1 - n]) / want - 1) < CIRCLE_RTOL


# ---------------------------------------------------------------- energy balance
def input_work(el, st, u1, N1, points):
    """int F . du along the straight step from st to (u1, N1), by quad of the trial force
    (iwan2_eval at intermediate points is exact on the straight path), split at the
    stick-slip switches ``points`` of the reference."""
    u0, N0 = st.u, st.N
    d = np.asarray(u1) - u0

    def power(s):
        return el.eval(st, u0 + s * d, N0 + s * (N1 - N0)).F @ d

    pts = sorted(p for p in points if p is not None and 0 < p < 1)
    return quad(power, 0.0, 1.0, points=pts or None, epsabs=0.0, epsrel=QUAD_RTOL, limit=200)[0]


@pytest.mark.parametrize("path", ["ellipse", "lift-off"])
def test_energy_balance_closes_to_round_off(path):
    """Input work = W + change of stored energy, every step (flat tail: k_res = 0, so
    lift-off releases no stored energy)."""
    el = IwanElement2D.from_curve(*cattaneo_table(8), N_ref=N_SPHERE, tail="flat")
    r = el.element.slip_radii().max()
    n = 60
    t = 2 * np.pi * np.arange(1, 2 * n + 1) / n
    u = np.c_[1.5 * r * np.cos(t), 0.5 * r * np.sin(t)]
    N = np.full(t.size, N_SPHERE)
    if path == "lift-off":
        N = N_SPHERE * (0.6 + 0.5 * np.cos(3 * t))    # lift-off and re-contact in between
        N[n // 2: n // 2 + 4] = -20.0
    st, ref = el.initial_state(), RefIwan2D.of(el)
    E0, work = 0.0, 0.0
    for ui, Ni in zip(u, N):
        ref_before = (ref.u.copy(), ref.N)
        ref.step(ui, Ni)
        points = ref.s_star
        if ref_before[1] > 0 and Ni <= 0:      # the switches refer to the part before lift-off
            sl = ref_before[1] / (ref_before[1] - Ni)
            points = [None if p is None else p * sl for p in points] + [sl]
        elif ref_before[1] <= 0 < Ni:
            sc = -ref_before[1] / (Ni - ref_before[1])
            points = [None if p is None else sc + p * (1 - sc) for p in points] + [sc]
        work += input_work(el, st, ui, Ni, points)
        out = el.step(st, ui, Ni)
        assert math.isclose(work, out.W + out.E - E0, rel_tol=0, abs_tol=1e-10 * max(out.W, 1e-9))


# ---------------------------------------------------------------- exactness of the path
def test_results_do_not_depend_on_how_a_straight_path_is_sampled(iwan):
    rng = np.random.default_rng(SEED + 2)
    r = iwan.element.slip_radii().max()
    u, N = random_history(rng, 12, 0.7 * r, N_SPHERE, 0.4 * N_SPHERE)
    N[5] = -5.0
    a, b = iwan.initial_state(), iwan.initial_state()
    prev, Nprev = np.zeros(2), N_SPHERE
    for ui, Ni in zip(u, N):
        iwan.step(a, ui, Ni)
        for s in (0.13, 0.5, 0.77, 1.0):           # the same line, in four pieces
            iwan.step(b, prev + s * (ui - prev), Nprev + s * (Ni - Nprev))
        prev, Nprev = ui, Ni
        assert np.allclose(a.z, b.z, rtol=0, atol=1e-12 * r)
        assert math.isclose(a.W, b.W, rel_tol=1e-11)


# ---------------------------------------------------------------- tangent
def fd_tangent(el, st, u, N, h):
    """Central differences of the trial force in (u_x, u_y, N): shape (2, 3)."""
    cols = []
    for k, step in enumerate((h, h, h * N_SPHERE / 1e-6)):
        dx = np.zeros(3)
        dx[k] = step
        Fp = el.eval(st, u + dx[:2], N + dx[2]).F
        Fm = el.eval(st, u - dx[:2], N - dx[2]).F
        cols.append((Fp - Fm) / (2 * step))
    return np.column_stack(cols)


def test_step_tangent_equals_central_differences(iwan):
    rng = np.random.default_rng(SEED + 3)
    r = iwan.element.slip_radii().max()
    u, N = random_history(rng, 30, 0.5 * r, N_SPHERE, 0.3 * N_SPHERE)
    st = iwan.initial_state()
    checked = 0
    for i in range(len(u) - 1):
        iwan.step(st, u[i], N[i])
        out = iwan.eval(st, u[i + 1], N[i + 1])
        J = np.column_stack([out.K, out.dFdN])
        fd = fd_tangent(iwan, st, u[i + 1], N[i + 1], FD_STEP * r)
        scale = np.abs(J[:, :2]).max()
        if np.abs(fd - J)[:, :2].max() > FD_RTOL * scale:   # a switch within the difference
            continue
        assert np.allclose(J[:, 2], fd[:, 2], rtol=0, atol=FD_RTOL * np.abs(J[:, 2]).max() + 1e-12)
        checked += 1
    assert checked >= len(u) - 4


def test_zero_step_tangent_is_the_limit_for_continued_motion():
    el = IwanElement2D.jenkins(K_J, FS_J)
    st = el.initial_state()
    el.step(st, [2 * R_J, 0.5 * R_J])                  # slipping, moving along (4, 1)
    t = np.array([4.0, 1.0]) / math.hypot(4, 1)
    K0 = el.eval(st, st.u).K
    Kh = el.eval(st, st.u + 1e-9 * R_J * t).K
    assert np.allclose(K0, Kh, rtol=0, atol=1e-6 * K_J)
    e = st.u - st.z[0]
    n = e / np.linalg.norm(e)
    assert np.allclose(K0, K_J * (np.eye(2) - np.outer(n, n)), rtol=0, atol=ROUNDOFF * K_J)


# ---------------------------------------------------------------- bad input
def test_bad_inputs_are_refused_and_leave_the_state(iwan):
    st = iwan.initial_state()
    iwan.step(st, [1e-7, 2e-7])
    before = bytes(st._raw)
    for bad in ([np.nan, 0.0], [0.0, np.inf]):
        with pytest.raises(IwanInputError, match="NaN or infinite"):
            iwan.step(st, bad)
    with pytest.raises(IwanInputError, match="NaN or infinite"):
        iwan.step(st, [0.0, 0.0], np.nan)
    assert bytes(st._raw) == before
    st._raw.dir[0] = 0.5                              # corrupted: dir not a unit vector
    with pytest.raises(IwanInputError, match="bad state"):
        iwan.step(st, [0.0, 0.0])
    with pytest.raises(IwanInputError, match=r"shape \(n, 2\)"):
        iwan.series(np.zeros(5))


def test_same_model_as_the_1d_element():
    el1 = IwanElement.jenkins(K_J, FS_J)
    el2 = IwanElement2D(el1)
    assert el2.n_sliders == 1 and el2.N_ref == 1.0
    out = el2.step(el2.initial_state(), [0.5 * R_J, 0.0])
    assert np.allclose(out.F, [0.5 * FS_J, 0.0], rtol=ROUNDOFF)


# ---------------------------------------------------------------- periodic loop
def fourier_basis(n=64, h=2):
    th = 2 * np.pi * np.arange(n) / n
    cols = [np.ones(n)]
    for j in range(1, h + 1):
        cols += [np.cos(j * th), np.sin(j * th)]
    return np.column_stack(cols)


def test_periodic_jacobian_equals_central_differences(iwan):
    """Slip in two directions, N varying through lift-off: dF/d(X_x, X_y, X_N)."""
    E = fourier_basis()
    r = iwan.element.slip_radii().max()
    X = np.r_[np.array([0.1, 1.2, 0.3, 0.1, 0.0]) * r, np.array([0.0, 0.2, 0.9, 0.0, 0.1]) * r,
              N_SPHERE * np.array([0.3, 0.5, 0.0, 0.1, 0.0])]

    def loop(X):
        return iwan.periodic_jac(E @ X[:5], E @ X[5:10], E, N=E @ X[10:], EN=E, tol=1e-13,
                                 max_periods=400)

    res = loop(X)
    assert (E @ X[10:] < 0).any() and res.W_cycle > 0
    J = res.dF.reshape(-1, 15)
    fd = np.empty_like(J)
    for c in range(15):
        step = np.zeros(15)
        step[c] = FD_STEP * (r if c < 10 else N_SPHERE)
        fd[:, c] = (loop(X + step).F.ravel() - loop(X - step).F.ravel()) / (2 * step[c])
    assert np.abs(fd - J).max() <= FD_RTOL * np.abs(J).max()


@pytest.mark.parametrize("angle", [0.0, 0.7])
def test_periodic_loop_on_a_line_is_the_1d_loop(iwan, angle):
    E = fourier_basis()
    r = iwan.element.slip_radii().max()
    s = E @ (np.array([0.3, 1.2, 0.3, 0.1, 0.0]) * r)
    t = np.array([np.cos(angle), np.sin(angle)])
    F1, dF1, _, W1 = iwan.element.periodic_jac(s, E)
    res = iwan.periodic_jac(s * t[0], s * t[1], E)
    assert np.abs(res.F @ t - F1).max() <= ROUNDOFF * np.abs(F1).max()
    assert abs(res.W_cycle - W1) <= ROUNDOFF * W1
    dline = np.einsum("i,tijc,j->tc", t, res.dF[:, :, :2, :], t)   # along the line, both ways
    assert np.abs(dline - dF1).max() <= ROUNDOFF * np.abs(dF1).max()


def test_periodic_circle_energy():
    el, a, n = IwanElement2D.jenkins(K_J, FS_J), 3 * R_J, 4000
    t = 2 * np.pi * np.arange(n) / n
    res = el.periodic_jac(a * np.cos(t), a * np.sin(t))
    assert abs(res.W_cycle / (2 * np.pi * FS_J * math.sqrt(a * a - R_J * R_J)) - 1) < CIRCLE_RTOL


def test_periodic_refuses_bad_input(iwan):
    E = fourier_basis()
    with pytest.raises(IwanInputError, match="shape"):
        iwan.periodic_jac(np.zeros(64), np.zeros(64), E[:10])
    with pytest.raises(IwanInputError, match="NaN or infinite"):
        iwan.periodic_jac(np.full(64, np.nan), np.zeros(64), E)
