"""The contact surface in the harmonic balance against its own quasi-static loop.

A small flat face (15 nodes, planar) under a constant normal force N and a harmonic
tangential force T cos(theta) at the rigid input, no mass: the HB's periodic solution
(the surface's node ContactElements and its stiffness as a Model, FullResidual,
Newton) must dissipate what the quasi-static force-controlled loop of
``surface_static`` dissipates, up to the harmonic truncation, which is slow for a
surface (each node's slip is a clipped signal): measured +8.7 % at H = 15 and +2.2 % at
H = 31 (-84 % at H = 7).
"""
from __future__ import annotations

import numpy as np
import pytest

from contact_core.condense import condense
from contact_core.spec import ContactSpec
from harmonic_balance import surface as sf
from harmonic_balance import surface_static as ss
from harmonic_balance.fourier import FourierBasis
from harmonic_balance.linear import LinearModel
from harmonic_balance.model import Model
from harmonic_balance.newton import newton
from harmonic_balance.residual import FullResidual

N, MU, SHARE, PENALTY = 100.0, 0.5, 0.8, 100.0
#: Quasi-static load steps per leg (force control; the friction work is exact per step).
STEPS = 40
#: Energy agreement at H = 31 (measured 2.2 %; the truncation error shrinks like ~1/H).
ENERGY_RTOL_H31 = 0.04


@pytest.fixture(scope="module")
def surface(tmp_path_factory):
    cc = condense(ContactSpec(body="flat", width=1.2e-3, length=1.2e-3, grid=5), directions=("z", "x"),
                  cache=tmp_path_factory.mktemp("surface_hb_cache"))
    return sf.build(cc, MU, penalty=PENALTY, tangents=("x",))


def quasi_static_energy(surface) -> float:
    return ss.cyclic_friction_work(surface, N, SHARE * MU * N, STEPS)


def hb_energy(surface, H: int) -> tuple[float, float]:
    """(friction work per cycle of the HB loop [J], work of the excitation [J])."""
    n, T_a = surface.n_dof, SHARE * MU * N
    f0, f1 = np.zeros(n), np.zeros(n, complex)
    f0[surface.input_dof("approach")], f1[surface.input_dof("tangential_x")] = N, T_a
    model = Model(LinearModel(M=np.zeros((n, n)), K=surface.K), list(surface.elements),
                  {0: f0, 1: f1}, surface.input_dof("tangential_x"))
    basis = FourierBasis(tuple(range(H + 1)), 8 * (H + 1))
    res = FullResidual(model, basis)
    x0 = np.zeros((basis.nb, n))
    x0[basis.index(0)[0]] = ss.preload(surface, N).x   # prestress; sliders virgin there
    x0 = x0.ravel()
    R, J, _ = res(x0, 1.0, True)
    x = newton(lambda z: res(z, 1.0, True)[:2], x0 - np.linalg.solve(J, R), 1e-9 * N, 80).x
    W = sum(r.W - r.W_viscous for r in res.evaluate(x, 1.0, jac=False))
    U = x.reshape(basis.nb, n)[:, surface.input_dof("tangential_x")]
    return W, np.pi * T_a * U[basis.index(1)[1]]     # f = T_a cos: work pi T_a b_1


def test_surface_hb_dissipates_the_quasi_static_loop_as_H_grows(surface):
    W_qs = quasi_static_energy(surface)
    errors = []
    for H in (15, 31):
        W, W_ext = hb_energy(surface, H)
        assert W == pytest.approx(W_ext, rel=1e-3)   # energy balance of the HB solution itself
        errors.append(abs(W / W_qs - 1.0))
    assert errors[1] < errors[0] and errors[1] < ENERGY_RTOL_H31
