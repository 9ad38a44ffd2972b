"""Tangential stick/slip solve on the half-space model against Cattaneo-Mindlin.

The normal forces are the Hertz pressure sampled at the nodes (times the cell
area), so these tests check the tangential solve alone; tests with the normal
solver's own forces are in test_tangential_models.py.
"""
import numpy as np
import pytest
from refcheck import check
from scipy import optimize

from contact_core import halfspace_bem as hb
from contact_core import tangential_curve as tc
from contact_core import tangential_reference as tr
from contact_core.tangential import TangentialProblem

R, F, MU, E, NU = 0.01, 200.0, 0.5, 200e9, 0.3
E_STAR = E / (2 * (1 - NU**2))
G_STAR = tr.shear_modulus_star(E, NU, E, NU)
A = (3 * F * R / (4 * E_STAR)) ** (1 / 3)
P0 = 3 * F / (2 * np.pi * A**2)
GRID = 21

#: Virgin curve against Mindlin, over the whole curve: the required 1 % of mu N
#: (0.24 % measured; kept at the requirement, as the gross-slip displacement and
#: the Masing branch below share it and the step control targets 1 %).
CURVE_TOL = 0.01
#: k_t against 8 G* a: the discrete contact area of a 21-cell grid differs from
#: pi a^2, and k_t scales with the contact size; -1.33 % measured.
KT_RTOL = 0.02
#: Loop energy against Mindlin-Deresiewicz at T*/(mu N) ~ 0.75: the thin slip
#: annulus is resolved by a few cells only (1.20 % measured on 21 x 21).
MD_RTOL = 0.018
#: Direct loop against Masing's loop from the same model's virgin curve
#: (both discretised by the step control; 0.2 % measured).
MASING_RTOL = 0.003
#: Trapezoid loop area against the frictional dissipation of the same steps
#: (-0.105 % measured).
AREA_RTOL = 0.0016


@pytest.fixture(scope="module")
def problem():
    contact = hb.sphere(R, 1.2 * A, GRID)
    r2 = contact.grid.x**2 + contact.grid.y**2
    f = P0 * np.sqrt(np.clip(1 - r2 / A**2, 0, None)) * contact.grid.area
    return TangentialProblem(contact, f, MU)


@pytest.fixture(scope="module")
def virgin(problem):
    return tc.virgin_curve(problem)


def test_virgin_curve_follows_cattaneo_mindlin(problem, virgin):
    T_ref = tr.mindlin_force(virgin.u, problem.N, MU, A, G_STAR)
    check(f"virgin curve T(u) [N] over the curve, Hertz pressure, half-space BEM grid {GRID}", virgin.T, T_ref,
          atol=CURVE_TOL * MU * problem.N, source="Cattaneo-Mindlin (Johnson 1985, ch. 7)")
    assert np.all(np.diff(virgin.T) >= 0) and np.all(np.diff(virgin.u) > 0)


def test_initial_stiffness_is_8_gstar_a(problem, virgin):
    check(f"k_t [N/m], Hertz pressure, half-space BEM grid {GRID}", problem.k_t, 8 * G_STAR * A, rtol=KT_RTOL,
          source="Mindlin k_t = 8 G* a")
    # the first step is still in full stick: its secant is k_t
    assert virgin.T[1] / virgin.u[1] == pytest.approx(problem.k_t, rel=1e-6)


def test_full_stick_stiffness_is_the_linear_stick_solve(problem):
    # independent computation: solve C q = 1 with numpy's general solver
    q = np.linalg.solve(problem.C, np.ones(problem.n_c))
    assert problem.k_t == pytest.approx(float(problem.w @ q), rel=1e-10)


@pytest.mark.parametrize("ratio", [0.3, 0.6, 0.9])
def test_stick_radius_follows_mindlin(problem, ratio):
    sol, _ = tc.solve_force(problem, problem.initial_state(), ratio * MU * problem.N)
    assert sol.T == pytest.approx(ratio * MU * problem.N, rel=1e-9)
    area = problem.contact.grid.area
    c_num = np.sqrt(area[sol.stick].sum() / np.pi)
    dx = np.sqrt(area[0])
    assert abs(c_num - tr.mindlin_stick_radius(sol.T, problem.N, MU, A)) <= dx  # grid resolution


def test_gross_slip_is_reached_at_mu_n(problem, virgin):
    last = virgin.points[-1]
    assert last.T == pytest.approx(MU * problem.N, rel=1e-9)
    assert not last.stick.any()
    assert virgin.points[-2].T < MU * problem.N
    u_s = tr.mindlin_slip_displacement(problem.N, MU, A, G_STAR)
    check(f"gross-slip displacement u_s [m], half-space BEM grid {GRID}", virgin.u[-1], u_s, rtol=CURVE_TOL,
          source="Cattaneo-Mindlin u_s = 3 mu N / (16 G* a)")


def test_coulomb_law_holds_at_every_node_and_point(problem, virgin):
    for p in virgin.points:
        q, f = p.q[problem.idx], problem.bound
        assert np.all(np.abs(q) <= f * (1 + 1e-12))
        np.testing.assert_allclose(np.abs(p.q[p.slip]), MU * problem.f_n[p.slip], rtol=1e-12)


def test_stick_nodes_share_the_imposed_displacement(problem, virgin):
    Cq = problem.contact.Cxx @ virgin.points[len(virgin.points) // 2].q
    p = virgin.points[len(virgin.points) // 2]
    assert p.stick.sum() > 10 and p.slip.sum() > 10
    # elastic give of both surfaces equals the rigid motion: no relative slip
    np.testing.assert_allclose(Cq[p.stick], p.delta, rtol=1e-9)
    assert np.all(p.delta - Cq[p.slip] > 0)  # slip nodes have slipped forwards


def test_force_control_refuses_a_load_above_gross_slip(problem):
    with pytest.raises(ValueError, match="gross-slip"):
        tc.solve_force(problem, problem.initial_state(), 1.01 * MU * problem.N)
    with pytest.raises(ValueError, match="finite"):
        tc.solve_force(problem, problem.initial_state(), np.nan)


def test_bad_input_is_refused(problem):
    with pytest.raises(ValueError, match="mu"):
        TangentialProblem(problem.contact, problem.f_n, -0.1)
    with pytest.raises(ValueError, match="finite"):
        problem.solve(problem.initial_state(), np.inf)
    with pytest.raises(ValueError, match="compressive"):
        TangentialProblem(problem.contact, -problem.f_n, MU)


def test_frictionless_contact_carries_no_tangential_force(problem):
    free = TangentialProblem(problem.contact, problem.f_n, 0.0)
    sol, _ = free.solve(free.initial_state(), 1e-6)
    assert sol.T == 0.0 and not sol.stick.any()


def test_virgin_curve_is_odd(problem, virgin):
    u = 0.5 * virgin.u[-1]
    pos, _ = problem.solve(problem.initial_state(), u)
    neg, _ = problem.solve(problem.initial_state(), -u)
    assert neg.T == pytest.approx(-pos.T, rel=1e-12)


@pytest.fixture(scope="module")
def loop(problem, virgin):
    amplitude = 0.6 * virgin.u[-1]
    path, energy = tc.hysteresis_loop(problem, amplitude)
    return amplitude, path, energy


def test_direct_loop_energy_matches_mindlin_deresiewicz(problem, loop):
    _, _, energy = loop
    W_md = tr.mindlin_deresiewicz_energy(energy["T_amplitude"], problem.N, MU, A, G_STAR)
    assert energy["W_friction"] == pytest.approx(W_md, rel=MD_RTOL)
    assert energy["W_area"] == pytest.approx(energy["W_friction"], rel=AREA_RTOL)


def test_direct_loop_matches_masing_loop_from_virgin_curve(problem, virgin, loop):
    amplitude, path, energy = loop
    W_masing = tr.masing_loop_energy(amplitude, virgin.u, virgin.T)
    assert energy["W_area"] == pytest.approx(W_masing, rel=MASING_RTOL)
    # branch by branch: the unloading branch a -> -a against Masing's rule
    u, T = path.u, path.T
    i_a = int(np.argmin(np.abs(u - amplitude)))
    i_m = int(np.argmin(u))
    T_masing = tr.masing_branch(u[i_a:i_m + 1], amplitude, T[i_a], virgin.u, virgin.T)
    assert np.abs(T[i_a:i_m + 1] - T_masing).max() <= CURVE_TOL * MU * problem.N


def test_loop_closes_after_one_cycle(loop):
    _, path, energy = loop
    assert path.T[-1] == pytest.approx(energy["T_amplitude"], rel=1e-9)


def test_solver_matches_bounded_least_squares_on_a_random_problem():
    """Independent oracle: scipy's BVLS on the same box QP, random SPD compliance."""
    rng = np.random.default_rng(20261122)
    n = 40
    B = rng.standard_normal((n, n))
    C = (B @ B.T / n + np.eye(n)) * 1e-9
    from contact_core.condensed import CondensedContact, ContactGrid

    grid = ContactGrid(x=np.zeros(n), y=np.zeros(n), area=np.ones(n), mult=np.full(n, 2.0), h=np.zeros(n))
    contact = CondensedContact(grid=grid, Czz=C, rigid=np.ones((n, 1)), Czz_bodies=(C, 0 * C), Cxx=C)
    f = rng.uniform(0.5, 2.0, n)
    prob = TangentialProblem(contact, f, 0.4)
    state = prob.initial_state()
    for delta in (0.3e-9, 0.8e-9, -0.5e-9):  # load, then reverse: history matters
        sol, new = prob.solve(state, delta)
        L = np.linalg.cholesky(C)
        rhs = np.linalg.solve(L, delta - state.s)
        ref = optimize.lsq_linear(L.T, rhs, bounds=(-prob.bound, prob.bound), method="bvls", tol=1e-15)
        np.testing.assert_allclose(sol.q, ref.x, atol=1e-9 * prob.bound.max())
        state = new


def test_bvls_fallback_gives_the_same_solution(problem, monkeypatch):
    """The fallback (used only if the projected Newton iteration stalls) agrees."""
    import contact_core.tangential as tg

    delta = 0.7 * problem.gross_slip_displacement(problem.initial_state())
    ref, _ = problem.solve(problem.initial_state(), delta)
    monkeypatch.setattr(tg, "MAX_ITER", 0)
    fb, _ = problem.solve(problem.initial_state(), delta)
    # with no projected Newton iteration allowed, every iteration reported is BVLS's: it ran
    assert fb.iterations >= 1
    np.testing.assert_allclose(fb.q, ref.q, atol=1e-8 * problem.bound.max())
    assert np.array_equal(fb.stick, ref.stick)


def test_non_reciprocal_compliance_is_refused(problem):
    from dataclasses import replace

    C = problem.contact.Cxx.copy()
    C[0, 1] *= 1.5
    with pytest.raises(ValueError, match="symmetric"):
        TangentialProblem(replace(problem.contact, Cxx=C), problem.f_n + 1.0, MU)


def test_extreme_friction_coefficients(problem):
    """mu -> infinity: the stuck line up to huge loads; mu tiny: gross slip at once."""
    stuck = TangentialProblem(problem.contact, problem.f_n, 1e6)
    u = 10 * problem.gross_slip_displacement(problem.initial_state())
    sol, _ = stuck.solve(stuck.initial_state(), u)
    assert sol.stick.sum() == stuck.n_c and sol.T == pytest.approx(stuck.k_t * u, rel=1e-9)
    slick = TangentialProblem(problem.contact, problem.f_n, 1e-9)
    curve = tc.virgin_curve(slick)
    assert curve.T[-1] == pytest.approx(1e-9 * slick.N, rel=1e-9)
    assert slick.k_t == pytest.approx(problem.k_t, rel=1e-12)  # stiffness does not see mu


def test_one_huge_step_lands_in_gross_slip(problem):
    u = 50 * problem.gross_slip_displacement(problem.initial_state())
    sol, state = problem.solve(problem.initial_state(), u)
    assert not sol.stick.any() and sol.T == pytest.approx(MU * problem.N, rel=1e-12)
    again, _ = problem.solve(state, u)  # same displacement again: nothing changes
    np.testing.assert_array_equal(again.q, sol.q)


def test_points_are_dense_where_the_curve_bends(virgin):
    """Mindlin's curve bends most towards gross slip: the steps shrink there."""
    steps = np.diff(virgin.u)
    # (single steps vary: a ring of nodes switching to slip is a kink in the
    # discrete curve, which the step control also refines)
    assert steps[-5:].mean() < 0.5 * steps[:5].mean()
    assert len(virgin.u) <= 60  # still a compact table


def test_table_interpolates_the_model_within_the_step_tolerance(problem, virgin):
    """Linear interpolation between the chosen points against the model at the midpoints."""
    mids = 0.5 * (virgin.u[1:] + virgin.u[:-1])
    exact = np.array([problem.solve(problem.initial_state(), u)[0].T for u in mids])
    interp = np.interp(mids, virgin.u, virgin.T)
    assert np.abs(exact - interp).max() <= tc.CURVE_TOL * MU * problem.N


def test_virgin_point_carries_the_history_and_matches_one_step_loading(problem, virgin):
    """On Cattaneo-Mindlin's monotone path the stick zone only shrinks, so one
    step from the virgin state and the stepped march give the same state."""
    target = 0.55 * MU * problem.N
    marched = tc.virgin_point(problem, T=target)
    direct, _ = tc.solve_force(problem, problem.initial_state(), target)
    assert marched.T == pytest.approx(target, rel=1e-9)
    np.testing.assert_allclose(marched.q, direct.q, atol=1e-9 * problem.bound.max())
    at_u = tc.virgin_point(problem, u=marched.delta)
    np.testing.assert_allclose(at_u.q, marched.q, atol=1e-9 * problem.bound.max())
    with pytest.raises(ValueError, match="gross-slip"):
        tc.virgin_point(problem, T=1.5 * MU * problem.N)
