"""Force elements with their own kinematics: assembly, cyclic phase, contact law, Jacobians."""
import numpy as np
import pytest
from hbcases import SEED, sdof, two_dof

from fmu_src.element import IwanElement
from harmonic_balance import contact
from harmonic_balance.aft import FrictionLink, aft_link
from harmonic_balance.contact import ContactElement, frictionless_statics
from harmonic_balance.forces import LinearElement, harmonic_work
from harmonic_balance.fourier import FourierBasis
from harmonic_balance.kinematics import Kinematics, phase_operator
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model
from harmonic_balance.residual import CondensedResidual, FullResidual, energy_per_cycle

#: Central differences (step 1e-7) of the contact AFT against its analytic Jacobian,
#: relative to the largest entry (round-off of the differences): measured at most
#: 1.9e-9 (dF/dU) and 9.3e-9 (dF/domega, dashpots only) over these draws; 1.5x that.
FD_RTOL_U = 3e-9
FD_RTOL_W = 1.4e-8
#: Residual Jacobians (products with Q, T, receptances): measured at most 1.3e-9.
FD_RTOL_RES = 2e-9
#: Sector against ring HB solutions (both Newton-converged to |R| < 1e-12, quadratic
#: convergence leaves round-off): measured 1.5e-15 of the largest coefficient.
SECTOR_RING_RTOL = 1e-14
#: Energy balance at an HB solution (|R| < 1e-12 bounds it near 1e-12 / W_ext):
#: measured 5.8e-16 relative.
ENERGY_BALANCE_RTOL = 1e-14
#: Harmonic work of the element force against the C core's sampled-loop work (H = 7,
#: n_t = 256): measured 3.7e-5 relative; 1.5x.
AFT_WORK_RTOL = 5.6e-5
#: Round-off of sums over n_t samples (closed forms, invariances): measured <= 6.2e-15.
ROUND = 1e-14


def fd(f, x, h=1e-7):
    cols = []
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.column_stack(cols)


def plane_contact(friction, **kw):
    """Point on a plane: DOFs (x, y), s = x, p = -y (normal +y from ground into the point)."""
    kin = Kinematics.contact([0, 1], [0.0, 1.0], [1.0, 0.0], np.eye(2))
    return ContactElement(kin, 4.0, friction, **kw)


FRICTIONS = {"jenkins": lambda: IwanElement.jenkins(2.0, 0.3),
             "iwan": lambda: IwanElement.from_sliders([1.0, 0.5, 0.25], [0.1, 0.1, 0.2], 0.05, N_ref=2.0)}


def test_friction_link_assembly_is_bit_identical_to_the_incidence_formula():
    """The stacked Q/T assembly reproduces the former signed-incidence products bit for bit."""
    for model, Res in ((sdof(), FullResidual), (two_dof(True), CondensedResidual),
                       (two_dof(False), FullResidual)):
        b = FourierBasis("all:5")
        res = Res(model, b)
        x = np.random.default_rng(SEED).normal(scale=0.1, size=res.size)
        nb, L = b.nb, len(model.links)
        pos = {int(d): i for i, d in enumerate(res.dofs)}
        B = np.zeros((res.size, L * nb))  # the former residual's incidence matrix
        for l, link in enumerate(model.links):
            B[np.arange(nb) * res.m + pos[link.dof_a], l * nb + np.arange(nb)] = 1.0
            if link.dof_b is not None:
                B[np.arange(nb) * res.m + pos[link.dof_b], l * nb + np.arange(nb)] = -1.0
        U = (B.T @ x).reshape(L, nb)
        out = [aft_link(link, U[l], b) for l, link in enumerate(model.links)]
        J = np.zeros((L * nb, L * nb))
        for l, o in enumerate(out):
            J[l * nb:(l + 1) * nb, l * nb:(l + 1) * nb] = o[1]
        Fnl, dF, W = res.nonlinear(x)
        assert np.array_equal(Fnl, B @ np.concatenate([o[0] for o in out]))
        assert np.array_equal(dF, B @ J @ B.T)
        assert W == [o[2] for o in out]


def test_phase_operator_advances_the_time_history():
    """exp(i h phi) on the coefficients is the history at theta + phi (neighbour sector)."""
    b = FourierBasis("all:4")
    c = np.random.default_rng(SEED).normal(size=b.nb)
    phi = 2 * np.pi * 6 / 24
    th = np.linspace(0, 2 * np.pi, 37)
    P = phase_operator(b, phi)
    assert np.abs(b.evaluate(P @ c, th) - b.evaluate(c, th + phi)).max() < ROUND
    assert np.abs(P.T @ P - np.eye(b.nb)).max() < ROUND


def test_harmonic_stiffness_of_the_sector_matches_the_residual_jacobian():
    """Model.harmonic_stiffness(h) is the stuck HB operator's harmonic-h block (complex form).

    Entries up to 18 N/m: measured 3.6e-15 absolute, bound 1e-13.
    """
    model, b = cyclic_sector("all:3")
    res = FullResidual(model, b)
    Kst = res.stuck_operator() + np.kron(np.eye(b.nb), model.linear.K)
    n = model.n
    for h in (1, 2, 3):
        ic, isn = b.index(h)
        Kh = model.harmonic_stiffness(h)
        # real block [[Re, Im], [-Im, Re]] on (a, b) for U = a - i b (kinematics.py)
        assert np.abs(Kst[ic * n:(ic + 1) * n, ic * n:(ic + 1) * n] - Kh.real).max() < ROUND * 10
        assert np.abs(Kst[ic * n:(ic + 1) * n, isn * n:(isn + 1) * n] - Kh.imag).max() < ROUND * 10
        assert np.abs(Kh - Kh.conj().T).max() < ROUND * 10


def test_cyclic_spring_gives_the_harmonic_coupling_stiffness():
    """k_c (u_j - u_(j+1)) with u_(j+1) = exp(i h phi) u_j adds 2 k_c (1 - cos h phi) per harmonic."""
    kc, phi = 3.0, 2 * np.pi * 5 / 24
    el = LinearElement(Kinematics([0], [[1.0]], Q_next=[[-1.0]], phase=phi), [[kc]])
    model = Model(LinearModel(M=[[1.0]], C=[[0.0]], K=[[1.0]]), [el], {1: np.array([1.0])})
    b = FourierBasis("all:7")
    res = FullResidual(model, b)
    _, J, _ = res(np.zeros(res.size), 0.0)
    expect = 1.0 + 2 * kc * (1 - np.cos(b.order * phi))
    assert np.abs(J - np.diag(expect)).max() < ROUND * kc


@pytest.mark.parametrize("projection", ["product over rows", "sparse terms"])
@pytest.mark.parametrize("kind", sorted(FRICTIONS))
@pytest.mark.parametrize("draw", range(3))
def test_contact_jacobian_matches_finite_differences(kind, draw, projection, monkeypatch):
    """Both projections of the sampled Jacobian (contact.TERMS_MIN_WORK chooses)."""
    monkeypatch.setattr(contact, "TERMS_MIN_WORK", np.inf if projection == "product over rows" else 0.0)
    el = plane_contact(FRICTIONS[kind](), preload=0.2, slip_ref=0.03, beta_c=0.01)
    b = FourierBasis("all:5")
    U = np.random.default_rng(SEED + draw).normal(scale=0.15, size=(b.nb, 2))
    U[0, 1] = 0.0  # mean penetration = preload: partial lift-off
    w = 1.3
    r = el.evaluate(U, b, w)
    assert 0.0 < np.mean(r.f[:, 1] == 0.0) < 1.0  # the draw has partial lift-off
    Jfd = fd(lambda u: el.evaluate(u.reshape(U.shape), b, w, False).F.ravel(), U.ravel())
    assert np.abs(Jfd - r.dF).max() <= FD_RTOL_U * np.abs(r.dF).max()
    dw = (el.evaluate(U, b, w + 1e-7).F - el.evaluate(U, b, w - 1e-7).F).ravel() / 2e-7
    assert np.abs(dw - r.dF_domega).max() <= FD_RTOL_W * np.abs(r.dF_domega).max()


def test_normal_only_contact_jacobian_matches_finite_differences():
    el = ContactElement(Kinematics([0], [[-1.0]]), 3.0, preload=0.1, beta_c=0.02)
    b = FourierBasis("odd:7")   # no mean: the preload alone sets the static load
    U = np.random.default_rng(SEED).normal(scale=0.1, size=(b.nb, 1))
    r = el.evaluate(U, b, 0.9)
    assert 0.0 < np.mean(r.f[:, 0] == 0.0) < 1.0
    Jfd = fd(lambda u: el.evaluate(u.reshape(U.shape), b, 0.9, False).F.ravel(), U.ravel())
    assert np.abs(Jfd - r.dF).max() <= FD_RTOL_U * np.abs(r.dF).max()


def cyclic_sector(H="all:3"):
    """Sector: a blade (x, y) with a contact on the neighbour's (x, y), a rim spring, a link."""
    phi = 2 * np.pi * 3 / 8
    kin = Kinematics.contact([0, 1], [0.6, 0.8], [0.8, -0.6], np.eye(2), delta_next=-np.eye(2),
                             phase=phi)
    contact = ContactElement.jenkins(kin, 5.0, 3.0, 0.4, preload=0.05, beta_c=0.02)
    rim = LinearElement(Kinematics([0], [[1.0]], Q_next=[[-1.0]], phase=phi), [[0.7]])
    link = FrictionLink(IwanElement.jenkins(0.5, 0.05), 2, None, "ground")
    M, K = np.diag([1.0, 1.0, 0.5]), np.array([[2.0, 0, -1], [0, 3.0, 0], [-1, 0, 1.5]])
    lin = LinearModel(M=M, C=0.01 * M + 0.002 * K, K=K)
    f = {0: np.array([0.0, -0.1, 0.0]), 1: np.array([0.05, 0.02j, 0.0])}
    return Model(lin, [contact, rim, link], f), FourierBasis(H)


@pytest.mark.parametrize("Res", [FullResidual, CondensedResidual])
def test_residual_jacobian_with_cyclic_contact_matches_finite_differences(Res):
    model, b = cyclic_sector()
    res = Res(model, b)
    x = np.random.default_rng(SEED).normal(scale=0.08, size=res.size)
    w = 1.1
    R, J, Jw = res(x, w)
    Jfd = fd(lambda z: res(z, w, jac=False), x)
    assert np.abs(J - Jfd).max() <= FD_RTOL_RES * np.abs(J).max()
    Jw_fd = (res(x, w + 1e-7, jac=False) - res(x, w - 1e-7, jac=False)) / 2e-7
    assert np.abs(Jw - Jw_fd).max() <= FD_RTOL_RES * np.abs(Jw).max()


def test_viscous_operator_gives_the_dashpot_forces():
    """omega-derivative of the element forces = (D_theta (x) I) V x (cyclic dashpots included).

    Measured 1.3e-16 relative (symmetry of V: 5e-17).
    """
    model, b = cyclic_sector()
    res = FullResidual(model, b)
    x = np.random.default_rng(SEED).normal(scale=0.08, size=res.size)
    res.nonlinear(x, jac=False, omega=1.1)
    V = res.viscous_operator()
    assert np.abs(V - V.T).max() < ROUND * np.abs(V).max()  # conservative kinematics
    ref = np.kron(b.dtheta, np.eye(res.m)) @ V @ x
    assert np.abs(res.dF_domega - ref).max() < ROUND * np.abs(ref).max()


def test_condensed_and_full_residuals_agree_with_contacts():
    model, b = cyclic_sector()
    full, cond = FullResidual(model, b), CondensedResidual(model, b)
    assert full.size == cond.size  # every DOF is touched: same unknowns
    x = np.random.default_rng(SEED).normal(scale=0.08, size=full.size)
    # R_cond = G R_full (G the receptance): compare through the displacements' solve
    Rf = full(x, 1.1, jac=False)
    Rc = cond(x, 1.1, jac=False)
    A = full._K - 1.1**2 * full._M + 1.1 * full._C
    assert np.abs(A @ Rc - Rf).max() < ROUND * np.abs(Rf).max()  # measured 4.9e-16


def test_liftoff_releases_the_friction_and_the_slider_follows():
    el = plane_contact(IwanElement.jenkins(2.0, 0.3))
    b = FourierBasis("all:3")
    U = np.zeros((b.nb, 2))
    U[1, 0], U[2, 1], U[0, 1] = 0.4, 0.3, 0.1   # s = 0.4 cos, p = 0.1 + 0.3 sin
    r = el.evaluate(U, b, 1.0)
    off = r.f[:, 1] == 0.0
    assert 0.2 < off.mean() < 0.5
    assert np.all(r.f[off, 0] == 0.0)
    assert np.all(np.abs(r.f[:, 0]) <= 0.3 * r.f[:, 1] * (1 + ROUND))
    # at re-contact the element is virgin at the slip there: F = k_t (s - s_recontact)
    # until it slips; the first contact sample after lift-off is within k_t |ds|
    t = np.flatnonzero(off[:-1] & ~off[1:])[0] + 1
    assert abs(r.f[t, 0]) <= 2.0 * abs(r.q[t, 0] - r.q[t - 1, 0]) * (1 + ROUND)


def test_periodic_loop_closes_against_marched_periods():
    """The AFT loop at varying N is the state that marching many periods reaches."""
    fr = FRICTIONS["iwan"]()
    el = plane_contact(fr, preload=0.3)
    b = FourierBasis("all:3")
    U = np.random.default_rng(SEED).normal(scale=0.1, size=(b.nb, 2))
    r = el.evaluate(U, b, 1.0)
    s, N = r.q[:, 0], el.k_n * (0.3 + r.q[:, 1])
    ser = fr.series(np.tile(s, 30), np.tile(N, 30), state=fr.initial_state(N[0]))
    last = ser.F[-b.n_t:]
    assert np.abs(last - r.f[:, 0]).max() < ROUND * np.ptp(r.f[:, 0])  # measured 7.6e-17


def test_stuck_contact_has_the_prestress_mean_force():
    s0, kt = 0.02, 2.0
    el = plane_contact(IwanElement.jenkins(kt, 0.3), preload=0.5, slip_ref=s0)
    b = FourierBasis("all:3")
    U = np.zeros((b.nb, 2))
    U[0, 0], U[1, 0] = 0.05, 0.01      # mean slip 0.05, amplitude 0.01: stuck
    U[2, 1] = 0.1
    r = el.evaluate(U, b, 1.0)
    assert r.W == 0.0
    assert abs(r.F[0, 0] - kt * (0.05 - s0)) < ROUND


def test_constant_normal_load_contact_equals_the_friction_link():
    """p constant: the contact's tangential force is a Jenkins link of slip force mu k_n p_0."""
    el = plane_contact(IwanElement.jenkins(2.0, 0.3), preload=0.25)
    link = FrictionLink(IwanElement.jenkins(2.0, 0.3 * 4.0 * 0.25), 0)
    b = FourierBasis("all:5")
    U = np.zeros((b.nb, 2))
    U[:, 0] = np.random.default_rng(SEED).normal(scale=0.1, size=b.nb)
    U[0, 0] = 0.0
    r = el.evaluate(U, b, 1.0)
    Fh, dFh, W, _ = aft_link(link, U[:, 0], b)
    assert np.abs(r.F[:, 0] - Fh).max() < ROUND and abs(r.W - W) < ROUND
    assert np.abs(r.dF.reshape(b.nb, 2, b.nb, 2)[:, 0, :, 0] - dFh).max() < ROUND


def test_normal_load_phase_pi_is_equivalent_to_phase_zero():
    """Symmetry: N shifted by half a period and s -> -s give the same loop energy."""
    el = plane_contact(IwanElement.jenkins(2.0, 0.3), preload=0.3)
    b = FourierBasis("all:5")
    U = np.zeros((b.nb, 2))
    U[1, 0], U[1, 1] = 0.3, 0.15
    W0 = el.evaluate(U, b, 1.0).W
    U[1, 1] = -0.15
    assert abs(el.evaluate(U, b, 1.0).W - W0) < ROUND * W0
    U[1, 1], U[2, 1] = 0.0, 0.15
    assert abs(el.evaluate(U, b, 1.0).W - W0) > 1e-3 * W0  # a quarter period differs


def test_frictionless_statics_of_a_wedge_in_closed_form():
    """A body pushed by CF between two faces at g from the x axis: N = CF / (2 cos g)."""
    g, CF, kn = np.deg2rad(45.0), 120.0, 1e8
    nL, tL = [np.sin(g), -np.cos(g)], [np.cos(g), np.sin(g)]
    nR, tR = [-np.sin(g), -np.cos(g)], [np.cos(g), -np.sin(g)]
    els = [ContactElement.jenkins(Kinematics.contact([0, 1], n, t, np.eye(2)), kn, 0.8 * kn, 0.5)
           for n, t in ((nL, tL), (nR, tR))]
    lin = LinearModel(M=np.eye(2) * 0.005, C=np.zeros((2, 2)), K=np.zeros((2, 2)))
    model = Model(lin, els, {0: np.array([0.0, CF]), 1: np.array([1.0, 0.0])})
    x, slip = frictionless_statics(model, apply=True)
    for el in els:
        p = el.kinematics.Q[-1] @ x
        assert abs(kn * p - CF / (2 * np.cos(g))) < ROUND * CF
    assert slip[0] == els[0].slip_ref and abs(slip[0] + slip[1]) < ROUND * abs(slip[0])
    pulled = Model(lin, els, {0: np.array([0.0, -CF]), 1: np.array([1.0, 0.0])})
    with pytest.raises(ValueError, match="singular"):  # pulled away: both faces lift off
        frictionless_statics(pulled)


def ring_and_sector(n_r=4, eo=1, F0=0.24):
    """Blades (x, y) on springs, a pressed Jenkins contact between neighbours, EO forcing.

    The ring has n_r blades joined periodically; the sector is one blade with the
    contact on its neighbour through the cyclic phase phi = 2 pi EO / n_r.
    """
    phi = 2 * np.pi * eo / n_r
    n, t = [0.6, 0.8], [0.8, -0.6]
    law = dict(k_n=5.0, preload=0.05, beta_c=0.01)
    M, K, C = np.eye(2), np.diag([1.0, 2.0]), 0.02 * np.eye(2)

    sector = Model(LinearModel(M=M, C=C, K=K),
                   [ContactElement(Kinematics.contact([0, 1], n, t, np.eye(2), delta_next=-np.eye(2),
                                                      phase=phi), friction=IwanElement.jenkins(3.0, 0.3),
                                   **law)], {1: np.array([F0, 0.0])})
    els = []
    for j in range(n_r):
        k = (j + 1) % n_r
        kin = Kinematics.contact([2 * j, 2 * j + 1, 2 * k, 2 * k + 1], n, t,
                                 np.hstack([np.eye(2), -np.eye(2)]))
        els.append(ContactElement(kin, friction=IwanElement.jenkins(3.0, 0.3), **law))
    f = np.zeros(2 * n_r, complex)
    f[0::2] = F0 * np.exp(1j * phi * np.arange(n_r))
    ring = Model(LinearModel(M=np.kron(np.eye(n_r), M), C=np.kron(np.eye(n_r), C),
                             K=np.kron(np.eye(n_r), K)), els, {1: f})
    return sector, ring, phi


def test_cyclic_sector_equals_the_ring():
    """HB of the sector with the cyclic contact = HB of the whole ring (travelling wave)."""
    from harmonic_balance.newton import newton

    b, w = FourierBasis("all:5"), 1.05
    x = [None, None]
    for F0 in np.linspace(0.03, 0.24, 8):  # homotopy in the forcing level
        sector, ring, phi = ring_and_sector(F0=F0)
        for i, model in enumerate((sector, ring)):
            res = FullResidual(model, b)
            x0 = res.linear_guess(w) if x[i] is None else x[i]
            x[i] = newton(lambda z, r=res: r(z, w)[:2], x0, 1e-12).x
    Xs, Xr = x[0].reshape(b.nb, 2), x[1].reshape(b.nb, 8)
    res = FullResidual(sector, b)
    loop = res.evaluate(Xs.ravel(), w)[0]
    assert np.any(np.abs(loop.f[:, 0]) >= 0.3 * loop.f[:, 1] * (1 - 1e-12))  # it slips
    P = phase_operator(b, phi)
    scale = np.abs(Xs).max()
    for j in range(4):  # blade j = sector advanced by j phi
        Pj = np.linalg.matrix_power(P, j)
        assert np.abs(Xr[:, 2 * j:2 * j + 2] - Pj @ Xs).max() < SECTOR_RING_RTOL * scale


def test_energy_balance_of_the_cyclic_sector():
    """Excitation work = structural damping + contact (friction + dashpots), per sector.

    Exact at an HB solution up to the residual (velocity harmonics . R); the loop's
    sampled work W (C core) differs from the harmonic work by the AFT sampling only.
    """
    from harmonic_balance.newton import newton

    b, w = FourierBasis("all:7"), 1.05
    x = None
    for F0 in np.linspace(0.03, 0.24, 8):
        sector, _, _ = ring_and_sector(F0=F0)
        res = FullResidual(sector, b)
        x = newton(lambda z, r=res: r(z, w)[:2], res.linear_guess(w) if x is None else x, 1e-12).x
    X = x.reshape(b.nb, 2)
    E = energy_per_cycle(sector, b, X, w)
    (el,), (loop,) = sector.elements, res.evaluate(x, w)
    Qb, _ = el.kinematics.operators(b)
    W_el = harmonic_work((Qb @ x).reshape(b.nb, 2), loop.F, b)
    assert loop.W_viscous > 0.0 and loop.W > loop.W_viscous
    assert abs(E["W_ext"] - E["W_visc"] - W_el) <= ENERGY_BALANCE_RTOL * E["W_ext"]
    assert abs(W_el - loop.W) <= AFT_WORK_RTOL * loop.W


def test_contact_batch_stepper_gives_the_single_stepper_bits():
    """Vectorised histories (one C call per step) equal separate steppers bit for bit."""
    el = plane_contact(FRICTIONS["iwan"](), preload=0.05, slip_ref=0.01)
    rng = np.random.default_rng(SEED)
    q = np.cumsum(rng.normal(scale=0.03, size=(400, 3, 2)), axis=0)  # random walks, lift-offs
    single = [el.stepper() for _ in range(3)]
    batch = el.batch_stepper(3)
    for k in range(200):
        fb = batch.force(q[k]).copy()
        assert np.array_equal(fb, np.array([s.force(q[k, i]) for i, s in enumerate(single)]))
    assert np.array_equal(batch.dissipated(), [s.dissipated() for s in single])
    assert np.any(q[:200, :, 1] + 0.05 < 0) and batch.dissipated().min() > 0
    kept = batch.keep([2, 0])
    for k in range(200, 400):
        fb = kept.force(q[k, [2, 0]]).copy()
        assert np.array_equal(fb, np.array([single[i].force(q[k, i]) for i in (2, 0)]))


def test_exact_link_stuck_test_agrees_with_the_sampled_one():
    """A link with the mean retained: a loop that never slips is the virgin stuck line
    F = k0 u, Jacobian k0 I, whether the exact link (its test on the harmonics) or the
    sampled one (on the samples) decides; a loop that slips a little is neither's stuck
    line. Jenkins k0 = 100 N/m, f_s = 1 N: amplitude 5 mm stays stuck (0.5 N), 20 mm slips
    (2 N)."""
    b = FourierBasis("all:7", 128)
    el = IwanElement.jenkins(100.0, 1.0)
    exact, sampled = FrictionLink(el, 0, exact=True), FrictionLink(el, 0)
    for amp, stuck in ((5e-3, True), (2e-2, False)):
        U = np.zeros(b.nb)
        U[0], U[1], U[4] = 3e-3, amp, 0.2 * amp      # a mean, harmonic 1 and harmonic 2
        Fe, Je, We, _ = aft_link(exact, U, b)
        Fs, Js, Ws, _ = aft_link(sampled, U, b)
        line = np.allclose(Fe, 100.0 * U, rtol=0, atol=ROUND * 100.0 * amp)
        assert line == stuck and np.allclose(Fs, 100.0 * U, rtol=0, atol=ROUND * 100.0 * amp) == stuck
        if stuck:
            assert We == 0.0 and np.array_equal(Je, 100.0 * np.eye(b.nb))
            np.testing.assert_allclose(Js, Je, rtol=0, atol=ROUND * 100.0)
        else:
            assert We > 0.0 and Ws > 0.0
