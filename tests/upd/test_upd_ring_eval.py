"""The ring residual's batched contact evaluation (``contact.evaluate_many``) against
each contact's own ``ContactElement.evaluate``: the same residual and Jacobian."""
import numpy as np
import pytest

import harmonic_balance.bladed_disk.ring_hb as ring_hb
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
from harmonic_balance.bladed_disk.sector import Sector
from harmonic_balance.bladed_disk.solve import frf

#: Relative difference allowed between the batched and the per-contact evaluation: the
#: same operations, summed in another order by the batched products (round-off of
#: sums over n_t = O(100) samples, ~1e-14); 1e-12 as asked of the batched path.
BATCH_RTOL = 1e-12
PATTERN = (1.02, 0.985, 1.0, 0.995)
#: Scales of the tuned peak's dynamic part: stuck and partly slipping (0.3), the
#: solution itself, gross slip with the contacts lifting off part of the cycle (6).
SCALES = (0.3, 1.0, 6.0)


def per_contact(elements, U, basis, omega, jac=True):
    """evaluate_many's outputs from each element's own evaluate (the reference)."""
    res = [el.evaluate(u, basis, omega, jac) for el, u in zip(elements, U)]
    dws = [r.dF_domega for r in res]
    dw = None if all(v is None for v in dws) else np.array(
        [np.zeros(U[0].size) if v is None else v for v in dws])
    return np.array([r.F for r in res]), np.array([r.dF for r in res]) if jac else None, dw


@pytest.fixture(scope="module")
def ring_states():
    """A mistuned four-blade ring (EO 1, H = 3) and states around its tuned peak."""
    sector = Sector(load_config().with_values(disk__blades=4, disk__engine_order=1))
    tuned = SectorHB(sector, 3)
    c = frf(tuned, 2 * np.pi * np.linspace(440.0, 475.0, 8))
    ring = MistunedRingHB(sector, PATTERN, 3)
    x = ring.from_sector(c.peak_x)
    x0 = ring.static_guess()
    return ring, c.peak_omega, [x0 + a * (x - x0) for a in SCALES]


def _rel(a, b):
    a, b = (v.toarray() if hasattr(v, "toarray") else v for v in (a, b))
    return np.abs(a - b).max() / np.abs(b).max()


def test_ring_residual_and_jacobian_batched_equal_per_contact(ring_states, monkeypatch):
    ring, w, states = ring_states
    for x in states:
        R, J, Rw = ring(x, w)
        R1 = ring(x, w, jac=False)
        with monkeypatch.context() as mp:
            mp.setattr(ring_hb, "evaluate_many", per_contact)
            R0, J0, Rw0 = ring(x, w)
            R10 = ring(x, w, jac=False)
        # R is near zero at the solution: compare with the external load's scale
        scale = np.abs(ring.Fext).max()
        assert np.abs(R - R0).max() / scale < BATCH_RTOL
        assert np.abs(R1 - R10).max() / scale < BATCH_RTOL
        assert _rel(J, J0) < BATCH_RTOL
        assert _rel(Rw, Rw0) < BATCH_RTOL


def test_states_cover_stick_slip_and_lift_off(ring_states):
    """The states above exercise the batched path's cases: a contact stuck throughout
    (every sample's friction row non-zero), one slipping in some samples (only some
    rows), one lifting off part of the cycle."""
    ring, w, states = ring_states
    (idx, G, Q), = ring._groups
    els = [ring.points[e] for e in idx]
    b, seen = ring.basis, set()
    for x in states:
        U = np.einsum("eja,eca->ecj", Q, x[G].reshape(len(idx), ring.nb, -1))
        pen = np.array([el.preload for el in els])[:, None] + U[:, :, 1] @ b.E.T
        seen |= {"lift-off"} if (pen <= 0).any() else set()
        for el, u, p in zip(els, U, pen):
            rows = el.friction.periodic_jac_rows(u[:, 0] @ b.E.T - el.slip_ref, b.E,
                                                 N=el.k_n * p, EN=el.k_n * b.E,
                                                 max_periods=el.max_periods, tol=el.tol)[1]
            seen.add("stuck" if rows.size == b.n_t else "partial slip")
    assert seen == {"lift-off", "stuck", "partial slip"}


def test_contacts_with_different_tolerances_take_their_own_path_with_the_same_numbers(ring_states):
    """Contacts whose loop tolerances differ cannot share one C call: each takes its own
    friction path inside evaluate_many, with its own evaluate's numbers."""
    import copy

    from harmonic_balance.contact_many import evaluate_many

    ring, w, states = ring_states
    (idx, G, Q), = ring._groups
    els = [copy.copy(ring.points[e]) for e in idx]
    els[0].tol = els[0].tol / 10.0
    for x in states:
        U = np.einsum("eja,eca->ecj", Q, x[G].reshape(len(idx), ring.nb, -1))
        for jac in (True, False):
            F, dF, dw = evaluate_many(els, U, ring.basis, w, jac)
            F0, dF0, dw0 = per_contact(els, U, ring.basis, w, jac)
            assert _rel(F, F0) < BATCH_RTOL
            if jac:
                assert _rel(dF, dF0) < BATCH_RTOL
            assert (dw is None) == (dw0 is None) and (dw is None or _rel(dw, dw0) < BATCH_RTOL)


def test_kept_contacts_and_linear_values_give_a_fresh_rings_bits(ring_states):
    """The ring keeps its contacts' constants (LineContacts) and A(omega)'s values of the
    last frequency and scale: after evaluations at another frequency and scale, R, J and
    dR/domega equal a fresh ring's first evaluation bit for bit; each J owns its values;
    the residual without the Jacobian is the Jacobian path's R (the same batched sums)."""
    ring, w, states = ring_states
    x = states[1]
    for lam in (1.0, 0.5):
        fresh = MistunedRingHB(ring.sector, PATTERN, 3)
        fresh.set_scale(lam)
        R0, J0, Rw0 = fresh(x, w)
        ring.set_scale(1.0)
        ring(x, 1.01 * w)
        ring(x, w)
        ring.set_scale(lam)
        R, J, Rw = ring(x, w)
        J2 = ring(x, w)[1]
        assert np.array_equal(R, R0) and np.array_equal(Rw, Rw0)
        assert np.array_equal(J.data, J0.data) and np.array_equal(J2.data, J0.data)
        J2.data[:] = 0.0
        assert np.array_equal(J.data, J0.data) and np.array_equal(ring(x, w)[1].data, J0.data)
        R1, Rw1 = ring(x, w, jac=False, rate=True)
        assert np.array_equal(R1, R) and np.array_equal(Rw1, Rw)
    ring.set_scale(1.0)
