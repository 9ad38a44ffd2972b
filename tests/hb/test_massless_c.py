"""The massless node step in C (``massless_c``, fmu_src/core/march_step.c) against the numpy path.

The C step makes :meth:`harmonic_balance.massless.MasslessContacts.solve`'s step for one
history operation for operation, so from the same committed states it must give the same
displacements and states to round-off: on a small flat face (15 nodes, x and z blocks)
along a path that sticks, slips grossly, reverses, repeats a sample (a zero step: every
slipping node at the kink of its trial map), rocks (an edge opens) and lifts the whole
face off and brings it back (re-contact). Then the condensed element's forces and exact
Jacobian (the forward sensitivities advanced in C too) against the numpy path's, with the
blocks factorized and with the large blocks' diagonal updates of kept inverses.
"""
from __future__ import annotations

import numpy as np
import pytest
from hbcases import condensed_flat_face

from harmonic_balance import massless, massless_c
from harmonic_balance.fourier import FourierBasis
from harmonic_balance.massless import MAX_NEWTON_UNSPLIT, FactorCache, MasslessContacts

pytestmark = pytest.mark.skipif(massless_c.lib is None, reason="fmu_src._iwan built without march_step.c")

N, MU, PENALTY = 100.0, 0.5, 1e4
#: Seed of the path's random perturbations (written out: any seed must pass).
SEED = 20261128
#: Steps of the path.
STEPS = 160
#: Equal steps: the two paths differ in the order of a few sums (the residual's product and
#: the line search's slope), ~1e-16 of the loads; Newton's last step removes what that
#: leaves in w, so w and the states agree to round-off amplified by the block's condition.
STEP_RTOL = 1e-10
#: The element's forces and Jacobian, relative to their largest entry (measured ~1e-15).
ELEMENT_RTOL = 1e-10


@pytest.fixture(scope="module")
def element(tmp_path_factory):
    return condensed_flat_face(tmp_path_factory.mktemp("massless_c_cache"), N, MU, PENALTY)


def _path(el, q_static) -> np.ndarray:
    """Rigid inputs (STEPS, r): approach, rotation, tangential_x (the face's inputs)."""
    rng = np.random.default_rng(SEED)
    k_t = el.stuck_stiffness()[2, 2]
    t = np.linspace(0.0, 2.0, STEPS)
    q = np.tile(q_static, (STEPS, 1))
    q[:, 2] = 2.0 * MU * N / k_t * np.sin(2 * np.pi * t)                 # gross slip, reversals
    q[:, 0] *= np.where(t < 1.0, 1.0, 1.0 - 1.4 * np.sin(np.pi * (t - 1.0)) ** 2)   # lift-off, back
    q[:, 1] = np.where((t > 0.5) & (t < 1.0), 1.5 * q_static[0] / 6e-4 * np.sin(2 * np.pi * t), 0.0)
    q *= 1.0 + 0.02 * rng.standard_normal((STEPS, 1))
    q[40] = q[39]                                                         # a zero step at a kink
    return q


def _nodes(el, compiled: bool):
    nodes = MasslessContacts(el.elements, range(el.surface.n_w), 1, el.A != 0.0)
    nodes.factors = FactorCache()
    A = nodes.split(el.A)
    if compiled:
        assert nodes.compile(A)
    return nodes, A


def _state_fields(states):
    st = np.concatenate(states)
    n = 1
    return np.column_stack([st["u"], st["N"], st["u_contact"], st["w_diss"], st["z"][:, :n],
                            st["in_contact"], st["dir"]])


def test_the_compiled_step_solves_each_step_as_the_numpy_path(element):
    el, q_static, _ = element
    c_nodes, A = _nodes(el, True)
    np_nodes, _ = _nodes(el, False)
    w = el.w_static[None].copy()
    opened = reclosed = 0
    for q in _path(el, q_static):
        rhs = (q @ el.AR.T)[None]
        np_nodes.states = [s.copy() for s in c_nodes.states]
        open_before = np.concatenate(c_nodes.states)["in_contact"] == 0
        w_np = np_nodes.solve(A, rhs, w, MAX_NEWTON_UNSPLIT)
        w_c = c_nodes.solve(A, rhs, w, MAX_NEWTON_UNSPLIT)
        scale = np.abs(w_np).max()
        assert np.abs(w_c - w_np).max() <= STEP_RTOL * scale
        a, b = _state_fields(c_nodes.states), _state_fields(np_nodes.states)
        assert np.all(np.abs(a - b) <= STEP_RTOL * np.maximum(np.abs(b).max(axis=0), 1e-300))
        open_after = np.concatenate(c_nodes.states)["in_contact"] == 0
        opened += np.sum(open_after & ~open_before)
        reclosed += np.sum(open_before & ~open_after)
        w = w_c
    assert opened > 0 and reclosed > 0            # the path lifted nodes off and closed them again
    assert c_nodes.dissipated()[0] > 0.0


#: Block size from which both paths solve by diagonal updates of kept inverses in the
#: large-block test (the face's blocks have 15 DOFs; UPD-24's from 10 nodes per side on
#: are above massless.DIAGONAL_UPDATE_MIN).
SMALL_UPDATE_MIN = 10


@pytest.mark.parametrize("updates", [False, True], ids=["factorized", "diagonal_updates"])
@pytest.mark.parametrize("slip, breathing", [(0.3, 0.3), (2.0, 0.3), (1.0, 1.3)],
                         ids=["partial_slip", "gross_slip", "lift_off_and_recontact"])
def test_the_condensed_element_gives_the_numpy_forces_and_jacobian(element, slip, breathing, updates,
                                                                   monkeypatch):
    if updates:
        monkeypatch.setattr(massless, "DIAGONAL_UPDATE_MIN", SMALL_UPDATE_MIN)
    el, q_static, surface = element
    basis = FourierBasis((0, 1, 2), 64)
    U = np.zeros((basis.nb, el.m))
    U[0] = q_static
    j = surface.inputs.index("tangential_x")
    U[basis.index(1)[0], j] = slip * MU * N / el.stuck_stiffness()[j, j]
    U[basis.index(1)[1], 0] = breathing * q_static[0]        # the load breathes (> 1: lifts off)
    out = []
    for compiled in (False, True):
        el.compiled = compiled
        el.factors = FactorCache()
        out.append(el.evaluate(U, basis, 1.0, jac=True))
        if compiled:   # the march ran in C, its sensitivities too (and kept inverses if updated)
            assert el.factors.compiled is not None and el.factors.compiled_sensitivity is not None
            assert np.any(el.factors.compiled_refs[2][2]) == updates
    el.compiled = True
    (F0, J0), (F1, J1) = ((r.F, r.dF) for r in out)
    assert np.abs(F1 - F0).max() <= ELEMENT_RTOL * np.abs(F0).max()
    assert np.abs(J1 - J0).max() <= ELEMENT_RTOL * np.abs(J0).max()
    assert out[1].W == pytest.approx(out[0].W, rel=ELEMENT_RTOL)


def test_a_step_without_equilibrium_is_a_runtime_error_and_commits_nothing(element):
    el, q_static, _ = element
    nodes, A = _nodes(el, True)
    before = np.concatenate(nodes.states).copy()
    q = q_static.copy()
    q[2] = 50 * MU * N / el.stuck_stiffness()[2, 2]
    with pytest.raises(RuntimeError, match="no equilibrium"):
        nodes.solve(A, (q @ el.AR.T)[None], el.w_static[None], 1)
    assert np.concatenate(nodes.states).tobytes() == before.tobytes()
