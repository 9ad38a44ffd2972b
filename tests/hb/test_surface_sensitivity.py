"""The condensed surface's exact Jacobian (forward sensitivities of its march).

A small flat face (15 nodes, planar, penalty 1e4) under a constant approach and a
harmonic motion of its rigid inputs: the exact dF/dU against the forward differences of
the whole march (the reference path, ``CondensedSurface.jacobian_fd``), for a slipping
loop and for a rocking one in which edge nodes lift off and re-contact inside a period.
"""
from __future__ import annotations

import numpy as np
import pytest
from hbcases import condensed_flat_face

from harmonic_balance import surface_sensitivity as sens
from harmonic_balance.fourier import FourierBasis

N, MU, PENALTY = 100.0, 0.5, 1e4
#: Samples of the period and harmonics (the march is exact at the samples).
N_T, H = 32, 3
#: Difference step of the reference, relative to each input's amplitude: on one piece of
#: the piecewise-linear march and far above the node solve's tolerance (1e-7 of the loads).
FD_STEP = 1e-4
#: Agreement of the exact Jacobian with the differences, relative to its largest entry:
#: measured 8.5e-10 (slipping) and 3.3e-9 (rocking with lift-off, the re-contact's
#: bilinear terms give an O(FD_STEP) difference); 1e-6 is still far below the 1e-3 .. 1 of
#: a Jacobian term that a wrong settled set (a stuck slider taken as slipping) gets wrong.
JACOBIAN_RTOL = 1e-6


@pytest.fixture(scope="module")
def element(tmp_path_factory):
    return condensed_flat_face(tmp_path_factory.mktemp("surface_sensitivity_cache"), N, MU, PENALTY)


def _motion(element, slide: float, rock: float):
    """Input harmonics: the prestress, a tangential cosine of ``slide`` times the stuck face's
    slip amplitude, an approach sine and a second-harmonic rotation growing with ``rock``."""
    el, q_static, surface = element
    basis = FourierBasis(tuple(range(H + 1)), N_T)
    U = np.zeros((basis.nb, el.m))
    U[0] = q_static
    j, i, a = (surface.inputs.index(n) for n in ("tangential_x", "rotation", "approach"))
    U[basis.index(1)[0], j] = slide * MU * N / el.stuck_stiffness()[j, j]
    U[basis.index(1)[1], a] = 0.5 * rock * q_static[a]
    U[basis.index(2)[1], i] = rock * 1e-3                  # edge motion ~ rock * 0.6 um
    return basis, U


def _count_lift_off(monkeypatch, el, basis, U) -> int:
    """Node re-contacts inside a step along the march of U (the branch the rocking case covers)."""
    seen, end_state = [0], sens._end_state

    def spy(ref, st0, st1):
        e = end_state(ref, st0, st1)
        seen[0] += int(e.re.sum())
        return e

    monkeypatch.setattr(sens, "_end_state", spy)
    el.evaluate(U, basis, 1.0, jac=True)
    return seen[0]


@pytest.mark.parametrize("slide, rock", [(1.2, 0.3), (2.0, 1.0)], ids=["slipping", "rocking"])
def test_exact_jacobian_of_the_march_matches_its_forward_differences(element, slide, rock):
    el = element[0]
    basis, U = _motion(element, slide, rock)
    J = el.evaluate(U, basis, 1.0, jac=True).dF
    J_fd = el.jacobian_fd(U, basis, 1.0, rel=FD_STEP)
    assert np.abs(J - J_fd).max() <= JACOBIAN_RTOL * np.abs(J).max()


def test_rocking_motion_lifts_edge_nodes_off_and_back(element, monkeypatch):
    """The rocking case of the Jacobian test goes through lift-off and re-contact."""
    el = element[0]
    basis, U = _motion(element, 2.0, 1.0)
    assert _count_lift_off(monkeypatch, el, basis, U) > 0


#: Cached factors against fresh dense solves: the same operators factorized once instead of
#: per step; the node solve's slopes rounded to massless.SLOPE_DIGITS (5e-9 of a slope) move
#: Newton's last iterate by that share of its step. Measured 2e-16 here; on UPD-24 (5 and
#: 10 nodes per side, H 7) up to 5e-12 (F) and 1.3e-10 (dF) of the largest entry.
CACHE_RTOL = 1e-9


@pytest.mark.parametrize("slide, rock", [(1.2, 0.3), (2.0, 1.0)], ids=["slipping", "rocking"])
def test_cached_factors_give_the_fresh_solves_forces_and_jacobian(element, slide, rock):
    el = element[0]
    basis, U = _motion(element, slide, rock)
    cached = [el.evaluate(U, basis, 1.0, jac=True) for _ in range(2)]   # cold, then warm cache
    factors, el.factors = el.factors, None
    try:
        fresh = el.evaluate(U, basis, 1.0, jac=True)
    finally:
        el.factors = factors
    for lf in cached:
        assert np.abs(lf.F - fresh.F).max() <= CACHE_RTOL * np.abs(fresh.F).max()
        assert np.abs(lf.dF - fresh.dF).max() <= CACHE_RTOL * np.abs(fresh.dF).max()


@pytest.mark.parametrize("slide, rock", [(1.2, 0.3), (2.0, 1.0)], ids=["slipping", "rocking"])
def test_diagonal_updates_give_the_fresh_solves_forces_and_jacobian(element, slide, rock, monkeypatch):
    """Every block solved by diagonal updates of reference inverses (the path of blocks of
    DIAGONAL_UPDATE_MIN DOFs and more, UPD-24 at 10 nodes per side and up), here forced on
    the small face: the fresh dense solves' forces and Jacobian to round-off."""
    from harmonic_balance import massless
    from harmonic_balance.massless import FactorCache

    el = element[0]
    basis, U = _motion(element, slide, rock)
    factors = el.factors
    try:
        el.factors = None
        fresh = el.evaluate(U, basis, 1.0, jac=True)
        monkeypatch.setattr(massless, "DIAGONAL_UPDATE_MIN", 1)
        el.factors = updates = FactorCache()
        updated = [el.evaluate(U, basis, 1.0, jac=True) for _ in range(2)]   # cold, then warm
    finally:
        el.factors = factors
    assert updates._inv                                     # the updates' path was taken
    for lf in updated:
        assert np.abs(lf.F - fresh.F).max() <= CACHE_RTOL * np.abs(fresh.F).max()
        assert np.abs(lf.dF - fresh.dF).max() <= CACHE_RTOL * np.abs(fresh.dF).max()
