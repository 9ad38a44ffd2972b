"""The contact surface condensed onto its rigid inputs (``surface_condensed``).

A small flat face (15 nodes, planar, penalty 1e4) under a constant approach and a
tangential displacement cycle at its rigid input, marched by the element itself:
the linear limit (every node stuck) against the condensed stuck stiffness computed by
linear algebra, and the energy balance of a slipping loop (the resultant's work per
cycle equals the nodes' friction work).
"""
from __future__ import annotations

import numpy as np
import pytest
from hbcases import condensed_flat_face

from harmonic_balance import surface_static as ss
from harmonic_balance.fourier import FourierBasis

N, MU, PENALTY = 100.0, 0.5, 1e4
#: Samples of the period (the march is exact at the samples; the loop's work is summed
#: over them as the element's friction work is, step by step).
N_T = 64
#: Linear limit: a stuck face is linear, so its first harmonic is K_stuck times the
#: amplitude to the node solve's round-off (1e-7 of the loads at most, RESIDUAL_RTOL).
LINEAR_RTOL = 1e-6
#: Energy balance of the sampled loop: the resultant's work by the trapezoidal rule on
#: N_T samples against the friction work of the return mapping on the same straight
#: steps (equal for piecewise-linear paths up to the node solve's tolerance).
ENERGY_RTOL = 2e-3


@pytest.fixture(scope="module")
def element(tmp_path_factory):
    return condensed_flat_face(tmp_path_factory.mktemp("surface_condensed_cache"), N, MU, PENALTY)


def _loop(el, q_static, surface, amp):
    basis = FourierBasis((0, 1), N_T)
    U = np.zeros((basis.nb, el.m))
    U[0] = q_static
    U[basis.index(1)[0], surface.inputs.index("tangential_x")] = amp
    return basis, U, el.evaluate(U, basis, 1.0, jac=False)


def test_a_stuck_condensed_surface_is_its_condensed_stuck_stiffness(element):
    el, q_static, surface = element
    j = surface.inputs.index("tangential_x")
    amp = 1e-4 * MU * N / el.stuck_stiffness()[j, j]    # far below any slip
    basis, U, res = _loop(el, q_static, surface, amp)
    F1 = res.F[basis.index(1)[0]]
    assert F1 == pytest.approx(el.stuck_stiffness() @ U[basis.index(1)[0]], rel=LINEAR_RTOL,
                               abs=LINEAR_RTOL * abs(F1[j]))
    assert res.W < LINEAR_RTOL * MU * N * amp


def test_a_slipping_condensed_surface_balances_its_energy_per_cycle(element):
    el, q_static, surface = element
    j = surface.inputs.index("tangential_x")
    amp = 2.0 * MU * N / el.stuck_stiffness()[j, j]     # gross slip: the face slides
    _, _, res = _loop(el, q_static, surface, amp)
    q, f = np.vstack([res.q, res.q[:1]]), np.vstack([res.f, res.f[:1]])
    work = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(q, axis=0)))
    assert res.W > 0.5 * 4 * MU * N * amp * 0.5          # a wide loop: well into slip
    assert work == pytest.approx(res.W, rel=ENERGY_RTOL)


#: Force-controlled loop at H = 7 (the element's own march is exact at the samples, so
#: only the rigid inputs' motion is truncated): measured -0.22 % (penalty 1e4) against
#: the node-DOF harmonic balance's -84 % at the same H (test_surface_hb.py).
QS_ENERGY_RTOL_H7 = 0.01
#: Newton tolerance of the harmonic balance, relative to N.
HB_TOL_REL = 1e-9


def test_condensed_surface_hb_dissipates_the_quasi_static_loop_at_low_H(element):
    """The surface's rigid inputs as the only HB unknowns under a constant normal force and a
    harmonic tangential force (no mass): its loop dissipates the quasi-static loop's energy."""
    from harmonic_balance.linear import LinearModel
    from harmonic_balance.model import Model
    from harmonic_balance.newton import newton
    from harmonic_balance.residual import FullResidual

    el, q_static, surface = element
    r, T_a, H = el.m, 0.8 * MU * N, 7
    f0, f1 = np.zeros(r), np.zeros(r, complex)
    f0[surface.inputs.index("approach")], f1[surface.inputs.index("tangential_x")] = N, T_a
    model = Model(LinearModel(M=np.zeros((r, r)), K=np.zeros((r, r))), [el], {0: f0, 1: f1},
                  surface.inputs.index("tangential_x"))
    basis = FourierBasis(tuple(range(H + 1)), N_T)
    res = FullResidual(model, basis)
    x0 = np.zeros((basis.nb, r))
    x0[0], x0[basis.index(1)[0]] = q_static, np.linalg.solve(el.stuck_stiffness(), f1.real)
    sol = newton(lambda z: res(z, 1.0, True)[:2], x0.ravel(), HB_TOL_REL * N, 40)
    W = sum(e.W for e in res.evaluate(sol.x, 1.0, jac=False))
    W_qs = ss.cyclic_friction_work(surface, N, T_a)
    assert W == pytest.approx(W_qs, rel=QS_ENERGY_RTOL_H7)


#: Directional derivative of the resultants against the Jacobian's action: the march is
#: piecewise linear in U, so a central difference (STEP of the amplitude, far above the
#: node solve's tolerance of 1e-7 of the loads, which a step of 1e-6 already feels at
#: 3e-3) across no kink equals it up to round-off (the transposed Jacobian: 1.1, the loop
#: slips, so dF/dU is not symmetric).
STEP = 1e-4
JACOBIAN_RTOL = 1e-4


def test_condensed_jacobian_acts_as_the_directional_derivative(element):
    """dF/dU (read lazily, coefficient-major c * r + j) against a central difference of F
    along a random direction in every harmonic and input (seed written out)."""
    el, q_static, surface = element
    j = surface.inputs.index("tangential_x")
    amp = 1.2 * MU * N / el.stuck_stiffness()[j, j]     # slipping loop: dF/dU not symmetric
    basis, U, _ = _loop(el, q_static, surface, amp)
    res = el.evaluate(U, basis, 1.0, jac=True)
    v = np.random.default_rng(20261127).standard_normal(U.shape) * np.abs(U).max(axis=0)
    eps = STEP
    Fp = el.evaluate(U + eps * v, basis, 1.0, jac=False).F
    Fm = el.evaluate(U - eps * v, basis, 1.0, jac=False).F
    d = ((Fp - Fm) / (2 * eps)).ravel()
    assert res.dF @ v.ravel() == pytest.approx(d, rel=JACOBIAN_RTOL, abs=JACOBIAN_RTOL * np.abs(d).max())


def test_a_step_whose_node_solve_needs_many_iterations_settles_at_the_shortest_split(element, monkeypatch):
    """A node at a kink of its trial map leaves the node solve converging linearly, and
    halving the step does not move the kink: the shortest split step takes the
    iterations of a step that cannot split (massless.MAX_NEWTON_UNSPLIT) instead of
    failing the march (which the harmonic balance saw as a non-finite residual and
    stalled on). With one Newton iteration allowed before a split every step needs
    that last resort here; the loop is the one of the default march to the node solve's
    tolerance."""
    from harmonic_balance import surface_condensed as sc

    el, q_static, surface = element
    j = surface.inputs.index("tangential_x")
    amp = 2.0 * MU * N / el.stuck_stiffness()[j, j]     # gross slip: the nodes change state
    _, _, ref = _loop(el, q_static, surface, amp)
    monkeypatch.setattr(sc, "MAX_NEWTON", 1)
    _, _, res = _loop(el, q_static, surface, amp)
    assert np.all(np.isfinite(res.F))
    assert res.F == pytest.approx(ref.F, rel=LINEAR_RTOL, abs=LINEAR_RTOL * np.abs(ref.F).max())
    monkeypatch.setattr(sc, "MAX_NEWTON_UNSPLIT", 1)    # no last resort: the march fails
    _, _, bad = _loop(el, q_static, surface, amp)
    assert not np.all(np.isfinite(bad.F))
